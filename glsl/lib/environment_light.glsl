// environment_light.glsl — the environment as a light in the path tracer: radiance of rays that leave
// the scene (MIS-weighted against environment sampling after a non-delta bounce; the background for
// camera rays) and next-event estimation towards the environment. Needs environment.glsl, traverse.glsl,
// spawn.glsl, vertex.glsl. Radiance linear; directions unit world space; pdfs per steradian.

// Radiance carried by a ray in direction dir that hit nothing. cameraRay: straight from the camera
// (the background decides); prevDelta: the last bounce was specular or the camera (full weight);
// prevPdf: solid-angle pdf of the BSDF sample that chose dir (for the MIS weight).
vec3 escapedRadiance(vec3 dir, bool cameraRay, bool prevDelta, float prevPdf) {
  if (cameraRay && environment.size.z != kBackgroundEnvironment)
    return environment.size.z == kBackgroundColor ? environment.background.rgb : vec3(0.0);
  if (!environmentPresent()) return vec3(0.0);
  vec3 le = environmentRadiance(dir);
#ifdef CAUSTICA_MIS
  if (!prevDelta) return le * powerHeuristic(prevPdf, environmentPdf(dir));
#endif
  return le;
}

// A direction towards the environment, drawn by importance, that reaches it unoccluded from p.
struct EnvLightSample {
  vec3 wi;    // unit direction towards the environment
  vec3 le;    // radiance arriving from wi
  float pdf;  // per steradian
};

// Draws a direction from the environment's distribution (u uniform in [0,1)^2). False if nothing
// was drawn or the direction lies below the geometric normal ng of the surface at p.
bool sampleEnvironmentLight(vec3 ng, vec2 u, out EnvLightSample es) {
  es.wi = vec3(0.0, 1.0, 0.0);
  es.le = vec3(0.0);
  es.pdf = 0.0;
  if (!environmentPresent()) return false;
  if (!sampleEnvironment(u, es.wi, es.le, es.pdf)) return false;
  return es.pdf > 0.0 && dot(ng, es.wi) > 0.0;
}

// Whether the ray from p (moved off its surface along ng past its error bound) towards wi leaves
// the scene.
bool environmentVisible(vec3 p, vec3 pError, vec3 ng, vec3 wi) {
  ++gShadowRays;
  return !traceOccluded(offsetRayOrigin(p, pError, ng), wi, 3.0e38);
}

// Next-event estimate of the environment at a non-delta vertex v (vertex.glsl: any lobe, reflection or
// transmission), MIS-weighted against the vertex's own sampling (vertexPdf). Returns radiance before
// the path throughput; u uniform in [0,1)^2.
vec3 addEnvironmentLight(Vertex v, vec2 u) {
  EnvLightSample es;
  if (!environmentPresent() || !sampleEnvironment(u, es.wi, es.le, es.pdf) || !(es.pdf > 0.0)) return vec3(0.0);
  float pdfVertex;
  vec3 f = vertexEvalPdf(v, es.wi, pdfVertex);
  if (!(maxComponent(f) > 0.0)) return vec3(0.0);
  bool above = dot(v.ng, es.wi) > 0.0;  // transmission lobes reach the sky through the surface
  if (!environmentVisible(v.p, v.pError, above ? v.ng : -v.ng, es.wi)) return vec3(0.0);
  float w = powerHeuristic(es.pdf, pdfVertex);
  return f * (w / es.pdf) * es.le;
}
