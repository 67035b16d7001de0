// accumulate.glsl — adds a pixel's radiance samples to the rgba32f accumulation image with Kahan
// compensation (a second rgba32f image), so the mean stays precise after 100k+ samples.
// rgb: sum of radiance samples; a: number of samples (pixels may differ while a pass is in flight,
// and under adaptive sampling). Every second sample of a pixel (its 2nd, 4th, ... by the pixel's own
// count) is also added to the half image: the even and odd halves are two independent estimates of
// the pixel, whose difference is the error estimate (app/image/error_estimate.h). The moment image holds
// each channel's sum of squared deviations from the running mean (Welford's M2): a per-pixel sample
// variance with n - 1 degrees of freedom, for adaptive sampling's allocation (docs/adaptive-sampling.md).
// A shader that adds several samples per invocation loads the sums once (loadPixelSums), adds each
// sample in order (addSample) and stores once: the same arithmetic as one accumulate() per sample.

layout(rgba32f, binding = CAUSTICA_IMAGE_ACCUM) uniform restrict image2D accumImage;
layout(rgba32f, binding = CAUSTICA_IMAGE_COMP) uniform restrict image2D compImage;
layout(rgba32f, binding = CAUSTICA_IMAGE_HALF) uniform restrict image2D halfImage;
layout(rgba32f, binding = CAUSTICA_IMAGE_MOMENT) uniform restrict image2D momentImage;

// One pixel's running sums as the three images hold them.
struct PixelSums {
  vec4 sum;   // accumulation image: rgb radiance sum, a sample count
  vec4 comp;  // its Kahan compensation
  vec4 halves;// the odd-numbered samples' sum and count
  vec4 moment;// rgb: sum over samples of (x - mean before) (x - mean after), radiance^2; a unused (0)
};

PixelSums loadPixelSums(ivec2 pixel) {
  return PixelSums(imageLoad(accumImage, pixel), imageLoad(compImage, pixel), imageLoad(halfImage, pixel),
                   imageLoad(momentImage, pixel));
}

void storePixelSums(ivec2 pixel, PixelSums p) {
  imageStore(accumImage, pixel, p.sum);
  imageStore(compImage, pixel, p.comp);
  imageStore(halfImage, pixel, p.halves);
  imageStore(momentImage, pixel, p.moment);
}

// Adds one sample (value, samples = 1; or 0, 0 for a rejected one).
void addSample(inout PixelSums p, vec3 value, float samples) {
  // The count is an exact integer below 2^24 (and Kahan-compensated beyond): its parity before this
  // sample decides the half, so the halves stay balanced however the pixel's samples were dispatched.
  float before = p.sum.a - p.comp.a;
  bool odd = (uint(before) & 1u) == 1u;
  // Welford: with d = x - mean before, M2 += d (x - mean after) = d^2 before / (before + 1); the
  // Kahan-compensated sums give the mean before. Each term is >= 0: no cancellation.
  if (samples > 0.0 && before > 0.0) {
    vec3 d = value - (p.sum.rgb - p.comp.rgb) / before;
    p.moment.rgb += d * d * (before / (before + 1.0));
  }
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
