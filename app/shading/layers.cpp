// layers.cpp — C++ twins of glsl/lib/layers.glsl (see layers.h): same names, same arithmetic.
#include "shading/layers.h"

#include <algorithm>
#include <cmath>

#include "shared/sheen_albedo.h"
#include "util/math_constants.h"

namespace caustica {
namespace {
float mixf(float a, float b, float t) { return a * (1.0f - t) + b * t; }
float maxComponent3(const glm::vec3& c) { return std::max(c.x, std::max(c.y, c.z)); }
}  // namespace

float coatFresnel(float cosTheta) {
  float m = glm::clamp(1.0f - std::abs(cosTheta), 0.0f, 1.0f);
  float m2 = m * m;
  return kCoatF0 + (1.0f - kCoatF0) * (m2 * m2 * m);
}

float sheenRoughnessClamped(float roughness) { return glm::clamp(roughness, kMinSheenRoughness, 1.0f); }

float sheenD(const glm::vec3& h, float alpha) {
  float invAlpha = 1.0f / alpha;
  float sin2 = std::max(0.0f, 1.0f - h.z * h.z);
  return (2.0f + invAlpha) * std::pow(sin2, 0.5f * invAlpha) / (2.0f * kPi);
}

float sheenL(float x, float alpha) {
  float t = (1.0f - alpha) * (1.0f - alpha);
  float a = mixf(21.5473f, 25.3245f, t);
  float b = mixf(3.82987f, 3.32435f, t);
  float c = mixf(0.19823f, 0.16801f, t);
  float d = mixf(-1.97760f, -1.27393f, t);
  float e = mixf(-4.32054f, -4.85967f, t);
  return a / (1.0f + b * std::pow(x, c)) + d * x + e;
}

float sheenLambda(float cosTheta, float alpha) {
  float c = std::abs(cosTheta);
  return c < 0.5f ? std::exp(sheenL(c, alpha)) : std::exp(2.0f * sheenL(0.5f, alpha) - sheenL(1.0f - c, alpha));
}

float sheenVisibility(float cosO, float cosI, float alpha) {
  return 1.0f / ((1.0f + sheenLambda(cosO, alpha) + sheenLambda(cosI, alpha)) * (4.0f * cosO * cosI));
}

float sheenAlbedo(float cosTheta, float roughness) {
  constexpr int nMu = CAUSTICA_SHEEN_ALBEDO_MU, nR = CAUSTICA_SHEEN_ALBEDO_ROUGHNESS;
  float x = std::sqrt(glm::clamp(cosTheta, 0.0f, 1.0f)) * float(nMu - 1);
  float y = (sheenRoughnessClamped(roughness) - kMinSheenRoughness) / (1.0f - kMinSheenRoughness) * float(nR - 1);
  int i = std::min(int(x), nMu - 2), j = std::min(int(y), nR - 2);
  float fx = x - float(i), fy = y - float(j);
  int k = j * nMu + i;
  float lo = mixf(kSheenAlbedo[k], kSheenAlbedo[k + 1], fx);
  float hi = mixf(kSheenAlbedo[k + nMu], kSheenAlbedo[k + nMu + 1], fx);
  return mixf(lo, hi, fy);
}

glm::vec3 sheenEval(const glm::vec3& tint, float alpha, const glm::vec3& wo, const glm::vec3& wi) {
  glm::vec3 h = wo + wi;
  float len = glm::length(h);
  if (!(len > 0.0f)) return glm::vec3(0.0f);
  h /= len;
  float e = std::max(sheenAlbedo(wo.z, std::sqrt(alpha)), kMinSheenAlbedo);
  return tint * (sheenD(h, alpha) * sheenVisibility(wo.z, wi.z, alpha) / e);
}

glm::vec3 sampleUniformHemisphere(const glm::vec2& u) {
  float z = u.x;
  float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  float phi = 2.0f * kPi * u.y;
  return glm::vec3(r * std::cos(phi), r * std::sin(phi), z);
}

LayerWeights layerWeights(float coat, float cosCoat, const glm::vec3& sheenColor, float sheenRoughness, float cosBase,
                          float baseAlbedo) {
  LayerWeights w;
  w.coat = coat * coatFresnel(cosCoat);
  float c = maxComponent3(sheenColor);
  w.sheen = c > 0.0f ? c * std::min(sheenAlbedo(cosBase, sheenRoughness), 1.0f) : 0.0f;
  float lean = w.coat / (w.coat + (1.0f - w.coat) * glm::clamp(baseAlbedo, 0.0f, 1.0f));
  w.coatPick = w.coat > 0.0f ? std::min(lean, std::max(w.coat, 0.9f)) : 0.0f;
  return w;
}

glm::vec3 layeredAlbedo(const LayerWeights& w, const glm::vec3& sheenColor, const glm::vec3& baseAlbedo) {
  float c = maxComponent3(sheenColor);
  glm::vec3 sheen = c > 0.0f ? sheenColor / c : glm::vec3(0.0f);
  return glm::vec3(w.coat) + (1.0f - w.coat) * (w.sheen * sheen + (1.0f - w.sheen) * baseAlbedo);
}

}  // namespace caustica
