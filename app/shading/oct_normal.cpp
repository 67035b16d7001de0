// oct_normal.cpp — octahedral normal encoding (host) and its decoding twin.
#include "shading/oct_normal.h"

#include <cmath>

#include "shared/gpu_layout.h"

namespace caustica {

namespace {
std::uint32_t packSnorm(float x) {  // GLSL packSnorm2x16 of one component
  const float r = std::round(std::fmin(std::fmax(x, -1.0f), 1.0f) * 32767.0f);
  return static_cast<std::uint32_t>(static_cast<std::uint16_t>(static_cast<std::int16_t>(r)));
}
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
  // The nearest grid point in the plane is not always the nearest in angle: try the four around it.
  // Angles compared in double (in float, 1 - cos of 1e-4 rad is below the rounding of dot products).
  const glm::dvec3 unit = glm::normalize(glm::dvec3(n));
  const auto error = [&](std::uint32_t w) { return glm::length(glm::cross(glm::dvec3(octDecode(w)), unit)); };
  const float fx = std::floor(std::fmin(std::fmax(px, -1.0f), 1.0f) * 32767.0f);
  const float fy = std::floor(std::fmin(std::fmax(py, -1.0f), 1.0f) * 32767.0f);
  std::uint32_t best = packSnorm(px) | packSnorm(py) << 16;
  double bestError = error(best);
  for (int i = 0; i < 4; ++i) {
    const std::uint32_t w = packSnorm((fx + float(i & 1)) / 32767.0f) | packSnorm((fy + float(i >> 1)) / 32767.0f) << 16;
    const double e = error(w);
    if (e < bestError && glm::dot(glm::dvec3(octDecode(w)), unit) > 0.0) bestError = e, best = w;
  }
  return best;
}

}  // namespace caustica
