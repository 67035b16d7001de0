// pathtrace.comp — the path tracer entry shader: one invocation per pixel tracing K samples of it in one
// flat bounce loop (path regeneration: a lane starts its next sample as soon as a path ends); eye rays
// bounce until they reach emitters (naive) or also sample lights (CAUSTICA_MIS).
// Radiance is linear; throughput is per RGB channel; wavelengths in nm.
#include "lib/bindings.glsl"
#include "lib/rng.glsl"
#include "lib/sampling.glsl"
#include "lib/spawn.glsl"
#include "lib/intersect.glsl"
#include "lib/traverse.glsl"
#include "lib/camera.glsl"
#include "lib/textures.glsl"
#include "lib/spectral.glsl"
#include "lib/microfacet.glsl"
#include "lib/materials.glsl"
#include "lib/lights.glsl"
#ifdef CAUSTICA_ENV
#include "lib/environment.glsl"
#endif
#if defined(CAUSTICA_PUNCTUAL) || defined(CAUSTICA_SPOT_EMITTERS)
#include "lib/punctual.glsl"
#endif
#ifdef CAUSTICA_CASTERS
#include "lib/casters.glsl"
#endif
#include "lib/vertex.glsl"
#include "lib/accumulate.glsl"
#ifdef CAUSTICA_TRANSPARENT
#include "lib/coverage.glsl"
#endif
#include "lib/adaptive.glsl"

layout(local_size_x = CAUSTICA_WORKGROUP_X, local_size_y = CAUSTICA_WORKGROUP_Y) in;

uint gSecondaryRays = 0u;
const uint kMaxPassThroughs = 256u;  // alpha pass-throughs a path may make beyond its bounces
uint gShadowRays = 0u;
#ifdef CAUSTICA_ENV
#include "lib/environment_light.glsl"
#endif

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

// The index of refraction of a glass hit for the wavelength the path carries (nm; 0 = all). The first
// dispersive event picks the path's wavelength (hero wavelength, or one RGB channel) and its filter.
float glassIor(Material m, inout float lambda, inout vec3 filt, inout uvec4 rng) {
  float ior = m.params.w;
#ifdef CAUSTICA_DISPERSION
  if ((m.tex.z & kMatDispersive) != 0u) {
    if (lambda == 0.0) {  // the path keeps one wavelength from its first dispersive event on
#ifdef CAUSTICA_SPECTRAL
      lambda = kLambdaMin + (kLambdaMax - kLambdaMin) * rand01(rng);
      filt = channelSensitivity(lambda) * (kLambdaMax - kLambdaMin);
#else
      int c = min(int(rand01(rng) * 3.0), 2);
      lambda = kChannelLambda[c];
      filt = vec3(0.0);
      filt[c] = 3.0;
#endif
    }
    ior = cauchyIor(ior, m.absorption.w, lambda);
  }
#endif
  return ior;
}

// The state of one path sample between bounces (world space; radiance linear, per RGB channel).
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
  uint depth;          // bounces so far (path segments traced, alpha pass-throughs not counted)
  uint passThroughs;   // alpha pass-throughs: not bounces, so they do not consume the depth cap
  uvec4 rng;
};

// Sample `sampleIndex` (global) of the pixel: its random stream, keyed by (pixel, sample index, seed),
// and its camera ray.
PathState startPath(uvec2 pixel, uint sampleIndex) {
  PathState s;
  s.rng = rngSeed(pixel.y * frame.frame.x + pixel.x, sampleIndex, frame.frame.w);
  s.org = frame.camPos.xyz;
  s.dir = eyeRayDirection(pixel, rand2(s.rng));
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
  s.depth = 0u;
  s.passThroughs = 0u;
#ifdef CAUSTICA_TRANSPARENT
  gCameraRayMissed = false;
#endif
  return s;
}

// One bounce of the path: traces its ray, adds what it finds to s.radiance and samples the next
// direction. Returns false when the path has ended (escaped, absorbed, lost or ended by roulette);
// the caller also ends it at the depth cap (frame.options.x).
bool pathBounce(inout PathState s) {
  uint maxDepth = frame.options.x;
  uint depth = s.depth;
  if (depth + s.passThroughs > 0u) ++gSecondaryRays;
  Hit hit;
  if (!traceClosest(s.org, s.dir, 3.0e38, hit)) {
#ifdef CAUSTICA_TRANSPARENT
    if (depth == 0u) gCameraRayMissed = true;  // alpha 0 for this sample (coverage.glsl)
#endif
#ifdef CAUSTICA_ENV
    s.radiance += s.beta * s.filt * escapedRadiance(s.dir, depth == 0u, s.prevDelta, s.prevPdf);  // environment_light.glsl
#endif
    return false;
  }
#ifdef CAUSTICA_VOLUME
  s.beta *= exp(-s.sigma * hit.t);
#endif
#ifdef CAUSTICA_INSTANCED
  InstanceXform xf = instanceXform(hit.inst);
  TriGeom g;
  vec3 sn0, sn1, sn2;
  vec2 st0, st1, st2;
  instanceHitTriangle(hit, xf, g, sn0, sn1, sn2, st0, st1, st2);  // instances.glsl: world space
#else
  TriGeom g = triGeomAt(hit.tri);
  vec3 sn0, sn1, sn2;
  vec2 st0, st1, st2;
  triNormals(hit.tri, sn0, sn1, sn2);  // tri_shade.glsl
  triUvs(hit.tri, st0, st1, st2);
#endif
  float b0 = 1.0 - hit.u - hit.v;
  vec3 p = b0 * g.v0.xyz + hit.u * g.v1.xyz + hit.v * g.v2.xyz;
  vec3 pError = hitPointError(b0, hit.u, hit.v, g.v0.xyz, g.v1.xyz, g.v2.xyz);  // spawn.glsl
#ifdef CAUSTICA_INSTANCED
  pError += instancePointError(g, xf);
#endif
  vec3 cr = cross(g.v1.xyz - g.v0.xyz, g.v2.xyz - g.v0.xyz);
  float crLen = length(cr);
  if (!(crLen > 0.0)) return false;
  vec3 ngFront = cr / crLen;              // geometric normal of the front (counter-clockwise) face
  bool front = dot(s.dir, ngFront) < 0.0;
  vec3 ng = front ? ngFront : -ngFront;   // geometric normal on the side the ray came from
  vec3 nsRaw = b0 * sn0 + hit.u * sn1 + hit.v * sn2;
  float nsLen = length(nsRaw);
  vec3 ns = nsLen > 1.0e-12 ? nsRaw / nsLen : ngFront;
  if (dot(ns, ngFront) < 0.0) ns = -ns;
  vec2 uv = b0 * st0 + hit.u * st1 + hit.v * st2;
  Material m = materialAt(floatBitsToUint(g.v0.w));
#ifdef CAUSTICA_TEXTURES
  ns = applyNormalMap(m, ns, uv, g.v0.xyz, g.v1.xyz, g.v2.xyz, st0, st1, st2);
#endif
  if (!front) ns = -ns;                   // shading normal on the side the ray came from

  // Emission, weighted against light sampling when the last bounce could have sampled it.
  if (isEmissive(m) && (front || (m.tex.z & kMatDoubleSided) != 0u)) {
    float w = 1.0;
#ifdef CAUSTICA_SPOT_EMITTERS
    w *= spotEmitterFactor(m, -s.dir);  // a --light-radius sphere of a spot light emits into its cone
#endif
#if defined(CAUSTICA_MIS) && !defined(CAUSTICA_NO_EMITTERS)
    if (!s.prevDelta) {
#ifdef CAUSTICA_INSTANCED
      float pdfLight = instanceLightPdfArea(g, xf, s.prevP, s.prevN) * hit.t * hit.t / max(abs(dot(ngFront, s.dir)), 1.0e-12);
#else
      float pdfLight = lightPdfArea(hit.tri, s.prevP, s.prevN) * hit.t * hit.t / max(abs(dot(ngFront, s.dir)), 1.0e-12);
#endif
      w *= powerHeuristic(s.prevPdf, pdfLight);
    }
#endif
    s.radiance += s.beta * s.filt * materialEmission(m, uv) * w;
  }

  vec4 base = materialBaseColor(m, uv);
#ifdef CAUSTICA_OPACITY
  if (base.a < 1.0 && rand01(s.rng) >= base.a) {  // pass straight through (a delta event)
    s.org = offsetRayOrigin(p, pError, -ng);
    s.prevDelta = true;
    if (s.passThroughs < kMaxPassThroughs) ++s.passThroughs;  // up to that many layers of cut-outs are free
    else ++s.depth;
    return true;
  }
#endif

  vec3 newDir;
  vec2 metalRough = materialMetalRough(m, uv);
  uint lobe = chooseLobe(m, metalRough.x, metalRough.y, rand01(s.rng));
  // llvmpipe runs both sides of every branch (masked) for all 8 lanes of a SIMD group, and a loop's
  // body at least once, so each call site of a light estimate or a traversal costs on every bounce
  // whichever lobe the lanes took. The non-delta lobes (Lambertian and GGX) therefore share one
  // vertex and one call of each next-event estimate; each lobe draws its random numbers in the same
  // order as before (its own ones first, then the lights', then its direction), so images are
  // unchanged (docs/benchmarks.md, "Session 5").
  bool diffuse = lobe == kLobeDiffuse;
#ifdef CAUSTICA_GGX
  bool glossy = lobe >= kLobeConductor;  // GGX lobes: rough metal, plastic, rough glass (microfacet.glsl)
#else
  const bool glossy = false;
#endif
#ifdef CAUSTICA_GLASS
  // Both glass lobes take the wavelength's index of refraction first (one call for the two lobes).
  float ior = 1.0;
  if (lobe == kLobeGlass || lobe == kLobeRoughGlass) ior = glassIor(m, s.lambda, s.filt, s.rng);
#endif
  if (diffuse || glossy) {
    float eta = 1.0;            // GGX: n beyond the surface / n on the ray's side (rough glass only)
    vec3 sigmaBelow = s.sigma;  // the medium beyond the surface
#ifdef CAUSTICA_CASTERS
    if (diffuse) {
      // Cosine sampling mixed with directions aimed at glass and mirror objects (casters.glsl): more
      // paths reach the caustics they focus; the mixture pdf keeps the estimate unbiased and enters MIS.
      // Only at the path's first diffuse vertex (the caustics the camera sees; deeper vertices gain
      // less than they cost, docs/path-tracer.md), and not at the last vertex the depth limit allows.
      float uChoose = rand01(s.rng);
      if (s.firstDiffuse && depth + 1u < maxDepth) prepareCasters(p, ns, uChoose);
      else gCasterUsable = 0u;
      s.firstDiffuse = false;
      float uPick = rand01(s.rng);
      newDir = sampleDiffuseDirection(ns, uPick, rand2(s.rng));
    }
#endif
#if defined(CAUSTICA_GGX) && defined(CAUSTICA_GLASS)
    if (lobe == kLobeRoughGlass) {
      eta = front ? ior : 1.0 / ior;
#ifdef CAUSTICA_VOLUME
      sigmaBelow = (front && (m.tex.z & kMatHasVolume) != 0u) ? m.absorption.rgb : vec3(0.0);
#endif
    }
#endif
#if defined(CAUSTICA_MIS) || defined(CAUSTICA_PUNCTUAL) || defined(CAUSTICA_GGX)
    // The vertex as every light estimate below sees it (vertex.glsl), built once: the Lambertian lobe
    // (roughness and eta 1) or the GGX lobe.
    // Without GGX the lobe here is the Lambertian one: said as a constant, so that the GGX code of
    // vertexEval / vertexPdf (bsdfEvalPdf) folds away instead of running masked on every bounce.
#ifdef CAUSTICA_GGX
    uint vertexLobe = lobe;
#else
    const uint vertexLobe = kLobeDiffuse;
#endif
    Vertex v = makeVertex(makeBsdf(m, vertexLobe, base.rgb, diffuse ? 1.0 : metalRough.y, eta), p, pError, ng, ns,
                          s.dir, s.sigma, sigmaBelow);
#endif
#ifdef CAUSTICA_MIS
    // Light sampling only where the BSDF-sampled ray that competes with it in MIS will still be
    // traced (not at the last vertex the depth limit allows), so both estimators end alike.
    if (depth + 1u < maxDepth) s.radiance += s.beta * s.filt * sampleEmitterLight(v, s.rng, gShadowRays);
    // The environment's and the punctual lights' numbers are drawn in every shader variant, with the
    // feature or without: all variants then draw the same random numbers for the same path, so the
    // all-features shader renders the specialised shader's image to float rounding (a test compares).
    vec2 uEnv = rand2(s.rng);
#ifdef CAUSTICA_ENV
    // The environment's own next-event estimate (an independent shadow ray; environment_light.glsl),
    // through this lobe (both sides for rough glass), matching the MIS weight escaped rays get after
    // this vertex. Not from a Lambertian vertex inside an absorbing medium: the ray could only leave
    // through its boundary.
    if (depth + 1u < maxDepth && (!diffuse || s.sigma == vec3(0.0)))
      s.radiance += s.beta * s.filt * addEnvironmentLight(v, uEnv);
#endif
#endif
    float uPunctual = rand01(s.rng);
#ifdef CAUSTICA_PUNCTUAL
    // Punctual lights: their own estimate, added to the emitters' (a sum of unbiased estimates);
    // in both integrators, since a bounce never finds a delta light.
    if (depth + 1u < maxDepth) s.radiance += s.beta * s.filt * addPunctualLight(v, uPunctual);
#endif
    if (diffuse) {
#ifdef CAUSTICA_CASTERS
      float cosOut = dot(newDir, ns);
      if (dot(newDir, ng) <= 0.0 || cosOut <= 0.0) return false;  // below the true surface: absorbed
      float pdfDir = diffuseDirectionPdf(ns, newDir);
      s.beta *= base.rgb * (cosOut * INV_PI / pdfDir);
      s.prevPdf = pdfDir;
#else
#if defined(CAUSTICA_MIS) || defined(CAUSTICA_PUNCTUAL) || defined(CAUSTICA_GGX)
      vec3 t = v.t, b = v.b;  // makeVertex's basis about the same ns: not computed twice
#else
      vec3 t, b;
      orthonormalBasis(ns, t, b);
#endif
      vec3 local = sampleCosineHemisphere(rand2(s.rng));
      newDir = normalize(local.x * t + local.y * b + local.z * ns);
      float cosOut = dot(newDir, ns);
      if (dot(newDir, ng) <= 0.0 || cosOut <= 0.0) return false;  // below the true surface: absorbed
      s.beta *= base.rgb;
      s.prevPdf = cosOut * INV_PI;
#endif
      s.prevDelta = false;
    }
#ifdef CAUSTICA_GGX
    else {
      BsdfSample bs;
      float uPart = rand01(s.rng);
      if (!bsdfSample(v.bsdf, v.wo, vec3(uPart, rand2(s.rng)), bs)) return false;
      newDir = vertexToWorld(v, bs.wi);
      if (bs.transmitted ? dot(newDir, ng) >= 0.0 : dot(newDir, ng) <= 0.0) return false;  // through the true surface: lost
      s.beta *= bs.weight;
      s.prevPdf = bs.pdf;
      s.prevDelta = false;
      if (bs.transmitted) {
        s.etaScale *= eta * eta;
        s.sigma = sigmaBelow;
      }
    }
#endif
  }
#ifdef CAUSTICA_MIRROR
  else if (lobe == kLobeMirror) {
    newDir = reflect(s.dir, ns);
    if (dot(newDir, ng) <= 0.0) newDir = reflect(s.dir, ng);
    s.beta *= base.rgb;
    s.prevDelta = true;
  }
#endif
#ifdef CAUSTICA_GLASS
  else {
    float eta = front ? ior : 1.0 / ior;  // n_transmitted / n_incident
    bool transmitted;
    float u = rand01(s.rng);
    float weight = sampleDielectric(s.dir, ns, eta, u, newDir, transmitted);
    if (transmitted ? dot(newDir, ng) >= 0.0 : dot(newDir, ng) <= 0.0)  // shading normal misled: use ng
      weight = sampleDielectric(s.dir, ng, eta, u, newDir, transmitted);
    s.beta *= weight;
    if (transmitted) {
      s.beta *= base.rgb;  // KHR_materials_transmission: transmitted light is tinted by the base colour
      s.etaScale *= eta * eta;
    }
#ifdef CAUSTICA_VOLUME
    if (transmitted) s.sigma = (front && (m.tex.z & kMatHasVolume) != 0u) ? m.absorption.rgb : vec3(0.0);
#endif
    s.prevDelta = true;
  }
#endif

  // Russian roulette after a few bounces, on the throughput without the eta^2 radiance scaling
  // (inside glass that factor is not an energy loss and must not end paths; pbrt-v4 does the same),
  // times the dispersion filter: after a dispersive event the path carries s.filt (3 in one channel,
  // or the hero wavelength's sensitivity / pdf), and ignoring it ended those paths up to 3x too
  // often (cornell-dispersion 64x64: 1.3-2.1x the efficiency; docs/benchmarks.md).
  if (depth >= 3u) {
    float q = min(maxComponent(s.beta * s.filt) * s.etaScale, 1.0);
    if (rand01(s.rng) >= q) return false;
    s.beta /= q;
  }
  s.dir = newDir;
  s.org = offsetRayOrigin(p, pError, dot(s.dir, ng) > 0.0 ? ng : -ng);
  s.prevP = p;
  s.prevN = ns;
  ++s.depth;
  return true;
}

void main() {
  uvec2 pixel;
  bool valid = dispatchedPixel(pixel);  // adaptive.glsl: rows of frame.tile, or a live tile
  // K = frame.options.w samples of the pixel, sample indices frame.frame.z .. + K - 1, in one flat
  // loop of bounces: when a path ends its lane starts the next sample at once, so a long path holds
  // its SIMD neighbours only until their own K samples are done, not once per sample. Mesa's llvmpipe
  // caps a shader's loop iterations (65535 in all, then silently leaves the loops): the host chooses
  // K so that K * (depth cap + alpha pass-throughs) stays within the bound measured safe
  // (Renderer::samplesPerDispatch). Samples are accumulated in the order of their indices, exactly as
  // K dispatches of one sample would add them, so the image does not depend on K.
  uint primary = 0u, bad = 0u;
  if (valid) {
    uint samples = max(frame.options.w, 1u);
    uint maxDepth = frame.options.x;
    PixelSums sums = loadPixelSums(ivec2(pixel));  // accumulate.glsl
#ifdef CAUSTICA_TRANSPARENT
    float covered = loadCoverage(ivec2(pixel));  // coverage.glsl
#endif
    uint k = 0u;
    PathState path = startPath(pixel, frame.frame.z);
    while (true) {
      if (path.depth < maxDepth && pathBounce(path)) continue;
      vec3 l = path.radiance;
      bool finite = !(any(isnan(l)) || any(isinf(l)));
      if (!finite) ++bad;  // counted and reported; not part of the pixel's mean (neither as black)
      addSample(sums, finite ? l : vec3(0.0), finite ? 1.0 : 0.0);
#ifdef CAUSTICA_TRANSPARENT
      covered += finite && !gCameraRayMissed ? 1.0 : 0.0;
#endif
      if (++k == samples) break;
      path = startPath(pixel, frame.frame.z + k);
    }
    primary = samples;
    storePixelSums(ivec2(pixel), sums);
#ifdef CAUSTICA_TRANSPARENT
    storeCoverage(ivec2(pixel), covered);
#endif
  }
  // Ray and sample counts straight into the counters, one atomic per non-zero count: a reduction in
  // shared memory needs barrier(), which made the whole shader 9-13 % slower on llvmpipe
  // (docs/benchmarks.md, "Path regeneration").
  if (primary > 0u) atomicAdd(counters.primaryRays, primary);
  if (gSecondaryRays > 0u) atomicAdd(counters.secondaryRays, gSecondaryRays);
  if (gShadowRays > 0u) atomicAdd(counters.shadowRays, gShadowRays);
  if (bad > 0u) atomicAdd(counters.nonFinite, bad);
}
