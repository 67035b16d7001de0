// microfacet.glsl — GGX (Trowbridge–Reitz) with Smith height-correlated masking-shadowing and
// visible-normal sampling (Dupuy & Benyoub 2023), and the non-delta lobes built on it: rough metal,
// plastic (glTF fresnel_mix) and rough glass (Walter et al. 2007). Twins in app/shading/microfacet.cpp.
// Directions are in the local shading frame (unit, normal = +z); wo points back along the path, wi
// towards the light. Needs sampling.glsl (PI, luminance, fresnelDielectric, refractDir, sampleCosineHemisphere).
// The sheen lobe's own functions are in layers.glsl.

#include "layers.glsl"

const uint kLobeDiffuse = 0u;     // Lambertian, C / pi (sampled in path_scatter.glsl: caustic casters)
const uint kLobeMirror = 1u;      // smooth metal: delta reflection times C
const uint kLobeGlass = 2u;       // smooth dielectric: delta reflection / refraction
const uint kLobeConductor = 3u;   // rough metal: GGX, Schlick Fresnel with F0 = C
const uint kLobePlastic = 4u;     // GGX dielectric specular over Lambertian
const uint kLobeRoughGlass = 5u;  // rough dielectric: GGX reflection and refraction
const uint kLobeSheen = 6u;       // the Charlie sheen (KHR_materials_sheen), scaled to albedo C (layers.glsl)

// The glossy lobes (from kLobeConductor up: non-delta and not Lambertian) are compiled in when a
// feature that makes one is (the shader-feature table): the bounce loop's glossy branches
// (path_scatter.glsl) test this, so a new glossy lobe adds its define here, not there. The clear coat
// is a white metal lobe (kLobeMirror when smooth, kLobeConductor when rough) on the coat's normal.
#if defined(CAUSTICA_GGX) || defined(CAUSTICA_CLEARCOAT) || defined(CAUSTICA_SHEEN)
#define CAUSTICA_GLOSSY_LOBES
#endif
// The mirror and conductor lobes: metals and the clear coat.
#if defined(CAUSTICA_MIRROR) || defined(CAUSTICA_CLEARCOAT)
#define CAUSTICA_MIRROR_LOBE
#endif

const float kDeltaAlpha = 1.0e-3;       // below this GGX alpha a metal or glass lobe is the delta lobe
const float kMinPlasticAlpha = 1.0e-3;  // the plastic lobe's alpha is at least this

// Whether lobe l is rough glass / rough metal. With CAUSTICA_GGX set (a path tracer or Whitted variant)
// chooseLobe makes rough glass only with CAUSTICA_GLASS and rough metal only with CAUSTICA_MIRROR, so
// without them the test is a constant and that lobe's code folds away (llvmpipe would run it masked
// on every call). Without CAUSTICA_GGX (the twin tests) every lobe is possible.
#if defined(CAUSTICA_GGX) && !defined(CAUSTICA_GLASS)
#define CAUSTICA_IS_ROUGH_GLASS(l) false
#else
#define CAUSTICA_IS_ROUGH_GLASS(l) ((l) == kLobeRoughGlass)
#endif
#if defined(CAUSTICA_GGX) && !defined(CAUSTICA_MIRROR_LOBE)
#define CAUSTICA_IS_CONDUCTOR(l) false
#else
#define CAUSTICA_IS_CONDUCTOR(l) ((l) == kLobeConductor)
#endif
#if defined(CAUSTICA_GGX) && !defined(CAUSTICA_SHEEN)
#define CAUSTICA_IS_SHEEN(l) false
#else
#define CAUSTICA_IS_SHEEN(l) ((l) == kLobeSheen)
#endif

// One lobe with its parameters at a shading point.
struct Bsdf {
  uint lobe;
  vec3 color;  // base colour C: diffuse albedo, conductor F0, transmission tint; sheen: its albedo
  float alpha; // GGX alpha = roughness^2 (sheen: sheen roughness^2)
  float eta;   // dielectric: n on the wi side of a refraction / n on the wo side
  vec3 f0;     // plastic: specular reflectance at normal incidence
  float f90;   // plastic: specular reflectance at grazing incidence
};

// A sampled direction (local), its weight f |cos theta_i| / pdf and its solid-angle pdf.
struct BsdfSample {
  vec3 wi;
  vec3 weight;
  float pdf;
  bool transmitted;
};

float ggxD(vec3 h, float alpha) {
  if (h.z <= 0.0) return 0.0;
  float a2 = alpha * alpha;
  float d = (h.x * h.x + h.y * h.y) + h.z * h.z * a2;
  return a2 / (PI * d * d);
}

float ggxLambda(vec3 w, float alpha) {
  float z2 = w.z * w.z;
  if (!(z2 > 0.0)) return 3.0e38;
  float x = alpha * alpha * (w.x * w.x + w.y * w.y) / z2;
  return 0.5 * x / (sqrt(1.0 + x) + 1.0);
}

float ggxG1(vec3 w, float alpha) { return 1.0 / (1.0 + ggxLambda(w, alpha)); }

float ggxG2(vec3 wo, vec3 wi, float alpha) {
  return 1.0 / (1.0 + ggxLambda(wo, alpha) + ggxLambda(wi, alpha));
}

vec3 ggxSampleVisibleNormal(vec3 wo, float alpha, vec2 u) {
  vec3 ws = normalize(vec3(wo.x * alpha, wo.y * alpha, wo.z));
  float phi = 2.0 * PI * u.x;
  float hz = (1.0 - u.y) * (1.0 + ws.z);  // z + ws.z, without the cancellation of the sum near the cap's edge
  float z = hz - ws.z;
  float sinTheta = sqrt(clamp(1.0 - z * z, 0.0, 1.0));
  vec3 h = vec3(sinTheta * cos(phi) + ws.x, sinTheta * sin(phi) + ws.y, hz);
  h = vec3(h.x * alpha, h.y * alpha, max(h.z, 0.0));
  float len = length(h);
  return len > 0.0 ? h / len : vec3(0.0, 0.0, 1.0);
}

float ggxVisibleNormalPdf(vec3 wo, vec3 h, float alpha) {
  if (wo.z <= 0.0) return 0.0;
  return ggxG1(wo, alpha) * max(0.0, dot(wo, h)) * ggxD(h, alpha) / wo.z;
}

vec3 fresnelSchlick(vec3 f0, vec3 f90, float cosTheta) {
  float m = clamp(1.0 - cosTheta, 0.0, 1.0);
  float m2 = m * m;
  return f0 + (f90 - f0) * (m2 * m2 * m);
}

vec3 reflectAbout(vec3 wo, vec3 h) { return 2.0 * dot(wo, h) * h - wo; }

bool generalizedHalf(vec3 wo, vec3 wi, float etap, out vec3 wm) {
  wm = wi * etap + wo;
  float len = length(wm);
  if (!(len > 0.0)) return false;
  wm /= len;
  if (wm.z < 0.0) wm = -wm;
  if (wm.z == 0.0) return false;
  return dot(wm, wi) * wi.z >= 0.0 && dot(wm, wo) * wo.z >= 0.0;
}

float plasticSpecularProbability(Bsdf b, vec3 wo) {
  float fo = maxComponent(fresnelSchlick(b.f0, vec3(b.f90), wo.z));
  float d = (1.0 - fo) * luminance(b.color);
  float p = fo + d > 0.0 ? fo / (fo + d) : 1.0;
  return clamp(p, 0.1, 0.9);
}

// f(wo, wi) without the cosine (out f) and the solid-angle density with which bsdfSample produces wi
// (returned); both 0 where the lobe has no value. One body for every lobe: llvmpipe runs both sides of
// every branch for all 8 SIMD lanes, so the half vector (generalised for rough glass, wo + wi
// normalised otherwise: etap = 1 there, and wi * 1 + wo is wo + wi exactly), D, Lambda(wo), Lambda(wi)
// and the Schlick term are computed once with per-lane selected inputs, not once per lobe, and f and
// the pdf share them. Each lobe's value is the same arithmetic in the same order as the C++ twins
// bsdfEval and bsdfPdf (app/shading/microfacet.cpp), so bit for bit what separate code gave.
float bsdfEvalPdf(Bsdf b, vec3 wo, vec3 wi, out vec3 f) {
  f = vec3(0.0);
  if (wo.z <= 0.0) return 0.0;
  bool roughGlass = CAUSTICA_IS_ROUGH_GLASS(b.lobe);
  if (roughGlass ? wi.z == 0.0 : wi.z <= 0.0) return 0.0;
  if (b.lobe == kLobeDiffuse) {
    f = b.color * INV_PI;
    return wi.z * INV_PI;
  }
  if (CAUSTICA_IS_SHEEN(b.lobe)) {
    f = sheenEval(b.color, b.alpha, wo, wi);
    return 0.5 * INV_PI;  // sampleUniformHemisphere
  }
  bool refl = wi.z > 0.0;  // always outside rough glass
  float etap = refl ? 1.0 : b.eta;
  vec3 m = wi * etap + wo;  // generalizedHalf's arithmetic; the reflection half vector when etap = 1
  float len = length(m);
  if (!(len > 0.0)) return 0.0;
  m /= len;
  if (roughGlass) {
    if (m.z < 0.0) m = -m;
    if (m.z == 0.0 || !(dot(m, wi) * wi.z >= 0.0 && dot(m, wo) * wo.z >= 0.0)) return 0.0;
  }
  float d = ggxD(m, b.alpha);
  float lambdaO = ggxLambda(wo, b.alpha);
  float g2 = 1.0 / (1.0 + lambdaO + ggxLambda(wi, b.alpha));  // ggxG2
  float cosM = dot(wo, m);
  float pm = 1.0 / (1.0 + lambdaO) * max(0.0, cosM) * d / wo.z;  // ggxVisibleNormalPdf (wo.z > 0 here)
  if (roughGlass) {
    float fr = fresnelDielectric(cosM, b.eta);
    float dg = d * g2;
    if (refl) {
      f = vec3(dg * fr / (4.0 * wi.z * wo.z));
      return pm / (4.0 * abs(cosM)) * fr;
    }
    float cosI = dot(wi, m);
    float s = cosI + cosM / etap;
    float denom = s * s * wi.z * wo.z;
    f = b.color * (dg * (1.0 - fr) * abs(cosI * cosM / denom) / (etap * etap));
    return pm * abs(cosI) / (s * s) * (1.0 - fr);
  }
  float spec = d * g2 / (4.0 * wo.z * wi.z);
  float ps = pm / (4.0 * cosM);
  bool conductor = CAUSTICA_IS_CONDUCTOR(b.lobe);
  vec3 fs = fresnelSchlick(conductor ? b.color : b.f0, conductor ? vec3(1.0) : vec3(b.f90), cosM);
  if (conductor) {
    f = fs * spec;
    return ps;
  }
  f = fs * spec + (1.0 - maxComponent(fs)) * b.color * INV_PI;
  float p = plasticSpecularProbability(b, wo);
  return p * ps + (1.0 - p) * wi.z * INV_PI;
}

// f(wo, wi) without the cosine; 0 where the lobe has no value.
vec3 bsdfEval(Bsdf b, vec3 wo, vec3 wi) {
  vec3 f;
  bsdfEvalPdf(b, wo, wi, f);
  return f;
}

// Solid-angle density with which bsdfSample produces wi.
float bsdfPdf(Bsdf b, vec3 wo, vec3 wi) {
  vec3 f;
  return bsdfEvalPdf(b, wo, wi, f);
}

// Samples wi; u.x chooses the part (specular or diffuse, reflection or refraction), u.yz the direction.
// False when the sample is lost (below the surface): the path ends.
bool bsdfSample(Bsdf b, vec3 wo, vec3 u, out BsdfSample s) {
  s.wi = vec3(0.0);
  s.weight = vec3(0.0);
  s.pdf = 0.0;
  s.transmitted = false;
  if (wo.z <= 0.0) return false;
  vec2 uDir = u.yz;
  // One call of each direction sampler and of reflectAbout for every lobe (llvmpipe runs every branch):
  // a visible normal for rough glass, rough metal and plastic's specular part, a cosine direction for
  // the diffuse lobe and plastic's diffuse part, a uniform one for the sheen.
  bool roughGlass = CAUSTICA_IS_ROUGH_GLASS(b.lobe);
  bool sheen = CAUSTICA_IS_SHEEN(b.lobe);
  vec3 wm = ggxSampleVisibleNormal(wo, b.alpha, uDir);
  float f = fresnelDielectric(dot(wo, wm), b.eta);  // rough glass only
  bool specular = roughGlass ? u.x < f
                             : b.lobe != kLobeDiffuse && !sheen &&
                                   (CAUSTICA_IS_CONDUCTOR(b.lobe) || u.x < plasticSpecularProbability(b, wo));
  if (roughGlass && !specular) {
    if (!refractDir(-wo, wm, 1.0 / b.eta, s.wi) || s.wi.z >= 0.0) return false;
    s.transmitted = true;
  } else if (specular) {
    s.wi = reflectAbout(wo, wm);
    if (s.wi.z <= 0.0) return false;
  } else {
    s.wi = sheen ? sampleUniformHemisphere(uDir) : sampleCosineHemisphere(uDir);
  }
  vec3 fv;
  s.pdf = bsdfEvalPdf(b, wo, s.wi, fv);
  if (!(s.pdf > 0.0)) return false;
  s.weight = fv * (abs(s.wi.z) / s.pdf);
  return true;
}
