// spawn.cpp — C++ twins of glsl/lib/spawn.glsl (see spawn.h); same arithmetic, same names.
#include "accel/spawn.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace caustica {

namespace {

std::int32_t floatBits(float v) {
  std::int32_t b;
  std::memcpy(&b, &v, 4);
  return b;
}

float bitsFloat(std::int32_t b) {
  float v;
  std::memcpy(&v, &b, 4);
  return v;
}

}  // namespace

float gammaBound(int n) {
  const float u = 5.9604644775390625e-8f;
  return static_cast<float>(n) * u / (1.0f - static_cast<float>(n) * u);
}

glm::vec3 hitPointError(float b0, float b1, float b2, const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2) {
  return gammaBound(7) * (glm::abs(b0 * p0) + glm::abs(b1 * p1) + glm::abs(b2 * p2));
}

float nextFloatUp(float v) {
  if (std::isinf(v) && v > 0.0f) return v;
  if (v == 0.0f) return bitsFloat(1);
  const std::int32_t bits = floatBits(v);
  return bitsFloat(v > 0.0f ? bits + 1 : bits - 1);
}

float nextFloatDown(float v) {
  if (std::isinf(v) && v < 0.0f) return v;
  if (v == 0.0f) return -bitsFloat(1);
  const std::int32_t bits = floatBits(v);
  return bitsFloat(v > 0.0f ? bits - 1 : bits + 1);
}

glm::vec3 offsetRayOrigin(const glm::vec3& p, const glm::vec3& pError, const glm::vec3& n) {
  const float d = glm::dot(glm::abs(n), pError);
  const glm::vec3 offset = d * n;
  glm::vec3 po = p + offset;
  for (int i = 0; i < 3; ++i) {
    if (offset[i] > 0.0f) po[i] = nextFloatUp(po[i]);
    else if (offset[i] < 0.0f) po[i] = nextFloatDown(po[i]);
  }
  return po;
}

}  // namespace caustica
