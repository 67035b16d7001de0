// path_scatter.glsl — how a path tracer's path leaves a surface: alpha pass-through, the layer and lobe
// chosen there (clear coat, sheen, or the base material's lobes), its vertex for light sampling, and
// its direction (Lambertian with the caster mixture, GGX, sheen, mirror, smooth glass) with the
// throughput it costs. Needs path_state.glsl, surface.glsl, materials.glsl, vertex.glsl, spectral.glsl
// (casters.glsl with CAUSTICA_CASTERS).
//
// llvmpipe runs both sides of every branch (masked) for all 8 lanes of a SIMD group, and a loop's
// body at least once, so each call site of a light estimate or a traversal costs on every bounce
// whichever lobe the lanes took. The non-delta lobes (Lambertian and GGX) therefore share one
// vertex and one call of each next-event estimate (pathBounce); each lobe draws its random numbers
// in the same order (its own ones first, then the lights', then its direction), so images do not
// depend on the shader variant (docs/architecture.md, "Writing shaders for llvmpipe").

#ifdef CAUSTICA_OPACITY
// Alpha cut-out: with probability 1 - alpha the path passes straight through the surface (a delta
// event; up to kMaxPassThroughs of them cost no bounce). True when it did.
bool passThrough(inout PathState s, Surface sf, float alpha) {
  if (alpha < 1.0 && rand01(s.rng) >= alpha) {
    s.org = offsetRayOrigin(sf.p, sf.pError, -sf.ng);
    s.prevDelta = true;
#ifdef CAUSTICA_LIGHT_TRACE
    s.ltFamily = false;  // a pass-through is never part of the light tracer's family
#endif
    if (s.passThroughs < kMaxPassThroughs) ++s.passThroughs;  // up to that many layers of cut-outs are free
    else ++s.depth;
#ifdef CAUSTICA_MANIFOLD
    if (s.chain != 0u) s.chain = kChainDead;  // not a caster's event: the chain from x ends
#endif
    return true;
  }
  return false;
}
#endif

// The index of refraction of a glass hit for the wavelength the path carries (nm; 0 = all). The first
// dispersive event picks the path's wavelength (hero wavelength, or one RGB channel) and its filter.
float glassIor(Material m, inout float lambda, inout vec3 filt, inout uvec4 rng) {
  float ior = m.params.w;
#ifdef CAUSTICA_DISPERSION
  if ((m.tex.z & kMatDispersive) != 0u) {
    if (lambda == 0.0) pickWavelength(rand01(rng), lambda, filt);  // kept from its first dispersive event on
    ior = cauchyIor(ior, m.absorption.w, lambda);
  }
#endif
  return ior;
}

// The lobe a path scatters by at a surface, and what its sampling needs.
struct BounceLobe {
  uint lobe;        // kLobe* (microfacet.glsl), chosen with probability equal to its weight
  vec3 color;       // base colour at the hit (the coat: white; the sheen: its colour / its largest component)
  float roughness;  // material roughness at the hit (the coat's or the sheen's for those lobes)
  float eta;        // glass lobes: n beyond the surface / n on the ray's side; 1 for the others
  vec3 sigmaBelow;  // absorption coefficient of the medium beyond the surface (where refracted light goes)
  vec4 specular;    // the specular layer's F0 (rgb) and F90 (w) at the hit (plastic)
};

bool isDiffuseLobe(BounceLobe l) { return l.lobe == kLobeDiffuse; }
bool isGlossyLobe(BounceLobe l) {  // the glossy lobes: rough metal, plastic, rough glass (microfacet.glsl)
#ifdef CAUSTICA_GLOSSY_LOBES
  return l.lobe >= kLobeConductor;
#else
  return false;
#endif
}

// Chooses the lobe at surface sf with base colour `color` (one random number): the clear coat, else the
// sheen, else one of the base material's lobes (layers.glsl: the coat's pick is weighed into s.beta; the
// number is rescaled past each layer, so without layers the base sees it unchanged). The coat's
// lobe (a white metal lobe, delta or GGX by the coat's roughness) works about the coat normal: sf.ns
// becomes sf.nc, so that its vertex, its light sampling and the path's next MIS all use the coat's
// frame. Both glass lobes take the wavelength's index of refraction here (one glassIor call for both).
BounceLobe chooseBounceLobe(inout PathState s, inout Surface sf, vec3 color) {
  BounceLobe l;
  float u = rand01(s.rng);
  vec2 metalRough = materialMetalRough(sf.m, sf.uv);
  float trans = materialTransmission(sf.m, sf.uv);
  l.color = color;
  l.roughness = metalRough.y;
  l.eta = 1.0;
  l.sigmaBelow = s.sigma;
  l.specular = materialSpecular(sf.m, sf.uv);
#if defined(CAUSTICA_CLEARCOAT) || defined(CAUSTICA_SHEEN)
  vec2 coat = vec2(0.0);  // weight, roughness
  float cosCoat = 1.0;
  vec4 sheen = vec4(0.0);  // colour, roughness
#ifdef CAUSTICA_CLEARCOAT
  coat = materialCoat(sf.m, sf.uv);
  cosCoat = -dot(s.dir, sf.nc);
#endif
#ifdef CAUSTICA_SHEEN
  sheen = materialSheen(sf.m, sf.uv);
#endif
  LayerWeights w = layerWeights(coat.x, cosCoat, sheen.rgb, sheen.w, -dot(s.dir, sf.ns), luminance(color));
  bool takeCoat = u < w.coatPick;
  // The pick weighed by its weight over its probability (exactly 1 without a coat).
  s.beta *= takeCoat ? w.coat / w.coatPick : (1.0 - w.coat) / (1.0 - w.coatPick);
  u = w.coatPick < 1.0 ? max(u - w.coatPick, 0.0) / (1.0 - w.coatPick) : 0.0;
  bool takeSheen = !takeCoat && u < w.sheen;
  u = w.sheen < 1.0 ? max(u - w.sheen, 0.0) / (1.0 - w.sheen) : 0.0;
#endif
  l.lobe = chooseLobe(sf.m, metalRough.x, metalRough.y, trans, u);
#ifdef CAUSTICA_SHEEN
  if (takeSheen) {
    l.lobe = kLobeSheen;
    l.color = sheen.rgb / maxComponent(sheen.rgb);
    l.roughness = sheenRoughnessClamped(sheen.w);
  }
#endif
#ifdef CAUSTICA_CLEARCOAT
  if (takeCoat) {
    l.lobe = coat.y * coat.y >= kDeltaAlpha ? kLobeConductor : kLobeMirror;
    l.color = vec3(1.0);
    l.roughness = coat.y;
    sf.ns = sf.nc;
  }
#endif
#ifdef CAUSTICA_GLASS
  if (l.lobe == kLobeGlass || l.lobe == kLobeRoughGlass) {
    float ior = glassIor(sf.m, s.lambda, s.filt, s.rng);
    l.eta = sf.front ? ior : 1.0 / ior;
#ifdef CAUSTICA_VOLUME
    l.sigmaBelow = mediumBeyond(sf);
#endif
  }
#endif
  return l;
}

#ifdef CAUSTICA_CASTERS
// The Lambertian lobe's direction: cosine sampling mixed with directions aimed at glass and mirror
// objects (casters.glsl): more paths reach the caustics they focus; the mixture pdf keeps the estimate
// unbiased and enters MIS. Only at the path's first diffuse vertex (the caustics the camera sees;
// deeper vertices gain less than they cost, docs/path-tracer.md), and not at the last vertex the depth
// limit allows. With light tracing and only emissive triangles to light the scene, not at a vertex of its
// family either (a Lambertian vertex the camera sees directly): the light tracer takes the caustics there,
// and an aimed bounce would mostly find paths the eye path then drops; the caustics seen in a mirror or
// through glass stay the eye paths' to aim at. (The environment's and punctual lights' caustics are the eye
// paths' everywhere: with those, every first diffuse vertex aims.) Drawn before the lights' numbers.
vec3 sampleCasterMixture(inout PathState s, Surface sf) {
  float uChoose = rand01(s.rng);
  bool aim = s.firstDiffuse && nextRayTraced(s);
#ifdef CAUSTICA_LIGHT_TRACE
  bool otherLights = false;  // as resolveManifold tests it: an environment that emits, or a punctual light
#ifdef CAUSTICA_ENV
  otherLights = environmentPresent();  // (CAUSTICA_ENV also compiles for a background alone)
#endif
#ifdef CAUSTICA_PUNCTUAL
  otherLights = true;  // compiled only with a punctual light
#endif
  aim = aim && (!s.ltFamily || otherLights);
#endif
  if (aim) prepareCasters(sf.p, sf.ns, uChoose);
  else gCasterUsable = 0u;
  s.firstDiffuse = false;
  float uPick = rand01(s.rng);
  return sampleDiffuseDirection(sf.ns, uPick, rand2(s.rng));
}
#endif

// The vertex as every light estimate sees it (vertex.glsl), built once for the non-delta lobes: the
// Lambertian lobe (roughness and eta 1) or a glossy lobe. Without glossy lobes (CAUSTICA_GLOSSY_LOBES,
// microfacet.glsl) the lobe here is the Lambertian one: said as a constant, so that the GGX code of
// vertexEval / vertexPdf (bsdfEvalPdf) folds away instead of running masked on every bounce.
Vertex lobeVertex(PathState s, Surface sf, BounceLobe l) {
#ifdef CAUSTICA_GLOSSY_LOBES
  uint vertexLobe = l.lobe;
#else
  const uint vertexLobe = kLobeDiffuse;
#endif
  bool diffuse = isDiffuseLobe(l);
  return makeVertex(makeBsdf(vertexLobe, l.color, diffuse ? 1.0 : l.roughness, l.eta, l.specular), sf.p, sf.pError,
                    sf.ng, sf.ns, s.dir, s.sigma, l.sigmaBelow);
}

// A non-delta lobe's direction (newDir: the caster mixture's, already drawn, with CAUSTICA_CASTERS)
// and its throughput and pdf; false when the path is lost below or through the true surface.
bool scatterNonDelta(inout PathState s, Surface sf, Vertex v, BounceLobe l, inout vec3 newDir) {
  if (isDiffuseLobe(l)) {
#ifdef CAUSTICA_CASTERS
    float cosOut = dot(newDir, sf.ns);
    if (dot(newDir, sf.ng) <= 0.0 || cosOut <= 0.0) return false;  // below the true surface: absorbed
    float pdfDir = diffuseDirectionPdf(sf.ns, newDir);
    s.beta *= l.color * (cosOut * INV_PI / pdfDir);
    s.prevPdf = pdfDir;
#else
    vec3 local = sampleCosineHemisphere(rand2(s.rng));  // in makeVertex's basis about the same ns
    newDir = normalize(local.x * v.t + local.y * v.b + local.z * sf.ns);
    float cosOut = dot(newDir, sf.ns);
    if (dot(newDir, sf.ng) <= 0.0 || cosOut <= 0.0) return false;  // below the true surface: absorbed
    s.beta *= l.color;
    s.prevPdf = cosOut * INV_PI;
#endif
    s.prevDelta = false;
  }
#ifdef CAUSTICA_GLOSSY_LOBES
  else {
    BsdfSample bs;
    float uPart = rand01(s.rng);
    if (!bsdfSample(v.bsdf, v.wo, vec3(uPart, rand2(s.rng)), bs)) return false;
    newDir = vertexToWorld(v, bs.wi);
    if (bs.transmitted ? dot(newDir, sf.ng) >= 0.0 : dot(newDir, sf.ng) <= 0.0) return false;  // through the true surface: lost
    s.beta *= bs.weight;
    s.prevPdf = bs.pdf;
    s.prevDelta = false;
    if (bs.transmitted) {
      s.etaScale *= l.eta * l.eta;
      s.sigma = l.sigmaBelow;
    }
  }
#endif
  return true;
}

bool gDeltaFellBack = false;  // the last scatterDelta used the geometric normal (its shading normal misled it)

// A delta lobe's direction (mirror, smooth clear coat, smooth glass) and throughput.
void scatterDelta(inout PathState s, Surface sf, BounceLobe l, out vec3 newDir) {
  gDeltaFellBack = false;
#ifdef CAUSTICA_MIRROR_LOBE
  if (l.lobe == kLobeMirror) {
    newDir = reflect(s.dir, sf.ns);
    if (dot(newDir, sf.ng) <= 0.0) {
      newDir = reflect(s.dir, sf.ng);
      gDeltaFellBack = true;
    }
    s.beta *= l.color;
    s.prevDelta = true;
  }
#endif
#ifdef CAUSTICA_GLASS
#ifdef CAUSTICA_MIRROR_LOBE
  else
#endif
  {
    bool transmitted;
    float u = rand01(s.rng);
    float weight = sampleDielectric(s.dir, sf.ns, l.eta, u, newDir, transmitted);
    if (transmitted ? dot(newDir, sf.ng) >= 0.0 : dot(newDir, sf.ng) <= 0.0) {  // shading normal misled: use ng
      weight = sampleDielectric(s.dir, sf.ng, l.eta, u, newDir, transmitted);
      gDeltaFellBack = true;
    }
    s.beta *= weight;
    if (transmitted) {
      s.beta *= l.color;  // KHR_materials_transmission: transmitted light is tinted by the base colour
      s.etaScale *= l.eta * l.eta;
#ifdef CAUSTICA_VOLUME
      s.sigma = l.sigmaBelow;
#endif
    }
    s.prevDelta = true;
  }
#endif
}
