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
#if defined(CAUSTICA_CASTERS) || defined(CAUSTICA_MANIFOLD) || defined(CAUSTICA_LIGHT_TRACE)
#include "lib/casters.glsl"
#endif
#if defined(CAUSTICA_MANIFOLD) || defined(CAUSTICA_GUIDING)
#include "lib/caustic_cells.glsl"
#endif

#include "lib/vertex.glsl"
#include "lib/accumulate.glsl"
#ifdef CAUSTICA_TRANSPARENT
#include "lib/coverage.glsl"
#endif
#include "lib/adaptive.glsl"
#ifdef CAUSTICA_AOV
#include "lib/feature_buffers.glsl"
#endif

layout(local_size_x = CAUSTICA_WORKGROUP_X, local_size_y = CAUSTICA_WORKGROUP_Y) in;

#ifdef CAUSTICA_LIGHT_TRACE
layout(binding = CAUSTICA_TEXUNIT_LIGHT_SPLATS) uniform usamplerBuffer lightSplatTexels;  // rgb32ui: low words, high words

// The light tracer's estimate of pixel `pixel` for the k-th sample index of this dispatch: its
// fixed-point sums (gpu_layout.h, kLightSplatWords) in radiance.
vec3 lightSplat(uvec2 pixel, uint k) {
  int t = 2 * int((k * frame.frame.y + pixel.y) * frame.frame.x + pixel.x);
  uvec3 lo = texelFetch(lightSplatTexels, t).rgb, hi = texelFetch(lightSplatTexels, t + 1).rgb;
  return (vec3(hi) * 4294967296.0 + vec3(lo)) * casters.params.w;
}
#endif

#include "lib/surface.glsl"
#include "lib/path_state.glsl"
#ifdef CAUSTICA_LIGHT_TRACE
#include "lib/light_trace.glsl"
#endif
#ifdef CAUSTICA_ENV
#include "lib/environment_light.glsl"
#endif
#ifdef CAUSTICA_MANIFOLD
#include "lib/manifold.glsl"
#include "lib/path_manifold.glsl"
#endif
#include "lib/path_emission.glsl"
#include "lib/path_nee.glsl"
#include "lib/path_scatter.glsl"

// One bounce of the path: traces its ray, adds what it finds to s.radiance and samples the next
// direction. Returns false when the path has ended (escaped, absorbed, lost or ended by roulette);
// the caller also ends it at the depth cap (frame.options.x).
bool pathBounce(inout PathState s) {
  if (s.depth + s.passThroughs > 0u) ++gSecondaryRays;
  Hit hit;
  if (!traceClosest(s.org, s.dir, 3.0e38, hit)) {
    addEscaped(s);  // path_emission.glsl: the environment
#ifdef CAUSTICA_AOV
    featuresRecord(s.feat, vec3(1.0), vec3(0.0), true);  // the sky: no surface (feature_buffers.glsl)
#endif
    return false;
  }
#ifdef CAUSTICA_AOV
  featuresTravel(s.feat, hit.t);
#endif
#ifdef CAUSTICA_VOLUME
  s.beta *= exp(-s.sigma * hit.t);  // absorbed along the segment
#endif
  Surface sf;
  if (!surfaceAt(hit, s.dir, true, sf)) return false;  // surface.glsl
  vec4 base = materialBaseColor(sf.m, sf.uv, sf.color);
#ifdef CAUSTICA_OPACITY
  if (passThrough(s, sf, base.a)) return true;  // path_scatter.glsl: an alpha cut-out (absent: no emission either)
#endif
  addEmission(s, sf);                           // path_emission.glsl: with its MIS weight
  BounceLobe lobe = chooseBounceLobe(s, sf, base.rgb);  // path_scatter.glsl
  bool nonDelta = isDiffuseLobe(lobe) || isGlossyLobe(lobe);
#ifdef CAUSTICA_LIGHT_TRACE
  // The light tracer's family: a Lambertian first vertex, then Lambertian or smooth ones (light_trace.glsl).
  // A later Lambertian vertex needs the direction back along the path above its shading normal: the light
  // subpath samples that direction about it.
  s.ltFamily = s.ltFamily && (s.depth == 0u ? isDiffuseLobe(lobe) : !isGlossyLobe(lobe)) && !ltLayered(sf) &&
               (s.depth == 0u || !isDiffuseLobe(lobe) || dot(-s.dir, sf.ns) > 0.0);
#endif
#ifdef CAUSTICA_AOV
  // The first non-specular hit, or an emitter (albedo 1: its radiance is not divided by a colour).
  if (surfaceEmits(sf) || nonDelta)
    featuresRecord(s.feat, surfaceEmits(sf) ? vec3(1.0) : lobe.color, sf.ns, false);
#endif
#ifdef CAUSTICA_MANIFOLD
  bool firstDiffuse = s.firstDiffuse;  // sampleCasterMixture clears it
#endif
  vec3 newDir;
  Vertex v;
  if (nonDelta) {
#ifdef CAUSTICA_CASTERS
    if (isDiffuseLobe(lobe)) newDir = sampleCasterMixture(s, sf);  // its numbers before the lights'
#endif
    v = lobeVertex(s, sf, lobe);
    addDirectLight(s, v, isDiffuseLobe(lobe));  // path_nee.glsl: next-event estimation
  }
#ifdef CAUSTICA_MANIFOLD
  bool atX = addManifoldLight(s, sf, isDiffuseLobe(lobe), firstDiffuse, v);  // path_manifold.glsl: light through a caster, or the weight of a bounce's
#endif
  if (nonDelta) {
    if (!scatterNonDelta(s, sf, v, lobe, newDir)) return false;
  } else {
    scatterDelta(s, sf, lobe, newDir);  // mirror, smooth glass
#ifdef CAUSTICA_LIGHT_TRACE
    if (gDeltaFellBack) s.ltFamily = false;  // not the reverse of a light subpath's event
#endif
  }
#ifdef CAUSTICA_MANIFOLD
  trackCasterChain(s, sf, lobe.lobe, newDir, atX);
#endif
  if (!russianRoulette(s)) return false;  // path_state.glsl
  continuePath(s, sf, newDir);
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
#ifdef CAUSTICA_AOV
    FeatureSums features = loadFeatureSums(ivec2(pixel));  // feature_buffers.glsl
#endif
#ifdef CAUSTICA_TRANSPARENT
    float covered = loadCoverage(ivec2(pixel));  // coverage.glsl
#endif
    uint k = 0u;
    PathState path = startPath(pixel, frame.frame.z);
    while (true) {
      if (path.depth < maxDepth && pathBounce(path)) continue;
      vec3 l = path.radiance;
#ifdef CAUSTICA_LIGHT_TRACE
      l += lightSplat(pixel, k);  // the light tracer's paths of this sample index (light_trace.comp)
#endif
      bool finite = !(any(isnan(l)) || any(isinf(l)));
      if (!finite) ++bad;  // counted and reported; not part of the pixel's mean (neither as black)
      addSample(sums, finite ? l : vec3(0.0), finite ? 1.0 : 0.0);
#ifdef CAUSTICA_AOV
      if (finite) addFeatureSample(features, path.feat, l);
#endif
#ifdef CAUSTICA_TRANSPARENT
      covered += finite && !gCameraRayMissed ? 1.0 : 0.0;
#endif
      if (++k == samples) break;
      path = startPath(pixel, frame.frame.z + k);
    }
    primary = samples;
    storePixelSums(ivec2(pixel), sums);
#ifdef CAUSTICA_AOV
    storeFeatureSums(ivec2(pixel), features);
#endif
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
