// path_emission.glsl — what a path tracer's ray finds by itself: the environment when it leaves the
// scene, the emission of the surface it hits, each weighted against the light sampling that could
// have found it (MIS). Needs path_state.glsl, surface.glsl, lights.glsl (environment_light.glsl with CAUSTICA_ENV).

// The ray of s left the scene: the environment's radiance it carries (environment_light.glsl).
void addEscaped(inout PathState s) {
#ifdef CAUSTICA_TRANSPARENT
  if (s.depth == 0u) gCameraRayMissed = true;  // alpha 0 for this sample (coverage.glsl)
#endif
#ifdef CAUSTICA_ENV
  s.radiance += s.beta * s.filt * escapedRadiance(s.dir, s.depth == 0u, s.prevDelta, s.prevPdf);
#endif
}

// Emission of the surface the ray of s hit, weighted against light sampling when the last bounce
// could have sampled it (a non-delta vertex; power heuristic with the light tree's solid-angle pdf
// from that vertex).
void addEmission(inout PathState s, Surface sf) {
  if (surfaceEmits(sf)) {
    float w = 1.0;
#ifdef CAUSTICA_SPOT_EMITTERS
    w *= spotEmitterFactor(sf.m, -s.dir);  // a --light-radius sphere of a spot light emits into its cone
#endif
#if defined(CAUSTICA_MIS) && !defined(CAUSTICA_NO_EMITTERS)
    if (!s.prevDelta) {
#ifdef CAUSTICA_INSTANCED
      float pdfArea = instanceLightPdfArea(sf.g, sf.xf, s.prevP, s.prevN);
#else
      float pdfArea = lightPdfArea(sf.tri, s.prevP, s.prevN);
#endif
      float pdfLight = pdfArea * sf.t * sf.t / max(abs(dot(sf.ngFront, s.dir)), 1.0e-12);
      w *= powerHeuristic(s.prevPdf, pdfLight);
    }
#endif
#ifdef CAUSTICA_LIGHT_TRACE
    // A path of the light tracer's family: its light subpaths add it (light_trace.glsl), not this one.
    // (An emitter reached inside an absorbing medium is not: light subpaths start with none.)
    if (s.ltFamily && s.prevDelta && s.depth >= 2u && s.sigma == vec3(0.0)) {
      bool twoSided = (sf.m.tex.z & kMatDoubleSided) != 0u;
#ifdef CAUSTICA_INSTANCED
      if (ltEmissionPdf(sf.g, sf.xf, sf.p, sf.ngFront, twoSided, -s.dir) > 0.0) return;
#else
      if (ltEmissionPdf(sf.tri, sf.p, sf.ngFront, twoSided, -s.dir) > 0.0) return;
#endif
    }
#endif
    vec3 le = s.beta * s.filt * materialEmissionSeen(sf.m, sf.uv, dot(sf.ngFront, s.dir)) * w;
#ifdef CAUSTICA_MANIFOLD
    gManifoldCheck = manifoldChainEnds(s);  // a caster chain from x ends here: weighed after the solve
    if (gManifoldCheck) {
      gManifoldDeferred = le;
      return;
    }
#endif
    s.radiance += le;
  }
}
