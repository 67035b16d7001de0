// rng.h — C++ twins of glsl/lib/rng.glsl: pcg4d seeding of a 128-bit xoshiro128+ stream per
// (pixel, sample index, seed). Same names, same arithmetic, bit for bit.
#pragma once
#include <cstdint>

#include <glm/glm.hpp>

namespace caustica {

using RngState = glm::uvec4;

glm::uvec4 pcg4d(glm::uvec4 v);
RngState rngSeed(std::uint32_t pixel, std::uint32_t sampleIndex, std::uint32_t seed);
float rand01(RngState& s);  // uniform in [0, 1), 24 random bits

}  // namespace caustica
