// sampling.h — C++ twins of the GLSL sampling routines in glsl/lib/sampling.glsl, materials.glsl,
// spectral.glsl and rng.glsl (same names, same arithmetic), so tests can check what the shader does.
#pragma once
#include <cstdint>

#include <glm/glm.hpp>

namespace caustica {

constexpr float kPi = 3.14159265358979323846f;

std::uint32_t pcgHash(std::uint32_t v);
std::uint32_t rngSeed(std::uint32_t pixel, std::uint32_t sampleIndex, std::uint32_t seed);
float rand01(std::uint32_t& state);

float luminance(const glm::vec3& c);
void orthonormalBasis(const glm::vec3& n, glm::vec3& t, glm::vec3& b);
glm::vec3 sampleCosineHemisphere(const glm::vec2& u);  // about +z; pdf cos/pi
glm::vec2 sampleTriangleUniform(const glm::vec2& u);   // barycentrics of p1, p2; pdf 1/area
float powerHeuristic(float a, float b);
float fresnelDielectric(float cosI, float eta);        // eta = n_t / n_i
bool refractDir(const glm::vec3& d, const glm::vec3& n, float eta, glm::vec3& t);  // eta = n_i / n_t
// Returns the throughput factor; see materials.glsl.
float sampleDielectric(const glm::vec3& d, const glm::vec3& n, float eta, float u, glm::vec3& wi, bool& transmitted);
glm::vec3 offsetRayOrigin(const glm::vec3& p, const glm::vec3& n);
float cauchyIor(float iorD, float abbe, float lambdaNm);
glm::vec3 channelSensitivity(float lambdaNm);

}  // namespace caustica
