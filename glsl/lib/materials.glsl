// materials.glsl — the material contract (docs/materials.md) on the GPU: base colour, opacity,
// metallic and roughness, transmission, the specular layer, emission, normal maps, the clear-coat and
// sheen layers' parameters (layers.glsl), lobe choice (metal weight m, glass (1-m)t, diffuse (1-m)(1-t);
// each a delta lobe or a GGX lobe from microfacet.glsl) and the smooth dielectric.

// Linear base colour (rgb) and opacity (a) at uv, for a hit whose vertex colour (COLOR_0) is
// vertexColor: factor x texture x vertex colour (glTF 3.9.2); alpha likewise in BLEND and MASK only.
vec4 materialBaseColor(Material m, vec2 uv, vec4 vertexColor) {
  vec4 c = m.baseColor;
#ifdef CAUSTICA_VERTEX_COLORS
  c.rgb *= vertexColor.rgb;
  if ((m.tex.z & kMatVertexAlpha) != 0u) c.a *= vertexColor.a;
#endif
#ifdef CAUSTICA_TEXTURES
  if (m.tex.x != kInvalidIndex) {
    vec4 t = sampleTexture(m.tex.x, uv);
    c.rgb *= t.rgb;
    if ((m.tex.z & kMatAlphaTexture) != 0u) c.a *= t.a;  // BLEND and MASK only; OPAQUE ignores alpha
#ifndef CAUSTICA_VERTEX_COLORS
    if ((m.tex.z & kMatAlphaMask) != 0u) c.a = c.a >= uintBitsToFloat(m.tex2.w) ? 1.0 : 0.0;
#endif
  }
#endif
#ifdef CAUSTICA_VERTEX_COLORS
  // MASK with a texture or vertex alpha: the threshold of the product (without either, the host
  // thresholded the factor).
  if ((m.tex.z & kMatAlphaMask) != 0u) c.a = c.a >= uintBitsToFloat(m.tex2.w) ? 1.0 : 0.0;
#endif
  return c;
}

// Metallic (x) and roughness (y) at uv: the factors times the metallicRoughness texture (B, G; linear).
vec2 materialMetalRough(Material m, vec2 uv) {
  vec2 mr = m.params.xy;
#ifdef CAUSTICA_TEXTURES
  if (m.tex2.x != kInvalidIndex) mr *= sampleDataTexture(m.tex2.x, uv).bg;
#endif
  return mr;
}

// Transmission (the glass weight before metal) at uv: the factor times transmissionTexture's R (linear).
float materialTransmission(Material m, vec2 uv) {
  float t = m.params.z;
#ifdef CAUSTICA_FACTOR_TEXTURES
  if (m.tex4.w != kInvalidIndex) t *= sampleDataTexture(m.tex4.w, uv).r;
#endif
  return t;
}

// The specular layer's F0 (rgb) and F90 (w) at uv (KHR_materials_specular): with its textures,
// F0 = min(((ior - 1) / (ior + 1))^2 specularColorFactor x specularColorTexture, 1) x specularFactor x
// specularTexture.a and F90 = specularFactor x specularTexture.a; else the factors' (packed).
vec4 materialSpecular(Material m, vec2 uv) {
  vec4 s = m.specular;
#ifdef CAUSTICA_FACTOR_TEXTURES
  if (m.tex4.y != kInvalidIndex || m.tex4.z != kInvalidIndex) {
    vec3 tint = m.specularBase.rgb;
    float factor = m.specularBase.w;
    if (m.tex4.z != kInvalidIndex) tint *= sampleTexture(m.tex4.z, uv).rgb;
    if (m.tex4.y != kInvalidIndex) factor *= sampleDataTexture(m.tex4.y, uv).a;
    s = vec4(min(tint, vec3(1.0)) * factor, factor);
  }
#endif
  return s;
}

#ifdef CAUSTICA_CLEARCOAT
// Clear-coat weight (x) and roughness (y) at uv: the factors times clearcoatTexture's R and
// clearcoatRoughnessTexture's G (linear).
vec2 materialCoat(Material m, vec2 uv) {
  vec2 c = m.coat.xy;
#ifdef CAUSTICA_TEXTURES
  if (m.tex3.x != kInvalidIndex) c.x *= sampleDataTexture(m.tex3.x, uv).r;
  if (m.tex3.y != kInvalidIndex) c.y *= sampleDataTexture(m.tex3.y, uv).g;
#endif
  return c;
}
#endif

#ifdef CAUSTICA_SHEEN
// Sheen colour (rgb, linear) and roughness (w) at uv: the factors times sheenColorTexture's RGB (sRGB)
// and sheenRoughnessTexture's A.
vec4 materialSheen(Material m, vec2 uv) {
  vec4 s = m.sheen;
#ifdef CAUSTICA_TEXTURES
  if (m.tex3.w != kInvalidIndex) s.rgb *= sampleTexture(m.tex3.w, uv).rgb;
  if (m.tex4.x != kInvalidIndex) s.w *= sampleDataTexture(m.tex4.x, uv).a;
#endif
  return s;
}
#endif

#ifdef CAUSTICA_TEXTURES
// The triangle's tangent frame: t its dp/du made orthogonal to n, b = cross(n, t) turned towards -v;
// false where the texcoords or dp/du are degenerate.
bool tangentFromTriangle(vec3 n, vec3 p0, vec3 p1, vec3 p2, vec2 uv0, vec2 uv1, vec2 uv2, out vec3 t, out vec3 b) {
  vec3 dp1 = p1 - p0, dp2 = p2 - p0;
  vec2 d1 = uv1 - uv0, d2 = uv2 - uv0;
  float det = d1.x * d2.y - d1.y * d2.x;
  if (!(abs(det) > 0.0)) return false;
  vec3 dpdu = (dp1 * d2.y - dp2 * d1.y) / det;
  vec3 dpdv = (dp2 * d1.x - dp1 * d2.x) / det;
  t = dpdu - n * dot(n, dpdu);
  float tLen = length(t);
  if (!(tLen > 0.0)) return false;
  t /= tLen;
  b = cross(n, t);
  if (dot(b, dpdv) > 0.0) b = -b;  // bitangent points towards -v (up in the image), mirrored maps included
  return true;
}
#endif

// The shading normal after normal map `tex` (tangent space, glTF: +x along the tangent, +y along the
// bitangent; its x and y times `scale`). n: interpolated unit normal on the front side; tangent: the
// file's TANGENT interpolated at the hit (xyz; w the bitangent's sign, glTF: bitangent = cross(n,
// tangent) w), or w = 0 where the mesh has none: then the tangent is the triangle's dp/du (from p0..p2
// and uv0..uv2) and the bitangent points towards -v (up in the image), the same frame for an unmirrored
// map. Either tangent is made orthogonal to n. Returns n where the map or the frame is unusable.
vec3 applyNormalMapTexture(uint tex, float scale, vec3 n, vec2 uv, vec3 p0, vec3 p1, vec3 p2, vec2 uv0, vec2 uv1,
                           vec2 uv2, vec4 tangent) {
#ifdef CAUSTICA_TEXTURES
  if (tex == kInvalidIndex) return n;
  vec3 t, b;
  if (tangent.w != 0.0) {
    t = tangent.xyz - n * dot(n, tangent.xyz);
    float len = length(t);
    if (!(len > 0.0)) return n;
    t /= len;
    b = cross(n, t) * (tangent.w < 0.0 ? -1.0 : 1.0);
  } else if (!tangentFromTriangle(n, p0, p1, p2, uv0, uv1, uv2, t, b)) {
    return n;
  }
  vec3 c = sampleDataTexture(tex, uv).xyz * 2.0 - 1.0;
  c.xy *= scale;
  vec3 mapped = c.x * t + c.y * b + c.z * n;
  float len = length(mapped);
  return len > 0.0 && dot(mapped, n) > 0.0 ? mapped / len : n;
#else
  return n;
#endif
}

// The material's normal map (normalTexture) applied to n (applyNormalMapTexture).
vec3 applyNormalMap(Material m, vec3 n, vec2 uv, vec3 p0, vec3 p1, vec3 p2, vec2 uv0, vec2 uv1, vec2 uv2,
                    vec4 tangent) {
  return applyNormalMapTexture(m.tex2.y, uintBitsToFloat(m.tex2.z), n, uv, p0, p1, p2, uv0, uv1, uv2, tangent);
}

// Emitted radiance at uv (front face only unless double-sided; the caller checks the side).
vec3 materialEmission(Material m, vec2 uv) {
  vec3 e = m.emission.rgb;
#ifdef CAUSTICA_TEXTURES
  if (m.tex.y != kInvalidIndex) e *= sampleTexture(m.tex.y, uv).rgb;
#endif
  return e;
}

// Emitted radiance at uv leaving at |cos theta| to the geometric normal, as a path or light sampling
// sees it: under a clear coat darkened by the coat's weight (KHR_materials_clearcoat: emission x
// (1 - clearcoat x Fresnel); the Fresnel is taken to the geometric normal, the one light sampling knows).
vec3 materialEmissionSeen(Material m, vec2 uv, float cosTheta) {
  vec3 e = materialEmission(m, uv);
#ifdef CAUSTICA_CLEARCOAT
  e *= 1.0 - materialCoat(m, uv).x * coatFresnel(cosTheta);
#endif
  return e;
}

bool isEmissive(Material m) { return maxComponent(m.emission.rgb) > 0.0; }

// Picks one lobe with probability equal to its weight, so lobe weights cancel in the estimator.
// metal: the metallic value at the hit (materialMetalRough). With CAUSTICA_GGX a metal or glass with
// GGX alpha = roughness^2 >= kDeltaAlpha takes its rough lobe, and a diffuse part with a specular
// layer (F90 > 0) the plastic lobe; otherwise the delta lobes and the Lambertian lobe as before.
// (Glass of ior 1 stays the delta lobe: it passes light straight through, and the generalised half
// vector of rough refraction does not exist there.)
uint chooseLobe(Material m, float metal, float roughness, float trans, float u) {
#ifndef CAUSTICA_MIRROR
  metal = 0.0;
#endif
#ifndef CAUSTICA_GLASS
  trans = 0.0;
#endif
  uint lobe = kLobeDiffuse;
  if (u < metal) lobe = kLobeMirror;
  else if (u < metal + (1.0 - metal) * trans) lobe = kLobeGlass;
#ifdef CAUSTICA_GGX
  bool rough = roughness * roughness >= kDeltaAlpha;
  if (lobe == kLobeMirror && rough) lobe = kLobeConductor;
  else if (lobe == kLobeGlass && rough && m.params.w != 1.0) lobe = kLobeRoughGlass;  // ior 1: no interface
  else if (lobe == kLobeDiffuse && m.specular.w > 0.0) lobe = kLobePlastic;
#endif
  return lobe;
}

// The non-delta lobe `lobe` at a hit: colour C (base colour; the sheen's tint; white for the coat),
// roughness (GGX, or the sheen's), eta (rough glass: n beyond the surface / n on the ray's side) and
// the specular layer's F0 (rgb) and F90 (w) (materialSpecular).
Bsdf makeBsdf(uint lobe, vec3 color, float roughness, float eta, vec4 specular) {
  Bsdf b;
  b.lobe = lobe;
  b.color = color;
  b.alpha = roughness * roughness;
  if (lobe == kLobePlastic) b.alpha = max(b.alpha, kMinPlasticAlpha);
  b.eta = eta;
  b.f0 = specular.rgb;
  b.f90 = specular.w;
  return b;
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
