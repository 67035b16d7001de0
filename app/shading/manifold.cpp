// manifold.cpp — C++ twins of glsl/lib/manifold.glsl's arithmetic (same names and order).
#include "shading/manifold.h"

#include <cmath>

#include "shading/sampling.h"

namespace caustica {

NormalDiff normalDiffOn(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2, const glm::vec3& n0,
                        const glm::vec3& n1, const glm::vec3& n2, float u, float v, const glm::vec3& ns) {
  NormalDiff nd;
  glm::vec3 e1 = p1 - p0, e2 = p2 - p0;
  glm::vec3 n = glm::cross(e1, e2);
  float inv = 1.0f / glm::dot(n, n);
  nd.gu = glm::cross(e2, n) * inv;
  nd.gv = glm::cross(n, e1) * inv;
  nd.dn1 = n1 - n0;
  nd.dn2 = n2 - n0;
  glm::vec3 raw = (1.0f - u - v) * n0 + u * n1 + v * n2;
  float len = glm::length(raw);
  nd.scale = len > 1.0e-12f ? (glm::dot(raw, ns) >= 0.0f ? 1.0f : -1.0f) / len : 0.0f;
  return nd;
}

glm::vec3 normalDerivative(const NormalDiff& nd, const glm::vec3& ns, const glm::vec3& dp) {
  glm::vec3 raw = nd.dn1 * glm::dot(nd.gu, dp) + nd.dn2 * glm::dot(nd.gv, dp);
  return (raw - ns * glm::dot(ns, raw)) * nd.scale;
}

glm::vec3 transferDiff(const glm::vec3& dO, const glm::vec3& dD, const glm::vec3& d, float t, const glm::vec3& ng) {
  glm::vec3 q = dO + t * dD;
  return q - d * (glm::dot(q, ng) / glm::dot(d, ng));
}

bool refractDiff(const glm::vec3& d, const glm::vec3& n, float r, glm::vec3& dOut, const glm::vec3& dD,
                 const glm::vec3& dN, glm::vec3& dDOut, const glm::vec3& dD2, const glm::vec3& dN2, glm::vec3& dDOut2) {
  float cosI = -glm::dot(d, n);
  float sin2T = r * r * std::max(0.0f, 1.0f - cosI * cosI);
  dOut = d;
  dDOut = dD;
  dDOut2 = dD2;
  if (!(cosI > 0.0f) || sin2T >= 1.0f) return false;
  float cosT = std::sqrt(1.0f - sin2T);
  float mu = r * cosI - cosT;
  dOut = r * d + mu * n;
  float dCosI = -(glm::dot(dD, n) + glm::dot(d, dN));
  float dMu = r * dCosI - r * r * cosI * dCosI / cosT;
  dDOut = r * dD + mu * dN + dMu * n;
  float dCosI2 = -(glm::dot(dD2, n) + glm::dot(d, dN2));
  float dMu2 = r * dCosI2 - r * r * cosI * dCosI2 / cosT;
  dDOut2 = r * dD2 + mu * dN2 + dMu2 * n;
  return true;
}

glm::vec3 reflectDiff(const glm::vec3& d, const glm::vec3& n, const glm::vec3& dD, const glm::vec3& dN) {
  float cosI = -glm::dot(d, n);
  return dD + 2.0f * (-(glm::dot(dD, n) + glm::dot(d, dN))) * n + 2.0f * cosI * dN;
}

glm::vec3 manifoldDirection(const glm::vec3& axis, const glm::vec2& ab) {
  glm::vec3 t, b;
  orthonormalBasis(axis, t, b);
  return glm::normalize(axis + ab.x * t + ab.y * b);
}

glm::vec2 manifoldParams(const glm::vec3& axis, const glm::vec3& w) {
  glm::vec3 t, b;
  orthonormalBasis(axis, t, b);
  return glm::vec2(glm::dot(w, t), glm::dot(w, b)) / glm::dot(w, axis);
}

}  // namespace caustica
