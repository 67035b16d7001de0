// vertex.glsl — a scattering vertex as light sampling sees it: the lobe chosen there, in world space.
// vertexEval and vertexPdf are the one interface every next-event estimate uses (emissive triangles
// here; other light kinds call the same two functions). Needs microfacet.glsl, lights.glsl, spawn.glsl,
// traverse.glsl and, with CAUSTICA_CASTERS, casters.glsl (the Lambertian lobe's mixture pdf).

#ifdef CAUSTICA_MANIFOLD
LightSample gManifoldLight;     // the emitter sample of this vertex's next-event estimate (sampleEmitterLight),
bool gManifoldLightOk = false;  // which manifold NEE joins to the vertex through a caster (path_manifold.glsl)
#endif

struct Vertex {
  Bsdf bsdf;        // the lobe chosen at this vertex (never a delta lobe)
  vec3 p;           // hit point (world space)
  vec3 pError;      // bound on p's rounding error, per axis (spawn.glsl)
  vec3 ng;          // unit geometric normal on the side the path arrived from
  vec3 ns;          // unit shading normal on that side; t, b complete the shading frame
  vec3 t;
  vec3 b;
  vec3 wo;          // direction back along the path, local to (t, b, ns)
  vec3 sigmaAbove;  // absorption coefficient (per scene unit) of the medium on the side of ng
  vec3 sigmaBelow;  // ... and beyond the surface (where refracted light travels)
};

Vertex makeVertex(Bsdf bsdf, vec3 p, vec3 pError, vec3 ng, vec3 ns, vec3 dir, vec3 sigmaAbove, vec3 sigmaBelow) {
  Vertex v;
  v.bsdf = bsdf;
  v.p = p;
  v.pError = pError;
  v.ng = ng;
  v.ns = ns;
  orthonormalBasis(ns, v.t, v.b);
  v.wo = vec3(-dot(dir, v.t), -dot(dir, v.b), -dot(dir, ns));
  v.sigmaAbove = sigmaAbove;
  v.sigmaBelow = sigmaBelow;
  return v;
}

vec3 vertexToLocal(Vertex v, vec3 w) { return vec3(dot(w, v.t), dot(w, v.b), dot(w, v.ns)); }
vec3 vertexToWorld(Vertex v, vec3 w) { return normalize(w.x * v.t + w.y * v.b + w.z * v.ns); }

// f(wo, w) |cos theta| with the shading normal for the world direction w (unit, away from p); 0 when
// the shading and geometric normals disagree about w's side (light leaking through the true surface).
vec3 vertexEval(Vertex v, vec3 w) {
  vec3 wl = vertexToLocal(v, w);
  float gs = dot(v.ng, w);
  if (!(wl.z * gs > 0.0)) return vec3(0.0);
  return bsdfEval(v.bsdf, v.wo, wl) * abs(wl.z);
}

// Solid-angle density with which the vertex's own sampling produces w (with CAUSTICA_CASTERS the
// Lambertian lobe's mixture with the caster cones).
float vertexPdf(Vertex v, vec3 w) {
#ifdef CAUSTICA_CASTERS
  if (v.bsdf.lobe == kLobeDiffuse) return diffuseDirectionPdf(v.ns, w);
#endif
  return bsdfPdf(v.bsdf, v.wo, vertexToLocal(v, w));
}

// vertexEval (returned) and vertexPdf (out pdf) of one direction w together: the lobe's value and
// density share their half vector and GGX terms (bsdfEvalPdf), where two calls ran them twice on
// llvmpipe. Same values as the two functions.
vec3 vertexEvalPdf(Vertex v, vec3 w, out float pdf) {
  vec3 wl = vertexToLocal(v, w);
  vec3 f;
  pdf = bsdfEvalPdf(v.bsdf, v.wo, wl, f);
#ifdef CAUSTICA_CASTERS
  if (v.bsdf.lobe == kLobeDiffuse) pdf = diffuseDirectionPdf(v.ns, w);
#endif
  float gs = dot(v.ng, w);
  if (!(wl.z * gs > 0.0)) return vec3(0.0);
  return f * abs(wl.z);
}

// Next-event estimate of the emissive triangles at vertex v: one light sample, weighted against the
// vertex's BSDF sampling by the power heuristic. Returns radiance (to be multiplied by the path
// throughput); adds 1 to shadowRays for each visibility ray traced.
vec3 sampleEmitterLight(Vertex v, inout uvec4 rng, inout uint shadowRays) {
#ifdef CAUSTICA_NO_EMITTERS
  // The scene has no emissive triangles (Renderer::shaderDefines): the estimate is 0, its numbers are
  // drawn all the same (the random stream stays that of the other variants). Left out rather than run
  // masked, since llvmpipe runs every branch and every loop at least once.
  float uSelect = rand01(rng);
  vec2 uTri = rand2(rng);
  return vec3(0.0 * uSelect * uTri.x);
#else
  LightSample ls;
  bool sampled = sampleLight(v.p, v.ns, rand01(rng), rand2(rng), ls);
#ifdef CAUSTICA_MANIFOLD
  gManifoldLight = ls;  // manifold NEE joins the same light sample to x through a caster
  gManifoldLightOk = sampled;
#endif
  if (!sampled) return vec3(0.0);
  vec3 toLight = ls.p - v.p;
  float dist2 = dot(toLight, toLight);
  float dist = sqrt(dist2);
  vec3 wl = toLight / max(dist, 1.0e-30);
  float cosLight = -dot(ls.n, wl);
  if (!((cosLight > 0.0 || (ls.twoSided && cosLight < 0.0)) && dist > 0.0)) return vec3(0.0);
  float pdfVertex;
  vec3 f = vertexEvalPdf(v, wl, pdfVertex);
  if (!(maxComponent(f) > 0.0)) return vec3(0.0);
  vec3 nLight = cosLight > 0.0 ? ls.n : -ls.n;  // the emitter's geometric normal on p's side
  cosLight = abs(cosLight);
  float pdfLight = ls.pdfArea * dist2 / cosLight;
  ++shadowRays;
  // The shadow ray joins two points each moved off its own surface past its error bound (spawn.glsl;
  // pbrt-v4's SpawnRayTo): p along ng on the light's side, the light point along its normal on p's
  // side. The whole segment lies strictly on the lit side of the light's triangle, which therefore
  // cannot occlude its own sample at any angle, distance or scale. (Reusing wl and dist from the
  // unmoved p shifted the ray's end behind the emitter whenever ng and the light's normal point
  // alike: curved lights came out dark, 3-10 %.)
  bool above = dot(v.ng, wl) > 0.0;
  vec3 from = offsetRayOrigin(v.p, v.pError, above ? v.ng : -v.ng);
  vec3 to = offsetRayOrigin(ls.p, ls.pError, nLight);
  vec3 seg = to - from;
  float segLen = length(seg);
  if (!(segLen > 0.0) || traceOccluded(from, seg / segLen, segLen * (1.0 - 1.0e-4))) return vec3(0.0);
  float w = powerHeuristic(pdfLight, pdfVertex);
  vec3 transmittance = vec3(1.0);
#ifdef CAUSTICA_VOLUME
  transmittance = exp(-(above ? v.sigmaAbove : v.sigmaBelow) * dist);  // the medium the shadow ray runs in
#endif
#ifdef CAUSTICA_SPOT_EMITTERS
  ls.le *= spotEmitterFactor(materialAt(ls.material), -wl);  // a --light-radius spot sphere emits into its cone
#endif
  return f * (w / pdfLight) * ls.le * transmittance;
#endif
}
