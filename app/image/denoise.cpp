// denoise.cpp — the à-trous denoiser on the CPU, step for step as glsl/denoise.comp runs it (prepare,
// then the passes), and the --aov feature images. Radiance linear; distances in scene units.
#include "image/denoise.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include <glm/glm.hpp>

#include "shading/sampling.h"
#include "util/error.h"

namespace caustica {

namespace {

using glm::vec3;
using glm::vec4;

constexpr float kTiny = 1e-30f;             // keeps a zero scale from dividing 0 by 0
constexpr float kNormalMinLength = 1e-3f;   // a mean normal shorter than this: no surface
constexpr float kDepthRelative = 1e-3f;     // distance differences below this fraction are ignored
constexpr float kDenoiseAlbedoMatch = 0.01f;  // albedo luminance difference for which a neighbour's variance counts 1/e
// The kernel of a pass by |offset|: 1/4, 1/2, 1/4 (3x3 taps; 5x5 B3-spline taps measured no better and
// cost 2.8x as much: docs/denoising.md).
constexpr float kKernel[2] = {1.0f / 2.0f, 1.0f / 4.0f};

// One pixel's inputs as the shader reads them.
class Sums {
 public:
  explicit Sums(const DenoiseInput& in) : in_(in) {}
  bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < in_.width && y < in_.height; }
  vec4 at(const std::vector<float>& v, int x, int y) const {
    const std::size_t i = (static_cast<std::size_t>(y) * in_.width + x) * 4;
    return vec4(v[i], v[i + 1], v[i + 2], v[i + 3]);
  }
  vec4 accum(int x, int y) const { return at(*in_.accum, x, y); }
  vec4 albedo(int x, int y) const { return at(*in_.albedo, x, y); }
  vec4 normal(int x, int y) const { return at(*in_.normal, x, y); }
  // pixelNormalDistance: unit mean normal (0: none) and mean distance; w = -1 without samples.
  vec4 normalDistance(int x, int y) const {
    const vec4 acc = accum(x, y);
    if (!(acc.w > 0.0f)) return vec4(0.0f, 0.0f, 0.0f, -1.0f);
    const vec4 ns = normal(x, y);
    const vec3 nrm = vec3(ns) / acc.w;
    const float len = glm::length(nrm);
    return vec4(len > kNormalMinLength ? nrm / len : vec3(0.0f), ns.w / acc.w);
  }

 private:
  const DenoiseInput& in_;
};

// The smaller one-sided difference of the mean distance towards the two
// neighbours along d that have samples (0 when neither has).
float denoiseAxisGradient(const Sums& s, int x, int y, int dx, int dy, float z) {
  float best = 3.0e38f;
  for (int sign = -1; sign <= 1; sign += 2) {
    const int qx = x + sign * dx, qy = y + sign * dy;
    if (!s.inside(qx, qy)) continue;
    const vec4 g = s.normalDistance(qx, qy);
    if (g.w >= 0.0f) best = std::min(best, std::abs(g.w - z));
  }
  return best < 3.0e38f ? best : 0.0f;
}

float denoiseDepthScale(float sigmaDepth, float gradient, int offset, float z) {
  return sigmaDepth * gradient * static_cast<float>(offset) + kDepthRelative * std::abs(z) + kTiny;
}

// Calls visit(q, kernel weight, q's guide, q's normal) for each of the 8 taps of an à-trous pass around
// (x, y), `step` pixels apart, that lie in the image and have samples: denoise.comp's tap loop.
template <typename Visit>
void forEachTap(const Sums& s, const std::vector<vec4>& guide, int width, int x, int y, int step, Visit visit) {
  for (int j = -1; j <= 1; ++j)
    for (int k = -1; k <= 1; ++k) {
      if (j == 0 && k == 0) continue;
      const int qx = x + k * step, qy = y + j * step;
      if (!s.inside(qx, qy)) continue;
      const std::size_t q = static_cast<std::size_t>(qy) * width + qx;
      const vec4 gq = guide[q];
      if (gq.w < 0.0f) continue;
      const vec3 nqv = denoiseGuideNormal(gq);
      const float nq[3] = {nqv.x, nqv.y, nqv.z};
      visit(q, kKernel[std::abs(j)] * kKernel[std::abs(k)], gq, nq);
    }
}

}  // namespace

float denoiseNormalWeight(const float np[3], const float nq[3]) {
  const bool noP = np[0] == 0.0f && np[1] == 0.0f && np[2] == 0.0f;
  const bool noQ = nq[0] == 0.0f && nq[1] == 0.0f && nq[2] == 0.0f;
  if (noP || noQ) return noP && noQ ? 1.0f : 0.0f;
  float c = std::max(np[0] * nq[0] + np[1] * nq[1] + np[2] * nq[2], 0.0f);
  for (int i = 0; i < kDenoiseNormalSquarings; ++i) c *= c;
  return c;
}

glm::vec4 denoiseGuide(const glm::vec3& n, float albedoLum, float distance) {
  if (n.x == 0.0f && n.y == 0.0f && n.z == 0.0f) return glm::vec4(0.0f, 0.0f, 0.0f, distance);
  return glm::vec4(n.x, n.y, (n.z < 0.0f ? -1.0f : 1.0f) * (1.0f + albedoLum), distance);
}

glm::vec3 denoiseGuideNormal(const glm::vec4& g) {
  if (g.z == 0.0f) return glm::vec3(0.0f);
  return glm::vec3(g.x, g.y, (g.z < 0.0f ? -1.0f : 1.0f) * std::sqrt(std::max(1.0f - g.x * g.x - g.y * g.y, 0.0f)));
}

float denoiseGuideAlbedo(const glm::vec4& g) { return g.z == 0.0f ? 0.0f : std::abs(g.z) - 1.0f; }

float denoiseMeanVariance(float n, float m2, float l) {
  const float meanSquare = m2 / n;
  return std::max(meanSquare - l * l - (n + 2.0f) * std::numeric_limits<float>::epsilon() * meanSquare, 0.0f) / (n - 1.0f);
}

float denoiseLuminanceScale(float sigma, float varP, float varQ, float albedoP, float albedoQ) {
  const float match = std::exp(-std::abs(albedoP - albedoQ) / kDenoiseAlbedoMatch);
  return sigma * std::sqrt(varP + match * varQ) + kTiny;
}

glm::vec3 denoiseBoundedCorrection(const glm::vec3& correction, float bound, float n, float m2, float l) {
  const float limit = bound * std::sqrt(denoiseMeanVariance(n, m2, l));
  const float size = std::abs(luminance(correction));
  return size > limit ? correction * (limit / size) : correction;
}

float denoiseTapWeight(const float np[3], const float nq[3], float zp, float zq, float depthScaleValue, float lumDiff,
                       float luminanceScale) {
  return denoiseNormalWeight(np, nq) * std::exp(-(std::abs(zp - zq) / depthScaleValue + std::abs(lumDiff) / luminanceScale));
}

namespace {

// The images the stages hand on, as the shader's: ping and pong (demodulated illumination, variance of
// its mean; a pass reads ping, writes pong, then they swap), guide (normal, albedo, distance), centre
// (albedo, distance gradient), residual and spread (what the filter took: rgb, the filtered
// illumination's luminance), and the output (sums: rgb x n, n a pixel).
struct DenoiseImages {
  std::vector<vec4> ping, pong, guide, centre, residual, spread;
  std::vector<float> out;
};

std::size_t pixelIndex(int w, int x, int y) { return static_cast<std::size_t>(y) * w + x; }

// Output pixel i as sums: value x n, and n.
void writeOut(std::vector<float>& out, std::size_t i, vec3 value, float n) {
  const vec3 c = value * n;
  out[i * 4 + 0] = c.x;
  out[i * 4 + 1] = c.y;
  out[i * 4 + 2] = c.z;
  out[i * 4 + 3] = n;
}

// The variance of pixel (x, y)'s luminance from the luminance moments of the similar pixels around it
// (5x5), for pixels with too few samples for their own.
float neighbourhoodVariance(const Sums& s, const DenoiseSettings& settings, int x, int y, const vec4& nz, float gradient) {
  const float z = nz.w;
  float s0 = 0.0f, s1 = 0.0f, s2 = 0.0f;
  const float np[3] = {nz.x, nz.y, nz.z};
  for (int j = -2; j <= 2; ++j)
    for (int k = -2; k <= 2; ++k) {
      const int qx = x + k, qy = y + j;
      if (!s.inside(qx, qy)) continue;
      const vec4 gq = s.normalDistance(qx, qy);
      if (gq.w < 0.0f) continue;
      const float nq[3] = {gq.x, gq.y, gq.z};
      const vec4 aq = s.accum(qx, qy);
      const float l = luminance(vec3(aq) / aq.w);
      const float wq = denoiseTapWeight(np, nq, z, gq.w,
                                        denoiseDepthScale(settings.sigmaDepth, gradient, std::max(std::abs(j), std::abs(k)), z), 0.0f, 1.0f);
      s0 += wq;
      s1 += wq * l;
      s2 += wq * l * l;
    }
  const float m = s1 / s0;
  return std::max(s2 / s0 - m * m, 0.0f);
}

// prepare (CAUSTICA_DENOISE_PREPARE): demodulated illumination and the variance of the mean (ping), guide
// (normal, albedo, distance), albedo and distance gradient (centre).
void denoisePrepare(const Sums& s, const DenoiseSettings& settings, int w, int h, DenoiseImages& im) {
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const vec4 acc = s.accum(x, y);
      const std::size_t i = pixelIndex(w, x, y);
      const vec4 nz = s.normalDistance(x, y);
      if (!(acc.w > 0.0f)) {
        im.guide[i] = nz;
        im.ping[i] = vec4(0.0f);
        im.centre[i] = vec4(1.0f, 1.0f, 1.0f, 0.0f);
        continue;
      }
      const float n = acc.w;
      const vec3 mean = vec3(acc) / n;
      const vec4 as = s.albedo(x, y);
      const vec3 alb = glm::max(vec3(as) / n, vec3(settings.albedoFloor));
      const vec3 illum = mean / alb;
      const float z = nz.w;
      const float gradient = denoiseAxisGradient(s, x, y, 1, 0, z) + denoiseAxisGradient(s, x, y, 0, 1, z);
      const float var = n >= kDenoiseMinTemporalSamples ? denoiseMeanVariance(n, as.w, luminance(mean))
                                                        : neighbourhoodVariance(s, settings, x, y, nz, gradient);
      im.guide[i] = denoiseGuide(vec3(nz), luminance(alb), z);
      im.ping[i] = vec4(illum, var);
      im.centre[i] = vec4(alb, gradient);
    }
}

// One à-trous pass (CAUSTICA_DENOISE_PASS): 3x3 taps `step` pixels apart, weighted by the kernel and
// denoiseTapWeight, ping into pong. The last one writes the output, or, with residual passes to come,
// what the filter took from each pixel with the filtered luminance.
void denoisePass(const Sums& s, const DenoiseSettings& settings, int w, int h, int pass, DenoiseImages& im) {
  const int step = 1 << pass;
  const bool last = pass + 1 == settings.iterations;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = pixelIndex(w, x, y);
      const vec4 gp = im.guide[i];
      if (gp.w < 0.0f) {
        im.pong[i] = vec4(0.0f);
        if (last && !im.residual.empty()) im.residual[i] = vec4(0.0f);
        continue;
      }
      const vec4 cp = im.ping[i], ctr = im.centre[i];
      const vec3 npv = denoiseGuideNormal(gp);
      const float np[3] = {npv.x, npv.y, npv.z};
      const float ap = denoiseGuideAlbedo(gp);
      const float ds = denoiseDepthScale(settings.sigmaDepth, ctr.w, step, gp.w);
      float sumW = kKernel[0] * kKernel[0];
      vec3 sumI = sumW * vec3(cp);
      float sumV = sumW * sumW * cp.w;
      forEachTap(s, im.guide, w, x, y, step, [&](std::size_t q, float kernel, const vec4& gq, const float nq[3]) {
        const vec4 cq = im.ping[q];
        const float lumDiff = luminance(vec3(ctr) * (vec3(cq) - vec3(cp)));
        const float ls = denoiseLuminanceScale(settings.sigmaLuminance, cp.w, cq.w, ap, denoiseGuideAlbedo(gq));
        const float wq = kernel * denoiseTapWeight(np, nq, gp.w, gq.w, ds, lumDiff, ls);
        sumW += wq;
        sumI += wq * vec3(cq);
        sumV += wq * wq * cq.w;
      });
      const vec3 illum = sumI / sumW;
      im.pong[i] = vec4(illum, sumV / (sumW * sumW));
      if (!last) continue;
      const vec4 acc = s.accum(x, y);
      if (im.residual.empty()) writeOut(im.out, i, vec3(ctr) * illum, acc.w);
      else im.residual[i] = vec4(vec3(acc) / acc.w - vec3(ctr) * illum, luminance(illum));  // what the filter took away
    }
  std::swap(im.ping, im.pong);
}

// One residual pass (CAUSTICA_DENOISE_RESIDUAL): the same taps, weighted by normal, distance and the
// relative difference of the filtered illumination's luminance, spread what the filter took from each
// pixel over its surface and its like, so the image keeps its energy (a firefly's, a caustic's) where it
// was; the last one writes the output: the filtered image plus that.
void denoiseResidualPass(const Sums& s, const DenoiseSettings& settings, int w, int h, int pass, DenoiseImages& im) {
  const int step = 1 << pass;
  const bool last = pass + 1 == settings.residualPasses;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = pixelIndex(w, x, y);
      const vec4 gp = im.guide[i];
      if (gp.w < 0.0f) {
        im.spread[i] = vec4(0.0f);
        continue;
      }
      const vec4 rp = im.residual[i];
      const vec3 npv = denoiseGuideNormal(gp);
      const float np[3] = {npv.x, npv.y, npv.z};
      const float ds = denoiseDepthScale(settings.sigmaDepth, im.centre[i].w, step, gp.w);
      float sumW = kKernel[0] * kKernel[0];
      vec3 sumR = sumW * vec3(rp);
      forEachTap(s, im.guide, w, x, y, step, [&](std::size_t q, float kernel, const vec4& gq, const float nq[3]) {
        const vec4 rq = im.residual[q];
        const float wq = kernel * denoiseTapWeight(np, nq, gp.w, gq.w, ds, rp.w - rq.w, settings.sigmaResidual * (rp.w + rq.w) + kTiny);
        sumW += wq;
        sumR += wq * vec3(rq);
      });
      im.spread[i] = vec4(sumR / sumW, rp.w);
      if (last) {
        const vec4 acc = s.accum(x, y);
        vec3 correction = vec3(im.spread[i]);
        if (acc.w >= kDenoiseMinTemporalSamples)
          correction = denoiseBoundedCorrection(correction, settings.residualBound, acc.w, s.albedo(x, y).w, luminance(vec3(acc) / acc.w));
        writeOut(im.out, i, vec3(im.centre[i]) * vec3(im.ping[i]) + correction, acc.w);
      }
    }
  std::swap(im.residual, im.spread);
}

}  // namespace

std::vector<float> denoiseSums(const DenoiseInput& in, const DenoiseSettings& settings) {
  const std::size_t pixels = static_cast<std::size_t>(in.width) * static_cast<std::size_t>(in.height);
  if (!in.accum || !in.albedo || !in.normal || in.accum->size() != pixels * 4 || in.albedo->size() != pixels * 4 ||
      in.normal->size() != pixels * 4)
    throw Error("internal: the denoiser's inputs do not match the image size");
  if (settings.iterations < 1) throw Error("internal: the denoiser needs at least one pass");
  const Sums s(in);
  const int w = in.width, h = in.height;
  DenoiseImages im;
  im.ping.resize(pixels);
  im.guide.resize(pixels);
  im.centre.resize(pixels);
  denoisePrepare(s, settings, w, h, im);
  im.pong.resize(pixels);
  im.residual.resize(settings.residualPasses > 0 ? pixels : 0);
  im.out.assign(pixels * 4, 0.0f);
  for (int pass = 0; pass < settings.iterations; ++pass) denoisePass(s, settings, w, h, pass, im);
  im.spread.resize(im.residual.size());
  for (int pass = 0; pass < settings.residualPasses; ++pass) denoiseResidualPass(s, settings, w, h, pass, im);
  return im.out;
}

FeatureImages featureImages(const DenoiseInput& in) {
  const std::size_t pixels = static_cast<std::size_t>(in.width) * static_cast<std::size_t>(in.height);
  if (!in.accum || !in.albedo || !in.normal || in.accum->size() != pixels * 4 || in.albedo->size() != pixels * 4 ||
      in.normal->size() != pixels * 4)
    throw Error("internal: the feature sums do not match the image size");
  FeatureImages f;
  for (Image* img : {&f.albedo, &f.normal, &f.depth, &f.variance}) *img = Image{in.width, in.height, std::vector<float>(pixels * 3, 0.0f), {}};
  for (std::size_t i = 0; i < pixels; ++i) {
    const float n = (*in.accum)[i * 4 + 3];
    if (!(n > 0.0f)) continue;
    glm::vec3 mean(0.0f);
    for (int c = 0; c < 3; ++c) {
      f.albedo.rgb[i * 3 + c] = (*in.albedo)[i * 4 + c] / n;
      f.normal.rgb[i * 3 + c] = (*in.normal)[i * 4 + c] / n;
      mean[c] = (*in.accum)[i * 4 + c] / n;
    }
    const float var = n >= 2.0f ? denoiseMeanVariance(n, (*in.albedo)[i * 4 + 3], luminance(mean)) : 0.0f;
    for (int c = 0; c < 3; ++c) {
      f.depth.rgb[i * 3 + c] = (*in.normal)[i * 4 + 3] / n;
      f.variance.rgb[i * 3 + c] = var;
    }
  }
  return f;
}

}  // namespace caustica
