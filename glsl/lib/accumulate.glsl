// accumulate.glsl — adds a pixel's radiance samples to the rgba32f accumulation image with Kahan
// compensation (a second rgba32f image), so the mean stays precise after 100k+ samples.
// rgb: sum of radiance samples; a: number of samples (pixels may differ while a pass is in flight,
// and under adaptive sampling). Every second sample of a pixel (its 2nd, 4th, ... by the pixel's own
// count) is also added to the half image: the even and odd halves are two independent estimates of
// the pixel, whose difference is the error estimate (app/image/error_estimate.h).
// A shader that adds several samples per invocation loads the sums once (loadPixelSums), adds each
// sample in order (addSample) and stores once: the same arithmetic as one accumulate() per sample.

layout(rgba32f, binding = CAUSTICA_IMAGE_ACCUM) uniform restrict image2D accumImage;
layout(rgba32f, binding = CAUSTICA_IMAGE_COMP) uniform restrict image2D compImage;
layout(rgba32f, binding = CAUSTICA_IMAGE_HALF) uniform restrict image2D halfImage;

// One pixel's running sums as the three images hold them.
struct PixelSums {
  vec4 sum;   // accumulation image: rgb radiance sum, a sample count
  vec4 comp;  // its Kahan compensation
  vec4 halves;// the odd-numbered samples' sum and count
};

PixelSums loadPixelSums(ivec2 pixel) {
  return PixelSums(imageLoad(accumImage, pixel), imageLoad(compImage, pixel), imageLoad(halfImage, pixel));
}

void storePixelSums(ivec2 pixel, PixelSums p) {
  imageStore(accumImage, pixel, p.sum);
  imageStore(compImage, pixel, p.comp);
  imageStore(halfImage, pixel, p.halves);
}

// Adds one sample (value, samples = 1; or 0, 0 for a rejected one).
void addSample(inout PixelSums p, vec3 value, float samples) {
  // The count is an exact integer below 2^24 (and Kahan-compensated beyond): its parity before this
  // sample decides the half, so the halves stay balanced however the pixel's samples were dispatched.
  bool odd = (uint(p.sum.a - p.comp.a) & 1u) == 1u;
  // `precise` keeps the compiler from simplifying (t - sum) - y to zero.
  precise vec4 y = vec4(value, samples) - p.comp;
  precise vec4 t = p.sum + y;
  precise vec4 c = (t - p.sum) - y;
  p.sum = t;
  p.comp = c;
  if (samples > 0.0 && odd) p.halves += vec4(value, samples);
}

void accumulate(ivec2 pixel, vec3 value, float samples) {
  PixelSums p = loadPixelSums(pixel);
  addSample(p, value, samples);
  storePixelSums(pixel, p);
}
