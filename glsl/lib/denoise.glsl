// denoise.glsl — the tap weights of the à-trous denoiser (denoise.comp; docs/denoising.md). C++ twin:
// app/image/denoise.h (same names, same arithmetic). Needs sampling.glsl (luminance).

const int kDenoiseNormalSquarings = 7;        // normals compared by dot^(2^7) = dot^128 (SVGF's exponent)
const float kDenoiseMinTemporalSamples = 4.0; // fewer samples: the variance comes from the neighbourhood
const float kDenoiseTiny = 1e-30;             // keeps a zero scale from dividing 0 by 0
const float kDenoiseNormalMinLength = 1e-3;   // a mean normal shorter than this: no surface
const float kDenoiseDepthRelative = 1e-3;     // distance differences below this fraction are ignored

// 1 when both pixels saw no surface (normal 0), 0 when one did not, else max(dot, 0)^(2^7).
float denoiseNormalWeight(vec3 np, vec3 nq) {
  bool noP = np.x == 0.0 && np.y == 0.0 && np.z == 0.0;
  bool noQ = nq.x == 0.0 && nq.y == 0.0 && nq.z == 0.0;
  if (noP || noQ) return noP && noQ ? 1.0 : 0.0;
  precise float c = max(np.x * nq.x + np.y * nq.y + np.z * nq.z, 0.0);
  for (int i = 0; i < kDenoiseNormalSquarings; ++i) c *= c;
  return c;
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
