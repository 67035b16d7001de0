// accumulate.glsl — adds a pixel's radiance sum to the rgba32f accumulation image with Kahan
// compensation (a second rgba32f image), so the mean stays precise after 100k+ samples.
// rgb: sum of radiance samples; a: number of samples (pixels may differ while a pass is in flight,
// and under adaptive sampling). Every second sample of a pixel (its 2nd, 4th, ... by the pixel's own
// count) is also added to the half image: the even and odd halves are two independent estimates of
// the pixel, whose difference is the error estimate (app/image/error_estimate.h).

layout(rgba32f, binding = CAUSTICA_IMAGE_ACCUM) uniform restrict image2D accumImage;
layout(rgba32f, binding = CAUSTICA_IMAGE_COMP) uniform restrict image2D compImage;
layout(rgba32f, binding = CAUSTICA_IMAGE_HALF) uniform restrict image2D halfImage;

void accumulate(ivec2 pixel, vec3 value, float samples) {
  vec4 sum = imageLoad(accumImage, pixel);
  vec4 comp = imageLoad(compImage, pixel);
  // `precise` keeps the compiler from simplifying (t - sum) - y to zero.
  precise vec4 y = vec4(value, samples) - comp;
  precise vec4 t = sum + y;
  precise vec4 c = (t - sum) - y;
  imageStore(accumImage, pixel, t);
  imageStore(compImage, pixel, c);
  // The count is an exact integer below 2^24 (and Kahan-compensated beyond): its parity before this
  // sample decides the half, so the halves stay balanced however the pixel's samples were dispatched.
  if (samples > 0.0 && (uint(sum.a - comp.a) & 1u) == 1u)
    imageStore(halfImage, pixel, imageLoad(halfImage, pixel) + vec4(value, samples));
}
