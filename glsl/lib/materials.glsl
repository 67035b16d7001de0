// materials.glsl — the material contract (docs/materials.md) on the GPU: base colour, emission,
// lobe choice (mirror weight m, glass (1-m)t, diffuse (1-m)(1-t)) and the smooth dielectric.

const uint kLobeDiffuse = 0u;
const uint kLobeMirror = 1u;
const uint kLobeGlass = 2u;

// Linear base colour (rgb) and opacity (a) at uv.
vec4 materialBaseColor(Material m, vec2 uv) {
  vec4 c = m.baseColor;
#ifdef CAUSTICA_TEXTURES
  if (m.tex.x != kInvalidIndex) c.rgb *= sampleTexture(m.tex.x, uv).rgb;
#endif
  return c;
}

// Emitted radiance at uv (front face only unless double-sided; the caller checks the side).
vec3 materialEmission(Material m, vec2 uv) {
  vec3 e = m.emission.rgb;
#ifdef CAUSTICA_TEXTURES
  if (m.tex.y != kInvalidIndex) e *= sampleTexture(m.tex.y, uv).rgb;
#endif
  return e;
}

bool isEmissive(Material m) { return maxComponent(m.emission.rgb) > 0.0; }

// Picks one lobe with probability equal to its weight, so lobe weights cancel in the estimator.
uint chooseLobe(Material m, float u) {
  float metal = 0.0, trans = 0.0;
#ifdef CAUSTICA_MIRROR
  metal = m.params.x;
#endif
#ifdef CAUSTICA_GLASS
  trans = m.params.z;
#endif
  if (u < metal) return kLobeMirror;
  if (u < metal + (1.0 - metal) * trans) return kLobeGlass;
  return kLobeDiffuse;
}

// Smooth dielectric: d is the incident direction (unit, towards the surface), n the unit normal
// facing against d, eta = n_transmitted / n_incident, u uniform in [0,1). Chooses reflection with
// the exact Fresnel probability, else refraction. Returns the throughput factor: 1 for reflection,
// (n_i / n_t)^2 for refraction (radiance is compressed by eta^2 when it crosses into a denser medium).
float sampleDielectric(vec3 d, vec3 n, float eta, float u, out vec3 wi, out bool transmitted) {
  float cosI = -dot(d, n);
  float f = fresnelDielectric(cosI, eta);
  if (u < f || !refractDir(d, n, 1.0 / eta, wi)) {
    wi = reflect(d, n);
    transmitted = false;
    return 1.0;
  }
  transmitted = true;
  return 1.0 / (eta * eta);
}
