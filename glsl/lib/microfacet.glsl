// microfacet.glsl — GGX (Trowbridge–Reitz) with Smith height-correlated masking-shadowing and
// visible-normal sampling (Dupuy & Benyoub 2023), and the non-delta lobes built on it: rough metal,
// plastic (glTF fresnel_mix) and rough glass (Walter et al. 2007). Twins in app/shading/microfacet.cpp.
// Directions are in the local shading frame (unit, normal = +z); wo points back along the path, wi
// towards the light. Needs sampling.glsl (PI, luminance, fresnelDielectric, refractDir, sampleCosineHemisphere).

const uint kLobeDiffuse = 0u;     // Lambertian, C / pi (its code stays in pathtrace.comp: caustic casters)
const uint kLobeMirror = 1u;      // smooth metal: delta reflection times C
const uint kLobeGlass = 2u;       // smooth dielectric: delta reflection / refraction
const uint kLobeConductor = 3u;   // rough metal: GGX, Schlick Fresnel with F0 = C
const uint kLobePlastic = 4u;     // GGX dielectric specular over Lambertian
const uint kLobeRoughGlass = 5u;  // rough dielectric: GGX reflection and refraction

const float kDeltaAlpha = 1.0e-3;       // below this GGX alpha a metal or glass lobe is the delta lobe
const float kMinPlasticAlpha = 1.0e-3;  // the plastic lobe's alpha is at least this

// One lobe with its parameters at a shading point.
struct Bsdf {
  uint lobe;
  vec3 color;  // base colour C: diffuse albedo, conductor F0, transmission tint
  float alpha; // GGX alpha = roughness^2
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

// f(wo, wi) without the cosine; 0 where the lobe has no value.
vec3 bsdfEval(Bsdf b, vec3 wo, vec3 wi) {
  if (wo.z <= 0.0) return vec3(0.0);
  if (b.lobe == kLobeRoughGlass) {
    if (wi.z == 0.0) return vec3(0.0);
    bool refl = wi.z > 0.0;
    float etap = refl ? 1.0 : b.eta;
    vec3 wm;
    if (!generalizedHalf(wo, wi, etap, wm)) return vec3(0.0);
    float f = fresnelDielectric(dot(wo, wm), b.eta);
    float dg = ggxD(wm, b.alpha) * ggxG2(wo, wi, b.alpha);
    if (refl) return vec3(dg * f / (4.0 * wi.z * wo.z));
    float s = dot(wi, wm) + dot(wo, wm) / etap;
    float denom = s * s * wi.z * wo.z;
    float t = dg * (1.0 - f) * abs(dot(wi, wm) * dot(wo, wm) / denom) / (etap * etap);
    return b.color * t;
  }
  if (wi.z <= 0.0) return vec3(0.0);
  if (b.lobe == kLobeDiffuse) return b.color * INV_PI;
  vec3 h = wo + wi;
  float len = length(h);
  if (!(len > 0.0)) return vec3(0.0);
  h /= len;
  float spec = ggxD(h, b.alpha) * ggxG2(wo, wi, b.alpha) / (4.0 * wo.z * wi.z);
  float cosH = dot(wo, h);
  if (b.lobe == kLobeConductor) return fresnelSchlick(b.color, vec3(1.0), cosH) * spec;
  vec3 f = fresnelSchlick(b.f0, vec3(b.f90), cosH);
  return f * spec + (1.0 - maxComponent(f)) * b.color * INV_PI;
}

// Solid-angle density with which bsdfSample produces wi.
float bsdfPdf(Bsdf b, vec3 wo, vec3 wi) {
  if (wo.z <= 0.0) return 0.0;
  if (b.lobe == kLobeRoughGlass) {
    if (wi.z == 0.0) return 0.0;
    bool refl = wi.z > 0.0;
    float etap = refl ? 1.0 : b.eta;
    vec3 wm;
    if (!generalizedHalf(wo, wi, etap, wm)) return 0.0;
    float f = fresnelDielectric(dot(wo, wm), b.eta);
    float pm = ggxVisibleNormalPdf(wo, wm, b.alpha);
    if (refl) return pm / (4.0 * abs(dot(wo, wm))) * f;
    float s = dot(wi, wm) + dot(wo, wm) / etap;
    return pm * abs(dot(wi, wm)) / (s * s) * (1.0 - f);
  }
  if (wi.z <= 0.0) return 0.0;
  if (b.lobe == kLobeDiffuse) return wi.z * INV_PI;
  vec3 h = wo + wi;
  float len = length(h);
  if (!(len > 0.0)) return 0.0;
  h /= len;
  float ps = ggxVisibleNormalPdf(wo, h, b.alpha) / (4.0 * dot(wo, h));
  if (b.lobe == kLobeConductor) return ps;
  float p = plasticSpecularProbability(b, wo);
  return p * ps + (1.0 - p) * wi.z * INV_PI;
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
  if (b.lobe == kLobeRoughGlass) {
    vec3 wm = ggxSampleVisibleNormal(wo, b.alpha, uDir);
    float f = fresnelDielectric(dot(wo, wm), b.eta);
    if (u.x < f) {
      s.wi = reflectAbout(wo, wm);
      if (s.wi.z <= 0.0) return false;
    } else {
      if (!refractDir(-wo, wm, 1.0 / b.eta, s.wi) || s.wi.z >= 0.0) return false;
      s.transmitted = true;
    }
  } else if (b.lobe == kLobeDiffuse) {
    s.wi = sampleCosineHemisphere(uDir);
  } else if (b.lobe == kLobeConductor || u.x < plasticSpecularProbability(b, wo)) {
    s.wi = reflectAbout(wo, ggxSampleVisibleNormal(wo, b.alpha, uDir));
    if (s.wi.z <= 0.0) return false;
  } else {
    s.wi = sampleCosineHemisphere(uDir);
  }
  s.pdf = bsdfPdf(b, wo, s.wi);
  if (!(s.pdf > 0.0)) return false;
  s.weight = bsdfEval(b, wo, s.wi) * (abs(s.wi.z) / s.pdf);
  return true;
}
