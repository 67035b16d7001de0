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
// Caster guiding (CAUSTICA_GUIDING): guide lobes fitted to the guide cells' photons.
constexpr std::uint32_t kMinGuidePhotons = 8;  // photons a cell needs for a guide lobe
constexpr float kMaxGuideKappa = 1.0e4f;       // the narrowest guide lobe (vMF concentration)
constexpr int kGuideClasses = 2;               // guide lobes per caster: photons of its own chain, of any other
// The vMF lobe fitted to a guide cell (count x, summed direction yzw as int bits of kCellDirScale) at a
// vertex with unit normal n: unit axis and concentration; false without enough photons or from below.
bool guideLobe(const glm::uvec4& cell, const glm::vec3& n, glm::vec3& axis, float& kappa);
float vmfNorm(float kappa);                   // density at the axis (per steradian)
float vmfOneMinusCos(float kappa, float u);   // 1 - cos theta of a direction drawn from the lobe, u in [0, 1)
// The shader keeps this state in globals for the current diffuse vertex.
struct CasterVertex {
  static constexpr int kMax = CAUSTICA_MAX_CASTERS;
  std::uint32_t usable = 0, pick = 0;
  glm::vec3 axis[kMax];  // unit axis of the cone (n without a usable cone)
  float invSolidAngle[kMax];
  float oneMinusCos[kMax];  // 0 without a usable cone
  // Per usable caster k and photon class c, at [kGuideClasses * k + c]: the guide lobe (vMF) and its
  // probability within the caster's share (0: no lobe).
  glm::vec3 guideAxis[kGuideClasses * kMax];
  float guideKappa[kGuideClasses * kMax] = {};
  float guideNorm[kGuideClasses * kMax] = {};  // vmfNorm(kappa)
  float guideWeight[kGuideClasses * kMax] = {};
};
float guidePdf(const CasterVertex& v, std::uint32_t j, const glm::vec3& w);  // lobe j's density at w
bool casterFacesLights(const glm::vec3& p, const glm::vec3& axis, float oneMinusCos, const glm::vec4& lights,
                       float margin);
// refractMask bit i: spheres[i] refracts and is used only where casterFacesLights. guideCells: with caster
// guiding, the guide cells at p, kGuideClasses per caster (at [kGuideClasses * i + class]), and
// guideProbability the lobes' share of an aimed bounce where the caster's cone is usable; nullptr without.
// aimMask bit i: spheres[i]'s cone may be aimed at at all (aimCasterMask); its guide lobes count regardless.
CasterVertex prepareCasters(const glm::vec3& p, const glm::vec3& n, float u, const glm::vec4* spheres, std::uint32_t count,
                            std::uint32_t refractMask, const glm::vec4& lights, float margin,
                            const glm::uvec4* guideCells = nullptr, float guideProbability = 0.0f,
                            std::uint32_t aimMask = ~0u);
float diffuseDirectionPdf(const CasterVertex& v, float casterProbability, const glm::vec3& n, const glm::vec3& w);
glm::vec3 sampleDiffuseDirection(const CasterVertex& v, float casterProbability, const glm::vec3& n, float uPick,
                                 const glm::vec2& u);

}  // namespace caustica
