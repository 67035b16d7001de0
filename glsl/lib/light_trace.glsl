// light_trace.glsl — what the light tracer (light_trace.comp) and the path tracer agree on: the family
// of paths the light tracer takes over and the density it leaves emitters with (docs/path-tracer.md,
// "Light tracing"). Needs casters.glsl, lights.glsl, surface.glsl, materials.glsl.
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
