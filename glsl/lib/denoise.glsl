// denoise.glsl — the arithmetic of the à-trous denoiser (denoise.comp; docs/denoising.md): the guide a
// pixel is compared by, the variance of its mean and the tap weights. C++ twin: app/image/denoise.h
// (same names, same arithmetic). Needs sampling.glsl (luminance).

const int kDenoiseNormalSquarings = 7;        // normals compared by dot^(2^7) = dot^128 (SVGF's exponent)
const float kDenoiseMinTemporalSamples = 4.0; // fewer samples: the variance comes from the neighbourhood
const float kDenoiseTiny = 1e-30;             // keeps a zero scale from dividing 0 by 0
const float kDenoiseNormalMinLength = 1e-3;   // a mean normal shorter than this: no surface
const float kDenoiseDepthRelative = 1e-3;     // distance differences below this fraction are ignored
const float kDenoiseFloatEps = 1.1920929e-7;  // 2^-23
const float kDenoiseAlbedoMatch = 0.01;       // albedo luminance difference for which a neighbour's variance counts 1/e

// The guide of a pixel, one rgba32f texel: unit normal x and y, then the normal's z sign times
// (1 + albedo luminance), then the distance; (0, 0, 0, distance) where no surface was seen.
vec4 denoiseGuide(vec3 n, float albedoLum, float distance) {
  if (n.x == 0.0 && n.y == 0.0 && n.z == 0.0) return vec4(0.0, 0.0, 0.0, distance);
  return vec4(n.xy, (n.z < 0.0 ? -1.0 : 1.0) * (1.0 + albedoLum), distance);
}
vec3 denoiseGuideNormal(vec4 g) {
  if (g.z == 0.0) return vec3(0.0);
  return vec3(g.xy, (g.z < 0.0 ? -1.0 : 1.0) * sqrt(max(1.0 - g.x * g.x - g.y * g.y, 0.0)));
}
float denoiseGuideAlbedo(vec4 g) { return g.z == 0.0 ? 0.0 : abs(g.z) - 1.0; }

// The variance of a pixel's mean luminance l from n >= 2 samples whose squared luminances sum to m2: the
// sample variance / n, less the rounding error of a float sum of n squares ((n + 2) ULP of their mean),
// so that a pixel whose samples all agree gets exactly 0.
float denoiseMeanVariance(float n, float m2, float l) {
  float meanSquare = m2 / n;
  return max(meanSquare - l * l - (n + 2.0) * kDenoiseFloatEps * meanSquare, 0.0) / (n - 1.0);
}

// The residual passes' correction of a pixel scaled down so that its luminance is at most `bound`
// standard deviations of the pixel's mean (n samples, squared luminances summing to m2, mean luminance l).
vec3 denoiseBoundedCorrection(vec3 correction, float bound, float n, float m2, float l) {
  float limit = bound * sqrt(denoiseMeanVariance(n, m2, l));
  float size = abs(luminance(correction));
  return size > limit ? correction * (limit / size) : correction;
}

// 1 when both pixels saw no surface (normal 0), 0 when one did not, else max(dot, 0)^(2^7).
float denoiseNormalWeight(vec3 np, vec3 nq) {
  bool noP = np.x == 0.0 && np.y == 0.0 && np.z == 0.0;
  bool noQ = nq.x == 0.0 && nq.y == 0.0 && nq.z == 0.0;
  if (noP || noQ) return noP && noQ ? 1.0 : 0.0;
  precise float c = max(np.x * nq.x + np.y * nq.y + np.z * nq.z, 0.0);
  for (int i = 0; i < kDenoiseNormalSquarings; ++i) c *= c;
  return c;
}

// The luminance difference for weight 1/e between pixel p and tap q: sigma standard deviations of the
// difference of their means. p's own variance always counts; q's as far as q has p's albedo (the same
// surface's noise: a firefly or a caustic's sparse samples, which p should share), not across an albedo
// or emitter edge (an antialiased edge pixel's variance is not p's noise).
float denoiseLuminanceScale(float sigma, float varP, float varQ, float albedoP, float albedoQ) {
  float match = exp(-abs(albedoP - albedoQ) / kDenoiseAlbedoMatch);
  return sigma * sqrt(varP + match * varQ) + kDenoiseTiny;
}

// The edge-stopping weight of tap q for pixel p, the kernel's weight aside: normal weight x
// exp(-(|zp - zq| / depthScale + |lumDiff| / luminanceScale)); scales > 0.
float denoiseTapWeight(vec3 np, vec3 nq, float zp, float zq, float depthScale, float lumDiff, float luminanceScale) {
  return denoiseNormalWeight(np, nq) * exp(-(abs(zp - zq) / depthScale + abs(lumDiff) / luminanceScale));
}

// The distance's scale for a tap `offset` pixels away, from p's distance gradient (per pixel) and distance z.
float denoiseDepthScale(float sigmaDepth, float gradient, int offset, float z) {
  return sigmaDepth * gradient * float(offset) + kDenoiseDepthRelative * abs(z) + kDenoiseTiny;
}
