// rng.cpp — C++ twins of glsl/lib/rng.glsl (see rng.h).
#include "shading/rng.h"

namespace caustica {

glm::uvec4 pcg4d(glm::uvec4 v) {
  v = v * 1664525u + 1013904223u;
  v.x += v.y * v.w;
  v.y += v.z * v.x;
  v.z += v.x * v.y;
  v.w += v.y * v.z;
  v ^= v >> 16u;
  v.x += v.y * v.w;
  v.y += v.z * v.x;
  v.z += v.x * v.y;
  v.w += v.y * v.z;
  return v;
}

RngState rngSeed(std::uint32_t pixel, std::uint32_t sampleIndex, std::uint32_t seed) {
  RngState s = pcg4d(glm::uvec4(pixel, sampleIndex, seed, 0x9E3779B9u));
  if (s == glm::uvec4(0u)) s.x = 1u;
  return s;
}

namespace {
std::uint32_t rotl32(std::uint32_t x, std::uint32_t k) { return (x << k) | (x >> (32u - k)); }
}  // namespace

float rand01(RngState& s) {
  const std::uint32_t result = s.x + s.w;
  const std::uint32_t t = s.y << 9u;
  s.z ^= s.x;
  s.w ^= s.y;
  s.y ^= s.z;
  s.x ^= s.w;
  s.z ^= t;
  s.w = rotl32(s.w, 11u);
  return static_cast<float>(result >> 8u) * (1.0f / 16777216.0f);
}

}  // namespace caustica
