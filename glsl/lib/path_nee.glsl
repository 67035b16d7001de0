// path_nee.glsl — next-event estimation at a path tracer's non-delta vertex: one sample of each light
// kind (emissive triangles, environment, punctual lights), each through the vertex's BSDF
// (vertexEval, vertex.glsl) and with its own shadow ray. Needs path_state.glsl, vertex.glsl
// (environment_light.glsl with CAUSTICA_ENV, punctual.glsl with CAUSTICA_PUNCTUAL).

#ifdef CAUSTICA_PUNCTUAL
// Punctual-light next-event estimate at a non-delta vertex v (punctual.glsl): its own shadow ray, no
// MIS (a delta light cannot be hit by a bounce); the BSDF through vertexEval, like every light kind.
vec3 addPunctualLight(Vertex v, float u) {
  vec3 wi, li;
  float dist;
  if (!samplePunctualLight(v.p, v.pError, v.ng, u, wi, li, dist, gShadowRays)) return vec3(0.0);
#ifdef CAUSTICA_VOLUME
  vec3 sigma = dot(v.ng, wi) > 0.0 ? v.sigmaAbove : v.sigmaBelow;  // the medium the shadow ray runs in
  if (any(greaterThan(sigma, vec3(0.0)))) li *= exp(-sigma * dist);
#endif
  return vertexEval(v, wi) * li;
}
#endif

// Adds to s.radiance the light that reaches vertex v directly (diffuse: v is a Lambertian vertex).
// The lights' random numbers are drawn in every shader variant, with the light kind or without: all
// variants then draw the same numbers for the same path, so the all-features shader renders the
// specialised shader's image to float rounding (a test compares). Light sampling only where the
// BSDF-sampled ray that competes with it in MIS will still be traced (nextRayTraced).
void addDirectLight(inout PathState s, Vertex v, bool diffuse) {
#ifdef CAUSTICA_MIS
  if (nextRayTraced(s)) s.radiance += s.beta * s.filt * sampleEmitterLight(v, s.rng, gShadowRays);
  vec2 uEnv = rand2(s.rng);
#ifdef CAUSTICA_ENV
  // The environment's own next-event estimate (an independent shadow ray; environment_light.glsl),
  // through this lobe (both sides for rough glass), matching the MIS weight escaped rays get after
  // this vertex. Not from a Lambertian vertex inside an absorbing medium: the ray could only leave
  // through its boundary.
  if (nextRayTraced(s) && (!diffuse || s.sigma == vec3(0.0)))
    s.radiance += s.beta * s.filt * addEnvironmentLight(v, uEnv);
#endif
#endif
  float uPunctual = rand01(s.rng);
#ifdef CAUSTICA_PUNCTUAL
  // Punctual lights: their own estimate, added to the emitters' (a sum of unbiased estimates);
  // in both integrators, since a bounce never finds a delta light.
  if (nextRayTraced(s)) s.radiance += s.beta * s.filt * addPunctualLight(v, uPunctual);
#endif
}
