// sampling.cpp — C++ twins of the shader sampling routines (see sampling.h).
#include "shading/sampling.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace caustica {

float luminance(const glm::vec3& c) { return glm::dot(c, glm::vec3(0.2126f, 0.7152f, 0.0722f)); }

void orthonormalBasis(const glm::vec3& n, glm::vec3& t, glm::vec3& b) {
  float s = n.z >= 0.0f ? 1.0f : -1.0f;
  float a = -1.0f / (s + n.z);
  float c = n.x * n.y * a;
  t = glm::vec3(1.0f + s * n.x * n.x * a, s * c, -s * n.x);
  b = glm::vec3(c, s + n.y * n.y * a, -n.y);
}

glm::vec3 sampleCosineHemisphere(const glm::vec2& u) {
  float r = std::sqrt(u.x);
  float phi = 2.0f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - u.x))};
}

glm::vec2 sampleTriangleUniform(const glm::vec2& u) {
  float su = std::sqrt(u.x);
  return {1.0f - su, u.y * su};
}

float powerHeuristic(float a, float b) {
  if (!(a > 0.0f)) return 0.0f;
  float r = b / a;
  return 1.0f / (1.0f + r * r);
}

float fresnelDielectric(float cosI, float eta) {
  cosI = glm::clamp(cosI, 0.0f, 1.0f);
  float sin2T = (1.0f - cosI * cosI) / (eta * eta);
  if (sin2T >= 1.0f) return 1.0f;
  float cosT = std::sqrt(std::max(0.0f, 1.0f - sin2T));
  float rs = (cosI - eta * cosT) / (cosI + eta * cosT);
  float rp = (eta * cosI - cosT) / (eta * cosI + cosT);
  return 0.5f * (rs * rs + rp * rp);
}

bool refractDir(const glm::vec3& d, const glm::vec3& n, float eta, glm::vec3& t) {
  float cosI = -glm::dot(d, n);
  float sin2T = eta * eta * std::max(0.0f, 1.0f - cosI * cosI);
  if (sin2T >= 1.0f) {
    t = glm::vec3(0.0f);
    return false;
  }
  float cosT = std::sqrt(1.0f - sin2T);
  t = glm::normalize(eta * d + (eta * cosI - cosT) * n);
  return true;
}

float sampleDielectric(const glm::vec3& d, const glm::vec3& n, float eta, float u, glm::vec3& wi, bool& transmitted) {
  float cosI = -glm::dot(d, n);
  float f = fresnelDielectric(cosI, eta);
  if (u < f || !refractDir(d, n, 1.0f / eta, wi)) {
    wi = glm::reflect(d, n);
    transmitted = false;
    return 1.0f;
  }
  transmitted = true;
  return 1.0f / (eta * eta);
}

float cauchyIor(float iorD, float abbe, float lambdaNm) {
  if (abbe <= 0.0f) return iorD;
  const float lF = 486.1f, lC = 656.3f, lD = 587.6f;
  float b = (iorD - 1.0f) / (abbe * (1.0f / (lF * lF) - 1.0f / (lC * lC)));
  float a = iorD - b / (lD * lD);
  return a + b / (lambdaNm * lambdaNm);
}

glm::vec3 channelSensitivity(float lambdaNm) {
  const glm::vec3 mean(610.0f, 545.0f, 460.0f), sigma(30.0f, 30.0f, 22.0f);
  glm::vec3 x = (glm::vec3(lambdaNm) - mean) / sigma;
  return glm::exp(-0.5f * x * x) / (sigma * 2.50662827463f);
}

bool inCone(const glm::vec3& w, const glm::vec3& axis, float oneMinusCos) {
  glm::vec3 d = w - axis;
  return 0.5f * glm::dot(d, d) <= oneMinusCos * 1.0001f;
}

bool casterCone(const glm::vec3& p, const glm::vec3& n, const glm::vec4& sphere, glm::vec3& axis, float& oneMinusCos) {
  glm::vec3 d = glm::vec3(sphere) - p;
  float dist2 = glm::dot(d, d);
  float r2 = sphere.w * sphere.w;
  axis = glm::vec3(0.0f, 0.0f, 1.0f);
  oneMinusCos = 0.0f;
  if (!(dist2 > r2 * 1.0001f)) return false;
  float dist = std::sqrt(dist2);
  axis = d / dist;
  float sin2 = r2 / dist2;
  oneMinusCos = sin2 / (1.0f + std::sqrt(std::max(0.0f, 1.0f - sin2)));
  return oneMinusCos >= kCasterMinOneMinusCos && glm::dot(n, axis) > -std::sqrt(sin2);
}

glm::vec3 sampleUniformCone(const glm::vec3& axis, float oneMinusCos, const glm::vec2& u) {
  float omcT = u.x * oneMinusCos;
  float cosT = 1.0f - omcT;
  float sinT = std::sqrt(std::max(0.0f, omcT * (2.0f - omcT)));
  float phi = 2.0f * kPi * u.y;
  glm::vec3 t, b;
  orthonormalBasis(axis, t, b);
  return glm::normalize(sinT * std::cos(phi) * t + sinT * std::sin(phi) * b + cosT * axis);
}

bool casterFacesLights(const glm::vec3& p, const glm::vec3& axis, float oneMinusCos, const glm::vec4& lights,
                       float margin) {
  glm::vec3 d = glm::vec3(lights) - p;
  float dist2 = glm::dot(d, d);
  if (!(lights.w >= 0.0f)) return false;
  if (dist2 <= lights.w * lights.w) return true;
  float dist = std::sqrt(dist2);
  float angleLights = std::asin(std::min(1.0f, lights.w / dist));
  float angleCaster = std::asin(std::sqrt(oneMinusCos * (2.0f - oneMinusCos)));
  float between = 2.0f * std::asin(std::min(1.0f, 0.5f * glm::length(axis - d / dist)));
  return between <= angleCaster + angleLights + margin;
}

bool guideLobe(const glm::uvec4& cell, const glm::vec3& n, glm::vec3& axis, float& kappa) {
  axis = n;
  kappa = 0.0f;
  if (cell.x < kMinGuidePhotons) return false;
  glm::vec3 sum = glm::vec3(glm::ivec3(glm::uvec3(cell.y, cell.z, cell.w))) / (static_cast<float>(cell.x) * gpu::kCellDirScale);
  float len = glm::length(sum);
  if (!(len > 1.0e-3f) || glm::dot(sum, n) <= 0.0f) return false;
  float r = std::min(len, 0.9999f);
  kappa = std::min(r * (3.0f - r * r) / (1.0f - r * r), kMaxGuideKappa);
  axis = sum / len;
  return true;
}

float vmfNorm(float kappa) { return kappa / (2.0f * kPi * (1.0f - std::exp(-2.0f * kappa))); }

float vmfOneMinusCos(float kappa, float u) {
  return std::min(-std::log(u + (1.0f - u) * std::exp(-2.0f * kappa)) / kappa, 2.0f);
}

float guidePdf(const CasterVertex& v, std::uint32_t j, const glm::vec3& w) {
  glm::vec3 d = w - v.guideAxis[j];
  return v.guideNorm[j] * std::exp(-v.guideKappa[j] * 0.5f * glm::dot(d, d));
}

CasterVertex prepareCasters(const glm::vec3& p, const glm::vec3& n, float u, const glm::vec4* spheres, std::uint32_t count,
                            std::uint32_t refractMask, const glm::vec4& lights, float margin,
                            const glm::uvec4* guideCells, float guideProbability, std::uint32_t aimMask) {
  CasterVertex v;
  for (std::uint32_t i = 0; i < static_cast<std::uint32_t>(CasterVertex::kMax) && i < count; ++i) {
    glm::vec3 axis;
    float omc;
    bool cone = (aimMask & (1u << i)) != 0u && casterCone(p, n, spheres[i], axis, omc) &&
                ((refractMask & (1u << i)) == 0u || casterFacesLights(p, axis, omc, lights, margin));
    glm::vec3 gAxis[kGuideClasses];
    float kappa[kGuideClasses];
    bool guide[kGuideClasses] = {};
    std::uint32_t guides = 0;
    for (int c = 0; c < kGuideClasses; ++c) {
      gAxis[c] = n;
      kappa[c] = 0.0f;
      if (guideCells) guide[c] = guideLobe(guideCells[kGuideClasses * i + c], n, gAxis[c], kappa[c]);
      guides += guide[c];
    }
    if (!cone && guides == 0) continue;
    std::uint32_t k = v.usable++;
    v.axis[k] = cone ? axis : n;
    v.oneMinusCos[k] = cone ? omc : 0.0f;
    v.invSolidAngle[k] = cone ? 1.0f / (2.0f * kPi * omc) : 0.0f;
    // The guide lobes share guideProbability of the caster's part equally (all of it without a cone).
    float share = guides == 0 ? 0.0f : (cone ? guideProbability : 1.0f) / static_cast<float>(guides);
    for (int c = 0; c < kGuideClasses; ++c) {
      std::uint32_t j = kGuideClasses * k + c;
      v.guideAxis[j] = gAxis[c];
      v.guideKappa[j] = kappa[c];
      v.guideNorm[j] = guide[c] ? vmfNorm(kappa[c]) : 0.0f;
      v.guideWeight[j] = guide[c] ? share : 0.0f;
    }
  }
  if (v.usable > 0) v.pick = std::min(static_cast<std::uint32_t>(u * static_cast<float>(v.usable)), v.usable - 1);
  return v;
}

float diffuseDirectionPdf(const CasterVertex& v, float casterProbability, const glm::vec3& n, const glm::vec3& w) {
  float cosPdf = std::max(glm::dot(n, w), 0.0f) * kInvPi;
  if (v.usable == 0) return cosPdf;
  float sum = 0.0f;
  for (std::uint32_t k = 0; k < v.usable; ++k) {
    float coneWeight = 1.0f;
    for (std::uint32_t c = 0; c < kGuideClasses; ++c) {
      std::uint32_t j = kGuideClasses * k + c;
      coneWeight -= v.guideWeight[j];
      if (v.guideWeight[j] > 0.0f) sum += v.guideWeight[j] * guidePdf(v, j, w);
    }
    if (coneWeight > 1.0e-6f && inCone(w, v.axis[k], v.oneMinusCos[k])) sum += coneWeight * v.invSolidAngle[k];
  }
  return (1.0f - casterProbability) * cosPdf + casterProbability * sum / static_cast<float>(v.usable);
}

// One body for the cone, the guide lobes and cosine sampling, as the shader has it.
glm::vec3 sampleDiffuseDirection(const CasterVertex& v, float casterProbability, const glm::vec3& n, float uPick,
                                 const glm::vec2& u) {
  bool cone = v.usable > 0 && uPick < casterProbability;
  glm::vec3 axis = n;
  float omcT = 0.0f;
  if (cone) {
    axis = v.axis[v.pick];
    omcT = u.x * v.oneMinusCos[v.pick];  // 1 - cos(theta)
    // A guide lobe instead, chosen with uPick rescaled to [0, 1) over the caster's part.
    float pick = uPick / casterProbability, run = 0.0f;
    for (std::uint32_t c = 0; c < kGuideClasses; ++c) {
      std::uint32_t j = kGuideClasses * v.pick + c;
      float w0 = run;
      run += v.guideWeight[j];
      if (pick >= w0 && pick < run) {
        axis = v.guideAxis[j];
        omcT = vmfOneMinusCos(v.guideKappa[j], u.x);
      }
    }
  }
  float s = std::sqrt(cone ? std::max(0.0f, omcT * (2.0f - omcT)) : u.x);  // sin(theta)
  float z = cone ? 1.0f - omcT : std::sqrt(std::max(0.0f, 1.0f - u.x));    // cos(theta)
  float phi = 2.0f * kPi * u.y;
  glm::vec3 t, b;
  orthonormalBasis(axis, t, b);
  return glm::normalize(s * std::cos(phi) * t + s * std::sin(phi) * b + z * axis);
}

}  // namespace caustica
