// tonemap.comp — turns the accumulated radiance sum into the 8-bit sRGB display image (viewer).
// Same curves as app/image/tonemap.cpp (tonemapCurve); PNG output uses the C++ twin.
#include "shared/gpu_layout.h"

layout(local_size_x = CAUSTICA_WORKGROUP_X, local_size_y = CAUSTICA_WORKGROUP_Y) in;
layout(rgba32f, binding = CAUSTICA_IMAGE_ACCUM) uniform readonly image2D accumImage;
layout(rgba8, binding = CAUSTICA_IMAGE_DISPLAY) uniform writeonly image2D displayImage;
layout(location = 0) uniform float exposure;     // linear scale: 2^stops
layout(location = 1) uniform int curve;             // 0: clamp, 1: ACES filmic (Narkowicz 2015)
layout(location = 2) uniform int transparent;       // 1: --background transparent, alpha from the coverage image
layout(r32f, binding = CAUSTICA_IMAGE_COVERAGE) uniform readonly image2D coverageImage;  // camera-ray hits

vec3 tonemapCurve(vec3 x, int c) {
  if (c == 1) return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
  return clamp(x, 0.0, 1.0);
}

vec3 linearToSrgb(vec3 c) {
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, greaterThan(c, vec3(0.0031308)));
}

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = imageSize(displayImage);
  if (p.x >= size.x || p.y >= size.y) return;
  vec4 acc = imageLoad(accumImage, p);  // rgb: radiance sum, a: samples
  if (transparent == 0) {
    vec3 c = acc.a > 0.0 ? acc.rgb / acc.a * exposure : vec3(0.0);
    imageStore(displayImage, p, vec4(linearToSrgb(tonemapCurve(max(c, vec3(0.0)), curve)), 1.0));
    return;
  }
  // Transparent background: the straight (unpremultiplied) colour, as in the PNG, shown over a grey
  // checkerboard of 8-pixel squares with the pixel's alpha (compositing in display space, as image
  // viewers do).
  float hits = imageLoad(coverageImage, p).r;
  float alpha = acc.a > 0.0 ? clamp(hits / acc.a, 0.0, 1.0) : 0.0;
  vec3 c = hits > 0.0 ? acc.rgb / hits * exposure : vec3(0.0);
  vec3 checker = vec3((((p.x >> 3) ^ (p.y >> 3)) & 1) == 0 ? 0.4 : 0.6);
  imageStore(displayImage, p, vec4(mix(checker, linearToSrgb(tonemapCurve(max(c, vec3(0.0)), curve)), alpha), 1.0));
}
