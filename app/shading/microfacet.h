// microfacet.h — C++ twins of glsl/lib/microfacet.glsl: GGX (Trowbridge–Reitz) distribution, Smith
// height-correlated masking-shadowing, visible-normal sampling, and the non-delta lobes built on them.
// Every direction here is in the local shading frame (unit vectors, normal = +z); wo points away from
// the surface towards where the path came from (the camera side), wi towards where light comes from.
#pragma once
#include <cstdint>

#include <glm/glm.hpp>

namespace caustica {

// Lobes of the material model (docs/materials.md). The delta lobes and the Lambertian lobe keep their
// code in pathtrace.comp; the Bsdf functions below handle every lobe that is neither.
constexpr std::uint32_t kLobeDiffuse = 0;      // Lambertian, C / pi
constexpr std::uint32_t kLobeMirror = 1;       // smooth metal: delta reflection times C
constexpr std::uint32_t kLobeGlass = 2;        // smooth dielectric: delta reflection / refraction
constexpr std::uint32_t kLobeConductor = 3;    // rough metal: GGX with Schlick Fresnel, F0 = C
constexpr std::uint32_t kLobePlastic = 4;      // GGX dielectric specular over Lambertian (glTF fresnel_mix)
constexpr std::uint32_t kLobeRoughGlass = 5;   // rough dielectric: GGX reflection + refraction (Walter 2007)
constexpr std::uint32_t kLobeSheen = 6;        // Charlie sheen scaled to albedo C (shading/layers.h)

// glTF roughness r gives GGX alpha = r^2. Below this alpha a metal or glass lobe is the exact delta lobe.
constexpr float kDeltaAlpha = 1.0e-3f;
// The plastic lobe has no delta form: its alpha is clamped to at least this.
constexpr float kMinPlasticAlpha = 1.0e-3f;

// One lobe with its parameters at a shading point.
struct Bsdf {
  std::uint32_t lobe = kLobeDiffuse;
  glm::vec3 color{1.0f};  // base colour C: diffuse albedo, conductor F0, transmission tint; sheen: its albedo
  float alpha = 1.0f;     // GGX alpha (roughness^2); sheen: sheen roughness^2
  float eta = 1.5f;       // dielectric: n on the wi side of a refraction / n on the wo side
  glm::vec3 f0{0.04f};    // plastic: specular reflectance at normal incidence (KHR_materials_specular)
  float f90 = 1.0f;       // plastic: specular reflectance at grazing incidence (specularFactor)
};

// A sampled direction: wi (local), the weight f |cos theta_i| / pdf, the solid-angle pdf.
struct BsdfSample {
  glm::vec3 wi{0.0f};
  glm::vec3 weight{0.0f};
  float pdf = 0.0f;
  bool transmitted = false;
};

// ---- GGX -------------------------------------------------------------------------------------------
float ggxD(const glm::vec3& h, float alpha);                 // normal distribution, per steradian of h
float ggxLambda(const glm::vec3& w, float alpha);            // Smith Lambda
float ggxG1(const glm::vec3& w, float alpha);                // 1 / (1 + Lambda)
float ggxG2(const glm::vec3& wo, const glm::vec3& wi, float alpha);  // height-correlated: 1 / (1 + Lo + Li)
// Visible normal for wo (wo.z > 0), Dupuy & Benyoub 2023 (spherical caps); u in [0,1)^2.
glm::vec3 ggxSampleVisibleNormal(const glm::vec3& wo, float alpha, const glm::vec2& u);
// Its density per steradian of h: G1(wo) max(0, wo.h) D(h) / wo.z.
float ggxVisibleNormalPdf(const glm::vec3& wo, const glm::vec3& h, float alpha);
glm::vec3 fresnelSchlick(const glm::vec3& f0, const glm::vec3& f90, float cosTheta);

// ---- lobes (non-delta, non-Lambertian) -------------------------------------------------------------
// Probability that the plastic lobe samples its specular part, from wo only.
float plasticSpecularProbability(const Bsdf& b, const glm::vec3& wo);
// f(wo, wi) without the cosine; 0 where the lobe has no value.
glm::vec3 bsdfEval(const Bsdf& b, const glm::vec3& wo, const glm::vec3& wi);
// Solid-angle density with which bsdfSample produces wi.
float bsdfPdf(const Bsdf& b, const glm::vec3& wo, const glm::vec3& wi);
// bsdfEval (out f) and bsdfPdf (returned) of one wi: the twin of glsl/lib/microfacet.glsl's bsdfEvalPdf,
// which computes both in one body for every lobe (llvmpipe runs every branch; docs/architecture.md,
// "Writing shaders for llvmpipe"), with the same values as the two functions here.
float bsdfEvalPdf(const Bsdf& b, const glm::vec3& wo, const glm::vec3& wi, glm::vec3& f);
// Samples wi; u.x chooses between parts (specular/diffuse, reflection/refraction), u.yz the direction.
// False when the sample is lost (below the surface): the path ends.
bool bsdfSample(const Bsdf& b, const glm::vec3& wo, const glm::vec3& u, BsdfSample& s);

}  // namespace caustica
