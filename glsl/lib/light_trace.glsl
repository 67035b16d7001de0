// light_trace.glsl — what the light tracer (light_trace.comp) and the path tracer agree on: the family
// of paths the light tracer takes over and the density it leaves emitters with (docs/path-tracer.md,
// "Light tracing"). Needs sampling.glsl, casters.glsl, lights.glsl, surface.glsl, materials.glsl.
//
// The family: a Lambertian vertex seen directly by the camera (x1), then any number of Lambertian or
// smooth (mirror, smooth glass) vertices, the last event before an emissive triangle smooth, and the
// emitter's point and direction inside the cone of some caster's bounding sphere (ltEmissionPdf > 0):
// E D (D|S)* S L in Heckbert's notation. No vertex of it lies on a clear-coated or sheen material
// (ltLayered) and no alpha pass-through is part of it. The light tracer adds every such path and only
// those; the path tracer adds every other path, so the two sum to the image with nothing counted twice.

// Whether a vertex on sf ends the family: the clear coat and the sheen weigh their pick by the direction
// the path arrived from, which differs between a light subpath and an eye path (not reciprocal).
bool ltLayered(Surface sf) {
#ifdef CAUSTICA_CLEARCOAT
  if (materialCoat(sf.m, sf.uv).x > 0.0) return true;
#endif
#ifdef CAUSTICA_SHEEN
  if (maxComponent(materialSheen(sf.m, sf.uv).rgb) > 0.0) return true;
#endif
  return false;
}

// The emissive triangle ltEmissionPdf is asked about: its light-tree pdf per unit area from a point.
#ifdef CAUSTICA_INSTANCED
#define LtEmitter TriGeom ltG, InstanceXform ltXf
#define ltEmitterPdfArea(from) instanceLightPdfArea(ltG, ltXf, from, vec3(0.0))
#else
#define LtEmitter uint ltTri
#define ltEmitterPdfArea(from) lightPdfArea(ltTri, from, vec3(0.0))
#endif

// Density (per unit area of the emitter and per steradian) with which light_trace.comp leaves point y of
// the emissive triangle (unit front normal n, two-sided or not) along unit direction w: one of the
// casters.count.x casters picked uniformly, the light tree's choice of a point from the caster's centre
// (normal 0), and a uniform direction in the caster's cone from y (casterCone, as the caustic photons
// leave). Summed over the casters whose cone holds w (one-sample MIS over the casters), so it is the
// density of the whole mixture; 0: no light subpath leaves y along w.
float ltEmissionPdf(LtEmitter, vec3 y, vec3 n, bool twoSided, vec3 w) {
  if (!(dot(w, n) > 0.0 || twoSided)) return 0.0;
  uint count = min(casters.count.x, uint(CAUSTICA_MAX_CASTERS));
  float sum = 0.0;
  for (uint c = 0u; c < uint(CAUSTICA_MAX_CASTERS); ++c) {
    if (c >= count) break;
    vec4 s = casters.sphere[c];
    vec3 axis;
    float omc;
    if (!casterCone(y, twoSided ? normalize(s.xyz - y) : n, s, axis, omc) || !inCone(w, axis, omc)) continue;
    sum += ltEmitterPdfArea(s.xyz) / (2.0 * PI * omc);
  }
  return count > 0u ? sum / float(count) : 0.0;
}

// Where a light subpath leaves (light_trace.comp's start), with ltEmissionPdf its density: caster
// floor(uCaster x casters.count.x), a point on an emissive triangle by the light tree from its centre
// (uSelect, uTri), a uniform direction w in the caster's cone from there (uDir). ls: the point, with its
// radiance along w; tri: its triangle (instanced: within the light tree leaf's instance, gLightInstance);
// pdf: ltEmissionPdf(ls.p, w), per unit area and steradian. False when nothing leaves (w behind a one-sided
// emitter, or pdf 0). tests/gpu/light_trace_gpu_test.cpp holds its histogram against pdf (chi-square).
bool sampleLtEmission(float uCaster, float uSelect, vec2 uTri, vec2 uDir, out LightSample ls, out uint tri,
                      out vec3 w, out float pdf) {
  pdf = 0.0;
  w = vec3(0.0);
  tri = 0u;
  uint count = min(casters.count.x, uint(CAUSTICA_MAX_CASTERS));
  if (count == 0u) return false;
  vec4 sphere = casters.sphere[min(uint(uCaster * float(count)), count - 1u)];
  float pmf;
  if (!sampleLightTree(sphere.xyz, vec3(0.0), uSelect, tri, pmf)) return false;
  if (!sampleLightTriangle(sphere.xyz, tri, pmf, uTri, ls)) return false;
  vec3 axis;
  float omc;
  if (!casterCone(ls.p, ls.twoSided ? normalize(sphere.xyz - ls.p) : ls.n, sphere, axis, omc)) return false;
  w = sampleUniformCone(axis, omc, uDir);
  if (!(dot(w, ls.n) > 0.0 || ls.twoSided)) return false;
  if (!sampleLightTriangle(ls.p + w, tri, pmf, uTri, ls)) return false;  // the same point; its radiance along w
#ifdef CAUSTICA_INSTANCED
  pdf = ltEmissionPdf(instanceTriangle(tri, instanceXform(gLightInstance)), instanceXform(gLightInstance), ls.p,
                      ls.n, ls.twoSided, w);
#else
  pdf = ltEmissionPdf(tri, ls.p, ls.n, ls.twoSided, w);
#endif
  return pdf > 0.0;
}
