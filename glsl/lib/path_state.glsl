// path_state.glsl — one path sample of the path tracer between bounces (PathState), how it starts at
// the camera, how Russian roulette ends it and how it moves on to its next vertex. World space;
// radiance linear, per RGB channel. Needs rng.glsl, camera.glsl, spawn.glsl, surface.glsl
// (coverage.glsl when transparent).

uint gSecondaryRays = 0u;  // rays traced after the camera rays (this invocation)
uint gShadowRays = 0u;     // visibility rays of the next-event estimates
const uint kMaxPassThroughs = 256u;  // alpha pass-throughs a path may make beyond its bounces

struct PathState {
  vec3 org, dir;
  vec3 beta;           // path throughput
  float etaScale;      // product of eta^2 over refractions: beta * etaScale is free of radiance scaling
  vec3 radiance;       // estimate so far
  vec3 filt;           // per-channel weight of the wavelength(s) the path carries (dispersion)
  float lambda;        // nm; 0 while the path still carries every wavelength
  float prevPdf;       // solid-angle pdf of the last BSDF sample (non-delta lobes)
  bool prevDelta;      // last direction came from the camera or a delta lobe: no MIS on emitter hits
  vec3 prevP, prevN;   // last vertex's point and shading normal (light-tree pdf for MIS)
  vec3 sigma;          // absorption coefficient of the medium the ray travels in (per scene unit)
  bool firstDiffuse;   // no diffuse vertex yet on this path
#ifdef CAUSTICA_LIGHT_TRACE
  bool ltFamily;       // every vertex so far may belong to the light tracer's family (light_trace.glsl)
#endif
  uint depth;          // bounces so far (path segments traced, alpha pass-throughs not counted)
  uint passThroughs;   // alpha pass-throughs: not bounces, so they do not consume the depth cap
  uvec4 rng;
#ifdef CAUSTICA_MANIFOLD
  // The first diffuse vertex x from which casters were usable, and what followed it (path_manifold.glsl).
  uint chain;          // kChain* bits
  vec3 mx, mxN;        // x and its shading normal
  vec3 mxOrg;          // origin of rays leaving x on the side of its geometric normal
  vec3 mxSigma;        // absorption coefficient of the medium around x
  vec3 mxDir;          // the direction the path took from x, and its solid-angle pdf
  float mxPdf;
#endif
#ifdef CAUSTICA_AOV
  SampleFeatures feat;  // the denoiser's features of this sample (feature_buffers.glsl)
#endif
};

// Sample `sampleIndex` (global) of the pixel: its random stream, keyed by (pixel, sample index, seed),
// and its camera ray.
PathState startPath(uvec2 pixel, uint sampleIndex) {
  PathState s;
  s.rng = rngSeed(pixel.y * frame.frame.x + pixel.x, sampleIndex, frame.frame.w);
  eyeRay(pixel, rand2(s.rng), s.org, s.dir);
  s.beta = vec3(1.0);
  s.etaScale = 1.0;
  s.radiance = vec3(0.0);
  s.filt = vec3(1.0);
  s.lambda = 0.0;
  s.prevPdf = 0.0;
  s.prevDelta = true;
  s.prevP = vec3(0.0);
  s.prevN = vec3(0.0);
  s.sigma = vec3(0.0);
  s.firstDiffuse = true;
#ifdef CAUSTICA_LIGHT_TRACE
  s.ltFamily = true;
#endif
  s.depth = 0u;
  s.passThroughs = 0u;
#ifdef CAUSTICA_MANIFOLD
  s.chain = 0u;
  s.mx = s.mxN = s.mxOrg = s.mxSigma = s.mxDir = vec3(0.0);
  s.mxPdf = 0.0;
#endif
#ifdef CAUSTICA_AOV
  s.feat = noFeatures();
#endif
#ifdef CAUSTICA_TRANSPARENT
  gCameraRayMissed = false;
#endif
  return s;
}

// Whether the vertex now being shaded may start a ray that will still be traced (the depth cap,
// frame.options.x): light sampling and caster aiming happen only there, so that the BSDF-sampled ray
// competing with them in MIS exists and both estimators end alike.
bool nextRayTraced(PathState s) { return s.depth + 1u < frame.options.x; }

// Russian roulette after a few bounces, on the throughput without the eta^2 radiance scaling
// (inside glass that factor is not an energy loss and must not end paths; pbrt-v4 does the same),
// times the dispersion filter: after a dispersive event the path carries s.filt (3 in one channel,
// or the hero wavelength's sensitivity / pdf), and ignoring it ended those paths up to 3x too
// often (cornell-dispersion 64x64: 1.3-2.1x the efficiency; docs/path-tracer.md, "Chromatic aberration").
// False: the path ends.
bool russianRoulette(inout PathState s) {
  if (s.depth >= 3u) {
    float q = min(maxComponent(s.beta * s.filt) * s.etaScale, 1.0);
    if (rand01(s.rng) >= q) return false;
    s.beta /= q;
  }
  return true;
}

// The path leaves surface sf along unit direction dir: its next segment, one bounce more.
void continuePath(inout PathState s, Surface sf, vec3 dir) {
  s.dir = dir;
  s.org = offsetRayOrigin(sf.p, sf.pError, dot(s.dir, sf.ng) > 0.0 ? sf.ng : -sf.ng);
  s.prevP = sf.p;
  s.prevN = sf.ns;
  ++s.depth;
}
