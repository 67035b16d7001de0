// oct_normal.h — unit normals in 32 bits: the octahedral map (Cigolle et al. 2014) quantised to two
// 16-bit snorm values; octDecode is the twin of glsl/lib/tri_shade.glsl's (tests/gpu/twins_gpu_test.cpp).
#pragma once
#include <cstdint>

#include <glm/glm.hpp>

namespace caustica {

// The word of a zero normal ("none": the geometric normal is used), gpu::kOctZeroNormal (checked in
// oct_normal.cpp), here so that the scene model needs no GPU header.
constexpr std::uint32_t kOctNoNormal = 0x80008000u;

// A unit vector (any length > 0 works; it is normalised) to packSnorm2x16 of its octahedral point;
// gpu::kOctZeroNormal for a zero or non-finite vector. Rounds to the nearest of the four neighbouring
// grid points in angle: the decoded normal is within 4.3e-5 rad of n (mean 2.1e-5; oct_normal_test).
std::uint32_t octEncode(const glm::vec3& n);
// The unit normal of an encoded word; (0, 0, 0) for gpu::kOctZeroNormal.
glm::vec3 octDecode(std::uint32_t w);

// A tangent (xyz unit, w = +-1 the bitangent's sign) in one word: octEncode(xyz) with bit 0 (the low
// bit of x's snorm, moving the direction by at most one grid step, 3e-5 rad) set where w < 0;
// kOctNoNormal where w = 0 ("none"). tangentDecode in glsl/lib/oct_normal.glsl is the twin.
std::uint32_t tangentWord(const glm::vec4& t);
// The tangent (xyz unit, w = +-1) of a tangentWord; (0, 0, 0, 0) for kOctNoNormal.
glm::vec4 tangentFromWord(std::uint32_t w);

}  // namespace caustica
