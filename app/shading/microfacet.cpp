// microfacet.cpp — C++ twins of glsl/lib/microfacet.glsl (see microfacet.h): same names, same arithmetic.
#include "shading/microfacet.h"

#include <algorithm>
#include <cmath>

#include "shading/layers.h"
#include "shading/sampling.h"
#include "util/math_constants.h"

namespace caustica {
namespace {

float maxComponent3(const glm::vec3& c) { return std::max(c.x, std::max(c.y, c.z)); }

// Reflection of wo about the unit vector h (both pointing away from the surface).
glm::vec3 reflectAbout(const glm::vec3& wo, const glm::vec3& h) { return 2.0f * glm::dot(wo, h) * h - wo; }

// The microfacet normal of a reflection (etap = 1) or refraction (etap = eta) from wo to wi, on +z's
// side; false when it does not exist or one of the directions lies behind it (a back-facing microfacet).
bool generalizedHalf(const glm::vec3& wo, const glm::vec3& wi, float etap, glm::vec3& wm) {
  wm = wi * etap + wo;
  float len = glm::length(wm);
  if (!(len > 0.0f)) return false;
  wm /= len;
  if (wm.z < 0.0f) wm = -wm;
  if (wm.z == 0.0f) return false;
  return glm::dot(wm, wi) * wi.z >= 0.0f && glm::dot(wm, wo) * wo.z >= 0.0f;
}

}  // namespace

float ggxD(const glm::vec3& h, float alpha) {
  if (h.z <= 0.0f) return 0.0f;
  float a2 = alpha * alpha;
  float d = (h.x * h.x + h.y * h.y) + h.z * h.z * a2;  // = cos^2 (a2 - 1) + 1 for unit h, without cancellation
  return a2 / (kPi * d * d);
}

float ggxLambda(const glm::vec3& w, float alpha) {
  float z2 = w.z * w.z;
  if (!(z2 > 0.0f)) return 3.0e38f;
  float x = alpha * alpha * (w.x * w.x + w.y * w.y) / z2;  // alpha^2 tan^2(theta)
  return 0.5f * x / (std::sqrt(1.0f + x) + 1.0f);          // (sqrt(1 + x) - 1) / 2 without cancellation
}

float ggxG1(const glm::vec3& w, float alpha) { return 1.0f / (1.0f + ggxLambda(w, alpha)); }

float ggxG2(const glm::vec3& wo, const glm::vec3& wi, float alpha) {
  return 1.0f / (1.0f + ggxLambda(wo, alpha) + ggxLambda(wi, alpha));
}

glm::vec3 ggxSampleVisibleNormal(const glm::vec3& wo, float alpha, const glm::vec2& u) {
  // Stretch to the unit-roughness configuration, sample the spherical cap of visible normals, unstretch.
  glm::vec3 ws = glm::normalize(glm::vec3(wo.x * alpha, wo.y * alpha, wo.z));
  float phi = 2.0f * kPi * u.x;
  float hz = (1.0f - u.y) * (1.0f + ws.z);  // z + ws.z, without the cancellation of the sum near the cap's edge
  float z = hz - ws.z;
  float sinTheta = std::sqrt(glm::clamp(1.0f - z * z, 0.0f, 1.0f));
  glm::vec3 h(sinTheta * std::cos(phi) + ws.x, sinTheta * std::sin(phi) + ws.y, hz);
  h = glm::vec3(h.x * alpha, h.y * alpha, std::max(h.z, 0.0f));
  float len = glm::length(h);
  return len > 0.0f ? h / len : glm::vec3(0.0f, 0.0f, 1.0f);
}

float ggxVisibleNormalPdf(const glm::vec3& wo, const glm::vec3& h, float alpha) {
  if (wo.z <= 0.0f) return 0.0f;
  return ggxG1(wo, alpha) * std::max(0.0f, glm::dot(wo, h)) * ggxD(h, alpha) / wo.z;
}

glm::vec3 fresnelSchlick(const glm::vec3& f0, const glm::vec3& f90, float cosTheta) {
  float m = glm::clamp(1.0f - cosTheta, 0.0f, 1.0f);
  float m2 = m * m;
  return f0 + (f90 - f0) * (m2 * m2 * m);
}

float plasticSpecularProbability(const Bsdf& b, const glm::vec3& wo) {
  float fo = maxComponent3(fresnelSchlick(b.f0, glm::vec3(b.f90), wo.z));
  float d = (1.0f - fo) * luminance(b.color);
  float p = fo + d > 0.0f ? fo / (fo + d) : 1.0f;
  return glm::clamp(p, 0.1f, 0.9f);
}

glm::vec3 bsdfEval(const Bsdf& b, const glm::vec3& wo, const glm::vec3& wi) {
  if (wo.z <= 0.0f) return glm::vec3(0.0f);
  if (b.lobe == kLobeRoughGlass) {
    if (wi.z == 0.0f) return glm::vec3(0.0f);
    bool reflect = wi.z > 0.0f;
    float etap = reflect ? 1.0f : b.eta;
    glm::vec3 wm;
    if (!generalizedHalf(wo, wi, etap, wm)) return glm::vec3(0.0f);
    float f = fresnelDielectric(glm::dot(wo, wm), b.eta);
    float dg = ggxD(wm, b.alpha) * ggxG2(wo, wi, b.alpha);
    if (reflect) return glm::vec3(dg * f / (4.0f * wi.z * wo.z));
    float s = glm::dot(wi, wm) + glm::dot(wo, wm) / etap;
    float denom = s * s * wi.z * wo.z;
    float t = dg * (1.0f - f) * std::abs(glm::dot(wi, wm) * glm::dot(wo, wm) / denom) / (etap * etap);
    return b.color * t;  // radiance: divided by eta^2; transmitted light tinted by the base colour
  }
  if (wi.z <= 0.0f) return glm::vec3(0.0f);
  if (b.lobe == kLobeDiffuse) return b.color * kInvPi;
  if (b.lobe == kLobeSheen) return sheenEval(b.color, b.alpha, wo, wi);
  glm::vec3 h = wo + wi;
  float len = glm::length(h);
  if (!(len > 0.0f)) return glm::vec3(0.0f);
  h /= len;
  float spec = ggxD(h, b.alpha) * ggxG2(wo, wi, b.alpha) / (4.0f * wo.z * wi.z);
  float cosH = glm::dot(wo, h);
  if (b.lobe == kLobeConductor) return fresnelSchlick(b.color, glm::vec3(1.0f), cosH) * spec;
  // kLobePlastic: glTF's fresnel_mix of the specular layer over the diffuse base.
  glm::vec3 f = fresnelSchlick(b.f0, glm::vec3(b.f90), cosH);
  return f * spec + (1.0f - maxComponent3(f)) * b.color * kInvPi;
}

float bsdfPdf(const Bsdf& b, const glm::vec3& wo, const glm::vec3& wi) {
  if (wo.z <= 0.0f) return 0.0f;
  if (b.lobe == kLobeRoughGlass) {
    if (wi.z == 0.0f) return 0.0f;
    bool reflect = wi.z > 0.0f;
    float etap = reflect ? 1.0f : b.eta;
    glm::vec3 wm;
    if (!generalizedHalf(wo, wi, etap, wm)) return 0.0f;
    float f = fresnelDielectric(glm::dot(wo, wm), b.eta);
    float pm = ggxVisibleNormalPdf(wo, wm, b.alpha);
    if (reflect) return pm / (4.0f * std::abs(glm::dot(wo, wm))) * f;
    float s = glm::dot(wi, wm) + glm::dot(wo, wm) / etap;
    return pm * std::abs(glm::dot(wi, wm)) / (s * s) * (1.0f - f);
  }
  if (wi.z <= 0.0f) return 0.0f;
  if (b.lobe == kLobeDiffuse) return wi.z * kInvPi;
  if (b.lobe == kLobeSheen) return 0.5f * kInvPi;  // sampleUniformHemisphere
  glm::vec3 h = wo + wi;
  float len = glm::length(h);
  if (!(len > 0.0f)) return 0.0f;
  h /= len;
  float ps = ggxVisibleNormalPdf(wo, h, b.alpha) / (4.0f * glm::dot(wo, h));
  if (b.lobe == kLobeConductor) return ps;
  float p = plasticSpecularProbability(b, wo);
  return p * ps + (1.0f - p) * wi.z * kInvPi;
}

float bsdfEvalPdf(const Bsdf& b, const glm::vec3& wo, const glm::vec3& wi, glm::vec3& f) {
  f = bsdfEval(b, wo, wi);
  return bsdfPdf(b, wo, wi);
}

bool bsdfSample(const Bsdf& b, const glm::vec3& wo, const glm::vec3& u, BsdfSample& s) {
  s = BsdfSample{};
  if (wo.z <= 0.0f) return false;
  glm::vec2 uDir(u.y, u.z);
  if (b.lobe == kLobeRoughGlass) {
    glm::vec3 wm = ggxSampleVisibleNormal(wo, b.alpha, uDir);
    float f = fresnelDielectric(glm::dot(wo, wm), b.eta);
    if (u.x < f) {
      s.wi = reflectAbout(wo, wm);
      if (s.wi.z <= 0.0f) return false;
    } else {
      if (!refractDir(-wo, wm, 1.0f / b.eta, s.wi) || s.wi.z >= 0.0f) return false;
      s.transmitted = true;
    }
  } else if (b.lobe == kLobeDiffuse) {
    s.wi = sampleCosineHemisphere(uDir);
  } else if (b.lobe == kLobeSheen) {
    s.wi = sampleUniformHemisphere(uDir);
  } else if (b.lobe == kLobeConductor || u.x < plasticSpecularProbability(b, wo)) {
    s.wi = reflectAbout(wo, ggxSampleVisibleNormal(wo, b.alpha, uDir));
    if (s.wi.z <= 0.0f) return false;
  } else {
    s.wi = sampleCosineHemisphere(uDir);
  }
  s.pdf = bsdfPdf(b, wo, s.wi);
  if (!(s.pdf > 0.0f)) return false;
  s.weight = bsdfEval(b, wo, s.wi) * (std::abs(s.wi.z) / s.pdf);
  return true;
}

}  // namespace caustica
