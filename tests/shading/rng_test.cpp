// rng_test.cpp — the random streams: pcg4d is a bijection (its inverse is applied to a million
// random inputs), so distinct (pixel, sample, seed) keys start distinct 128-bit streams; no two of
// 512 x 512 pixels x 16 samples share a state (the former 32-bit seed gave ~2,000 such pairs).
#include <doctest/doctest.h>

#include <algorithm>
#include <random>
#include <tuple>
#include <vector>

#include "shading/rng.h"

using namespace caustica;

namespace {

// Inverse of pcg4d, step by step in reverse order.
glm::uvec4 pcg4dInverse(glm::uvec4 v) {
  auto unmix = [](glm::uvec4& u) {
    u.w -= u.y * u.z;
    u.z -= u.x * u.y;
    u.y -= u.z * u.x;
    u.x -= u.y * u.w;
  };
  unmix(v);
  v ^= v >> 16u;  // x ^ (x >> 16) is its own inverse on 32 bits
  unmix(v);
  std::uint32_t inv = 1664525u;  // Newton's iteration for the inverse of an odd number mod 2^32
  for (int i = 0; i < 5; ++i) inv *= 2u - 1664525u * inv;
  return (v - 1013904223u) * inv;
}

}  // namespace

TEST_CASE("rng: pcg4d is a bijection, so distinct keys give distinct stream states") {
  std::mt19937 g(5);
  for (int i = 0; i < 1000000; ++i) {
    glm::uvec4 v(g(), g(), g(), g());
    REQUIRE(pcg4dInverse(pcg4d(v)) == v);
  }
}

TEST_CASE("rng: no two paths of 512 x 512 pixels x 16 samples start from the same state") {
  std::vector<std::tuple<std::uint32_t, std::uint32_t, std::uint32_t, std::uint32_t>> states;
  const std::uint32_t pixels = 512u * 512u, samples = 16u;
  states.reserve(static_cast<size_t>(pixels) * samples);
  for (std::uint32_t s = 0; s < samples; ++s)
    for (std::uint32_t p = 0; p < pixels; ++p) {
      RngState r = rngSeed(p, s, 1u);
      states.emplace_back(r.x, r.y, r.z, r.w);
    }
  std::sort(states.begin(), states.end());
  CHECK(std::adjacent_find(states.begin(), states.end()) == states.end());
  // And the same first draws do not repeat either in their leading 32 bits more than chance allows.
  RngState a = rngSeed(0, 0, 1), b = rngSeed(0, 0, 2);
  int same = 0;
  for (int i = 0; i < 1000; ++i) same += rand01(a) == rand01(b);
  CHECK(same < 5);
}

TEST_CASE("rng: the zero state (xoshiro's fixed point) is never produced") {
  // The one key that pcg4d maps to zero, found through the inverse, is moved off it.
  glm::uvec4 key = pcg4dInverse(glm::uvec4(0u));
  if (key.w == 0x9E3779B9u) CHECK(rngSeed(key.x, key.y, key.z) != RngState(0u));
  RngState s = rngSeed(0, 0, 0);
  CHECK(s != RngState(0u));
}
