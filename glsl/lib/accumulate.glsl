// accumulate.glsl — adds a pixel's radiance sum to the rgba32f accumulation image with Kahan
// compensation (a second rgba32f image), so the mean stays precise after 100k+ samples.
// rgb: sum of radiance samples; a: number of samples (pixels may differ while a pass is in flight).

layout(rgba32f, binding = CAUSTICA_IMAGE_ACCUM) uniform restrict image2D accumImage;
layout(rgba32f, binding = CAUSTICA_IMAGE_COMP) uniform restrict image2D compImage;

void accumulate(ivec2 pixel, vec3 value, float samples) {
  vec4 sum = imageLoad(accumImage, pixel);
  vec4 comp = imageLoad(compImage, pixel);
  // `precise` keeps the compiler from simplifying (t - sum) - y to zero.
  precise vec4 y = vec4(value, samples) - comp;
  precise vec4 t = sum + y;
  precise vec4 c = (t - sum) - y;
  imageStore(accumImage, pixel, t);
  imageStore(compImage, pixel, c);
}
