// denoise.h — the edge-aware à-trous denoiser (docs/denoising.md) on the CPU: the C++ twin of
// glsl/lib/denoise.glsl and glsl/denoise.comp (same names, same arithmetic), for tests and tools, and the
// feature images (--aov) from the renderer's feature sums. No GL.
//
// The filter: the pixel's mean radiance is divided by its albedo (demodulated), then filtered by
// `iterations` passes of a 3x3 kernel with taps 2^k pixels apart (à-trous, Dammertz et al. 2010), each
// tap weighted by normal, distance and luminance difference, the last scaled by the standard deviation
// of the pixels' means (their variance propagated through the passes as in SVGF, Schied et al. 2017); then
// multiplied by the albedo again. Where the variance of the mean is small, neighbours that differ get no
// weight: a converged image is returned unchanged, and a caustic or a hard shadow without a feature
// edge is kept by its noise alone. What the passes took from each pixel (a firefly, the sparse samples
// of a caustic) is then spread over its surface by `residualPasses` passes weighted by normal, distance
// and relative luminance and added back, so the image and its regions keep their mean.
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "image/image_io.h"

namespace caustica {

struct DenoiseSettings {
  int iterations = 5;            // à-trous passes: taps 1, 2, 4, ... 2^(iterations-1) pixels apart
  int residualPasses = 5;        // passes that spread the residual (0: the filtered image as it is)
  float sigmaLuminance = 6.0f;   // luminance difference, in standard deviations of the noise, for weight 1/e
  float sigmaDepth = 1.0f;       // distance difference, in multiples of the local distance gradient x offset
  // Residual passes: relative difference of the filtered illumination's luminance, |a - b| / (a + b), for
  // weight 1/e: the light a bright feature lost is spread over pixels about as bright.
  float sigmaResidual = 0.3f;
  // The spread residual a pixel gets is at most this many standard deviations of its own mean (its
  // luminance; pixels with 4 samples or more): a pixel without noise (an emitter seen directly) keeps
  // its mean, and as samples accumulate the output converges to the raw mean everywhere.
  float residualBound = 3.0f;
  float albedoFloor = 0.01f;     // albedo below this is taken as this when demodulating
};

// Normals are compared by dot^(2^kDenoiseNormalSquarings) (SVGF's exponent 128).
constexpr int kDenoiseNormalSquarings = 7;
// Pixels with fewer samples than this take their variance from their neighbourhood (a per-pixel
// moment over fewer samples is too noisy), as SVGF does for short histories.
constexpr float kDenoiseMinTemporalSamples = 4.0f;

// The guide of a pixel (one rgba32f texel): unit normal x and y, the normal's z sign times (1 + albedo
// luminance), distance; (0, 0, 0, distance) where no surface was seen. And its two decoders.
glm::vec4 denoiseGuide(const glm::vec3& n, float albedoLum, float distance);
glm::vec3 denoiseGuideNormal(const glm::vec4& guide);
float denoiseGuideAlbedo(const glm::vec4& guide);
// The luminance difference for weight 1/e between pixel p and tap q: sigma standard deviations of the
// difference of their means, p's variance always counting and q's as far as q has p's albedo luminance
// (exp(-|difference| / 0.01)): the same surface's noise (a firefly, a caustic's sparse samples) is
// shared, an antialiased albedo or emitter edge's is not.
float denoiseLuminanceScale(float sigma, float varP, float varQ, float albedoP, float albedoQ);
// The weight of a tap for its normal: 1 when both pixels saw no surface (normal 0), 0 when one did not,
// else max(dot, 0)^(2^kDenoiseNormalSquarings). Unit (or zero) normals.
float denoiseNormalWeight(const float np[3], const float nq[3]);
// The edge-stopping weight of tap q for pixel p, the kernel's weight aside:
// normal weight x exp(-(|zp - zq| / depthScale + |luminance difference| / luminanceScale)).
// lumDiff: luminance of p's albedo x (q's illumination - p's); the scales are > 0.
float denoiseTapWeight(const float np[3], const float nq[3], float zp, float zq, float depthScale, float lumDiff,
                       float luminanceScale);

// The variance of a pixel's mean luminance l from n >= 2 samples whose squared luminances sum to m2: the
// sample variance / n, less the rounding error of a float sum of n squares ((n + 2) ULP of their mean),
// so that a pixel whose samples all agree gets exactly 0.
float denoiseMeanVariance(float n, float m2, float l);

// The residual passes' correction of a pixel scaled down so that its luminance is at most `bound`
// standard deviations of the pixel's mean (n samples, squared luminances summing to m2, mean luminance l).
glm::vec3 denoiseBoundedCorrection(const glm::vec3& correction, float bound, float n, float m2, float l);

// The inputs of the filter: the renderer's sums (AccumulationState's accum, albedo and normal images,
// width*height*4 floats each; count in accum's alpha).
struct DenoiseInput {
  int width = 0, height = 0;
  const std::vector<float>* accum = nullptr;   // rgb radiance sum, a sample count
  const std::vector<float>* albedo = nullptr;  // rgb albedo sum, a luminance^2 sum
  const std::vector<float>* normal = nullptr;  // xyz normal sum, w distance sum
};

// The filtered sums in the accumulation image's convention (rgb = denoised mean x count, a = count),
// width*height*4; pixels without samples stay 0. Throws Error when the inputs' sizes differ.
std::vector<float> denoiseSums(const DenoiseInput& in, const DenoiseSettings& settings = {});

// The feature images users may write (--aov), means per pixel over its samples.
struct FeatureImages {
  Image albedo;    // rgb albedo
  Image normal;    // rgb = xyz: mean shading normal (world space; 0 where no surface was seen)
  Image depth;     // every channel: mean distance to the first non-specular hit (0 where none)
  Image variance;  // every channel: variance of the pixel's mean luminance (denoiseMeanVariance; 0 below 2 samples)
};
FeatureImages featureImages(const DenoiseInput& in);

}  // namespace caustica
