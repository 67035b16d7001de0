// oct_normal.cpp — octahedral normal encoding (host) and its decoding twin.
#include "shading/oct_normal.h"

#include <cmath>

#include "shared/gpu_layout.h"

namespace caustica {
static_assert(kOctNoNormal == gpu::kOctZeroNormal, "oct_normal.h's zero word is gpu_layout.h's");

namespace {
float unpackSnorm(std::uint32_t bits) {  // GLSL unpackSnorm2x16 of one component
  const auto v = static_cast<std::int16_t>(static_cast<std::uint16_t>(bits & 0xffffu));
  return std::fmin(std::fmax(static_cast<float>(v) / 32767.0f, -1.0f), 1.0f);
}
}  // namespace

glm::vec3 octDecode(std::uint32_t w) {
  if (w == gpu::kOctZeroNormal) return glm::vec3(0.0f);
  const float px = unpackSnorm(w), py = unpackSnorm(w >> 16);
  glm::vec3 n(px, py, 1.0f - std::fabs(px) - std::fabs(py));
  const float t = std::fmax(-n.z, 0.0f);
  n.x += n.x >= 0.0f ? -t : t;
  n.y += n.y >= 0.0f ? -t : t;
  return glm::normalize(n);
}

namespace {
// The direction octDecode gives grid point (ix, iy) (snorm integers), before its normalize.
glm::vec3 octPoint(float ix, float iy) {
  const float px = std::fmin(std::fmax(ix / 32767.0f, -1.0f), 1.0f), py = std::fmin(std::fmax(iy / 32767.0f, -1.0f), 1.0f);
  glm::vec3 q(px, py, 1.0f - std::fabs(px) - std::fabs(py));
  const float t = std::fmax(-q.z, 0.0f);
  q.x += q.x >= 0.0f ? -t : t;
  q.y += q.y >= 0.0f ? -t : t;
  return q;
}
}  // namespace

std::uint32_t octEncode(const glm::vec3& n) {
  const float l1 = std::fabs(n.x) + std::fabs(n.y) + std::fabs(n.z);
  if (!(l1 > 0.0f) || !std::isfinite(l1)) return gpu::kOctZeroNormal;
  float px = n.x / l1, py = n.y / l1;
  if (n.z < 0.0f) {
    const float ox = (1.0f - std::fabs(py)) * (px >= 0.0f ? 1.0f : -1.0f);
    const float oy = (1.0f - std::fabs(px)) * (py >= 0.0f ? 1.0f : -1.0f);
    px = ox;
    py = oy;
  }
  // The nearest grid point in the plane is not always the nearest in angle: of the four around the
  // point, take the one whose direction q has the smallest sin^2 of the angle to n, |q x n|^2 / |q|^2
  // (no 1 - cos: in float that rounds to 0 at these angles).
  const glm::vec3 u = n / l1;
  const float fx = std::floor(std::fmin(std::fmax(px, -1.0f), 1.0f) * 32767.0f);
  const float fy = std::floor(std::fmin(std::fmax(py, -1.0f), 1.0f) * 32767.0f);
  float bestX = fx, bestY = fy, bestError = 3.0e38f;
  for (int i = 0; i < 4; ++i) {
    const float ix = std::fmin(fx + float(i & 1), 32767.0f), iy = std::fmin(fy + float(i >> 1), 32767.0f);
    const glm::vec3 q = octPoint(ix, iy);
    const glm::vec3 c = glm::cross(q, u);
    const float e = glm::dot(c, c) / glm::dot(q, q);
    if (e < bestError && glm::dot(q, u) > 0.0f) bestError = e, bestX = ix, bestY = iy;
  }
  const auto bits = [](float v) {
    return static_cast<std::uint32_t>(static_cast<std::uint16_t>(static_cast<std::int16_t>(v)));
  };
  return bits(bestX) | bits(bestY) << 16;
}

std::uint32_t tangentWord(const glm::vec4& t) {
  if (t.w == 0.0f) return kOctNoNormal;
  const std::uint32_t w = octEncode(glm::vec3(t));
  if (w == kOctNoNormal) return kOctNoNormal;
  return t.w < 0.0f ? w | 1u : w & ~1u;
}

glm::vec4 tangentFromWord(std::uint32_t w) {
  if (w == kOctNoNormal) return glm::vec4(0.0f);
  return glm::vec4(octDecode(w), (w & 1u) != 0u ? -1.0f : 1.0f);
}

}  // namespace caustica
