// layers.h — C++ twins of glsl/lib/layers.glsl: the clear coat (KHR_materials_clearcoat) and sheen
// (KHR_materials_sheen, the Charlie BRDF) layers over a glTF material, how a path picks a layer, and the
// sheen lobe (kLobeSheen of shading/microfacet.h). Directions local to the shading frame (unit, +z normal).
#pragma once
#include <glm/glm.hpp>

namespace caustica {

constexpr float kCoatF0 = 0.04f;             // ((1.5 - 1) / (1.5 + 1))^2: the coat's index is 1.5
constexpr float kMinSheenRoughness = 0.07f;  // sheen roughness is clamped to at least this
constexpr float kMinSheenAlbedo = 1.0e-4f;   // the sheen lobe's normalisation divides by at least this

// Schlick Fresnel of the coat at |cos theta| to the coat normal: the layer's weight per unit clearcoat.
float coatFresnel(float cosTheta);
float sheenRoughnessClamped(float roughness);
// Charlie distribution per steradian of the unit half vector h; alpha = sheen roughness^2.
float sheenD(const glm::vec3& h, float alpha);
float sheenL(float x, float alpha);                            // the masking fit L(x)
float sheenLambda(float cosTheta, float alpha);
float sheenVisibility(float cosO, float cosI, float alpha);    // G / (4 cos_o cos_i)
// Directional albedo of the white Charlie BRDF from the table glsl/shared/sheen_albedo.h (bilinear).
float sheenAlbedo(float cosTheta, float roughness);
// The sheen lobe scaled to directional albedo `tint`: tint D V / E(cos_o). wo.z, wi.z > 0.
glm::vec3 sheenEval(const glm::vec3& tint, float alpha, const glm::vec3& wo, const glm::vec3& wi);
glm::vec3 sampleUniformHemisphere(const glm::vec2& u);        // about +z; pdf 1 / (2 pi)

// The layers' weights at a hit and the probability of picking the coat (layers.glsl says how they combine).
struct LayerWeights {
  float coat = 0.0f;      // clearcoat x coatFresnel
  float sheen = 0.0f;     // max(sheenColor) x min(E, 1)
  float coatPick = 0.0f;  // probability of picking the coat, leaning towards it over a dark base
};
LayerWeights layerWeights(float coat, float cosCoat, const glm::vec3& sheenColor, float sheenRoughness, float cosBase,
                          float baseAlbedo);
// The layered material's albedo for feature buffers: coat white, sheen its colour x min(E, 1), then the base.
glm::vec3 layeredAlbedo(const LayerWeights& w, const glm::vec3& sheenColor, const glm::vec3& baseAlbedo);

}  // namespace caustica
