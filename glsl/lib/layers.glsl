// layers.glsl — the layers glTF puts over a material: the clear coat (KHR_materials_clearcoat: a GGX
// reflection of index 1.5 weighted by clearcoat x its Schlick Fresnel at the view angle) and the sheen
// (KHR_materials_sheen: the Charlie BRDF with its albedo scaling), how a path picks one of them or the
// base, and the sheen lobe's f, pdf and sampling. Twins in app/shading/layers.cpp. Directions local to
// the shading frame (unit, normal = +z). Needs sampling.glsl (PI, maxComponent).

#include "../shared/sheen_albedo.h"  // kSheenAlbedo: E(mu, roughness) of the white Charlie BRDF

const float kCoatF0 = 0.04;              // ((1.5 - 1) / (1.5 + 1))^2: the coat's index is 1.5
const float kMinSheenRoughness = 0.07;   // sheen roughness is clamped to at least this (1 / alpha <= 204)
const float kMinSheenAlbedo = 1.0e-4;    // the lobe's normalisation divides by at least this

// Schlick Fresnel of the coat at |cos theta| to the coat normal: the layer's weight per unit clearcoat.
float coatFresnel(float cosTheta) {
  float m = clamp(1.0 - abs(cosTheta), 0.0, 1.0);
  float m2 = m * m;
  return kCoatF0 + (1.0 - kCoatF0) * (m2 * m2 * m);
}

float sheenRoughnessClamped(float roughness) { return clamp(roughness, kMinSheenRoughness, 1.0); }

// Charlie distribution (Conty and Kulla 2017, as KHR_materials_sheen writes it) per steradian of the unit
// half vector h: (2 + 1 / alpha) sin(theta_h)^(1 / alpha) / (2 pi); alpha = sheen roughness^2.
float sheenD(vec3 h, float alpha) {
  float invAlpha = 1.0 / alpha;
  float sin2 = max(0.0, 1.0 - h.z * h.z);
  return (2.0 + invAlpha) * pow(sin2, 0.5 * invAlpha) / (2.0 * PI);
}

// The fit L(x) of the Charlie masking term, interpolated between alpha = 0 and 1 by (1 - alpha)^2.
float sheenL(float x, float alpha) {
  float t = (1.0 - alpha) * (1.0 - alpha);
  float a = mix(21.5473, 25.3245, t);
  float b = mix(3.82987, 3.32435, t);
  float c = mix(0.19823, 0.16801, t);
  float d = mix(-1.97760, -1.27393, t);
  float e = mix(-4.32054, -4.85967, t);
  return a / (1.0 + b * pow(x, c)) + d * x + e;
}

float sheenLambda(float cosTheta, float alpha) {
  float c = abs(cosTheta);
  return c < 0.5 ? exp(sheenL(c, alpha)) : exp(2.0 * sheenL(0.5, alpha) - sheenL(1.0 - c, alpha));
}

// The Charlie visibility G / (4 cos_o cos_i), both cosines > 0.
float sheenVisibility(float cosO, float cosI, float alpha) {
  return 1.0 / ((1.0 + sheenLambda(cosO, alpha) + sheenLambda(cosI, alpha)) * (4.0 * cosO * cosI));
}

// Directional albedo E(cos theta_o, roughness) of the white Charlie BRDF: bilinear in (sqrt(mu),
// roughness) over the table (scripts/make-sheen-albedo). At grazing angles and roughness below ~0.25
// it exceeds 1 (the BRDF as the extension defines it reflects more than it receives there).
float sheenAlbedo(float cosTheta, float roughness) {
  const int nMu = CAUSTICA_SHEEN_ALBEDO_MU, nR = CAUSTICA_SHEEN_ALBEDO_ROUGHNESS;
  float x = sqrt(clamp(cosTheta, 0.0, 1.0)) * float(nMu - 1);
  float y = (sheenRoughnessClamped(roughness) - kMinSheenRoughness) / (1.0 - kMinSheenRoughness) * float(nR - 1);
  int i = min(int(x), nMu - 2), j = min(int(y), nR - 2);
  float fx = x - float(i), fy = y - float(j);
  int k = j * nMu + i;
  float lo = mix(kSheenAlbedo[k], kSheenAlbedo[k + 1], fx);
  float hi = mix(kSheenAlbedo[k + nMu], kSheenAlbedo[k + nMu + 1], fx);
  return mix(lo, hi, fy);
}

// The sheen lobe, given the path took it (the lobe kLobeSheen of microfacet.glsl): the Charlie BRDF
// scaled to directional albedo `tint` (sheen colour / its largest component), f = tint D V / E(cos_o).
// wo.z > 0 and wi.z > 0; alpha = roughness^2.
vec3 sheenEval(vec3 tint, float alpha, vec3 wo, vec3 wi) {
  vec3 h = wo + wi;
  float len = length(h);
  if (!(len > 0.0)) return vec3(0.0);
  h /= len;
  float e = max(sheenAlbedo(wo.z, sqrt(alpha)), kMinSheenAlbedo);
  return tint * (sheenD(h, alpha) * sheenVisibility(wo.z, wi.z, alpha) / e);
}

// Its sampling: uniform over the hemisphere (the lobe lives at grazing angles, where cosine sampling
// seldom goes), pdf 1 / (2 pi).
vec3 sampleUniformHemisphere(vec2 u) {
  float z = u.x;
  float r = sqrt(max(0.0, 1.0 - z * z));
  float phi = 2.0 * PI * u.y;
  return vec3(r * cos(phi), r * sin(phi), z);
}

// The layered BRDF at a hit,
//   f = w_c f_coat + (1 - w_c) (w_s f_sheen + (1 - w_s) f_base),
//   w_c = clearcoat F_coat(cos_o to the coat normal), w_s = max(sheenColor) min(E(cos_o), 1),
// with f_coat the coat's GGX reflection (F = 1), f_sheen the sheen lobe (the Charlie BRDF scaled to
// albedo sheenColor / max(sheenColor)) and f_base the material's own lobes, is estimated by picking one:
// the coat with probability coatPick, else the sheen with probability w_s, else the base; the pick is
// weighed by its weight over its probability (1 for the sheen and the base's own lobes). coatPick
// leans towards the layer that reflects more: w_c / (w_c + (1 - w_c) a) for a base of albedo a (its
// colour's luminance), at most 0.9 unless w_c is above that: a dark base under a coat would otherwise
// spend most samples on itself and leave the coat's highlight to a few (w_c is 0.04 head-on).
struct LayerWeights {
  float coat;      // w_c: clearcoat x coatFresnel(cos to the coat normal)
  float sheen;     // w_s: max(sheen colour) x min(E(cos to the shading normal, roughness), 1)
  float coatPick;  // the probability of picking the coat (0 where w_c is 0)
};

LayerWeights layerWeights(float coat, float cosCoat, vec3 sheenColor, float sheenRoughness, float cosBase,
                          float baseAlbedo) {
  LayerWeights w;
  w.coat = coat * coatFresnel(cosCoat);
  float c = maxComponent(sheenColor);
  w.sheen = c > 0.0 ? c * min(sheenAlbedo(cosBase, sheenRoughness), 1.0) : 0.0;
  float lean = w.coat / (w.coat + (1.0 - w.coat) * clamp(baseAlbedo, 0.0, 1.0));
  w.coatPick = w.coat > 0.0 ? min(lean, max(w.coat, 0.9)) : 0.0;
  return w;
}

// The albedo of the layered material at a hit, for feature buffers: the coat counts as white, the sheen
// as its colour times min(E, 1), below them `baseAlbedo` (what the base material's lobes reflect).
vec3 layeredAlbedo(LayerWeights w, vec3 sheenColor, vec3 baseAlbedo) {
  float c = maxComponent(sheenColor);
  vec3 sheen = c > 0.0 ? sheenColor / c : vec3(0.0);
  return vec3(w.coat) + (1.0 - w.coat) * (w.sheen * sheen + (1.0 - w.sheen) * baseAlbedo);
}
