// sampling.h — C++ twins of the GLSL sampling routines in glsl/lib/sampling.glsl, materials.glsl,
// spectral.glsl and casters.glsl (rng.glsl: shading/rng.h) (same names, same arithmetic), so tests can check what the shader does.
#pragma once
#include <cstdint>

#include <glm/glm.hpp>

#include "shading/rng.h"
#include "shared/gpu_layout.h"
#include "util/math_constants.h"

namespace caustica {



float luminance(const glm::vec3& c);
void orthonormalBasis(const glm::vec3& n, glm::vec3& t, glm::vec3& b);
glm::vec3 sampleCosineHemisphere(const glm::vec2& u);  // about +z; pdf cos/pi
glm::vec2 sampleTriangleUniform(const glm::vec2& u);   // barycentrics of p1, p2; pdf 1/area
float powerHeuristic(float a, float b);
float fresnelDielectric(float cosI, float eta);        // eta = n_t / n_i
bool refractDir(const glm::vec3& d, const glm::vec3& n, float eta, glm::vec3& t);  // eta = n_i / n_t
// Returns the throughput factor; see materials.glsl.
float sampleDielectric(const glm::vec3& d, const glm::vec3& n, float eta, float u, glm::vec3& wi, bool& transmitted);
float cauchyIor(float iorD, float abbe, float lambdaNm);
glm::vec3 channelSensitivity(float lambdaNm);

// Caustic-caster sampling (glsl/lib/casters.glsl). Spheres are xyz centre, w radius; directions unit,
// world space; pdfs per steradian.
constexpr float kCasterMinOneMinusCos = 1.0e-5f;  // narrowest cone aimed at: 1 - cos(half angle)
bool inCone(const glm::vec3& w, const glm::vec3& axis, float oneMinusCos);
bool casterCone(const glm::vec3& p, const glm::vec3& n, const glm::vec4& sphere, glm::vec3& axis, float& oneMinusCos);
glm::vec3 sampleUniformCone(const glm::vec3& axis, float oneMinusCos, const glm::vec2& u);
// The shader keeps this state in globals for the current diffuse vertex.
struct CasterVertex {
  static constexpr int kMax = CAUSTICA_MAX_CASTERS;
  std::uint32_t usable = 0, pick = 0;
  glm::vec3 axis[kMax];  // unit axis of the cone
  float invSolidAngle[kMax];
  float oneMinusCos[kMax];
};
bool casterFacesLights(const glm::vec3& p, const glm::vec3& axis, float oneMinusCos, const glm::vec4& lights,
                       float margin);
// refractMask bit i: spheres[i] refracts and is used only where casterFacesLights.
CasterVertex prepareCasters(const glm::vec3& p, const glm::vec3& n, float u, const glm::vec4* spheres, std::uint32_t count,
                            std::uint32_t refractMask, const glm::vec4& lights, float margin);
float diffuseDirectionPdf(const CasterVertex& v, float casterProbability, const glm::vec3& n, const glm::vec3& w);
glm::vec3 sampleDiffuseDirection(const CasterVertex& v, float casterProbability, const glm::vec3& n, float uPick,
                                 const glm::vec2& u);

}  // namespace caustica
