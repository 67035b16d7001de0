// light_trace.comp — the light tracer's entry shader: light subpaths leave emissive triangles towards the
// casters' bounding spheres, follow smooth and Lambertian bounces, and splat each Lambertian vertex the
// camera sees into its pixel (the family of lib/light_trace.glsl; docs/path-tracer.md, "Light tracing").
// One invocation per subpath: x and y count the subpaths of a sample index, z the sample index within
// the dispatch (frame.frame.z + z). The splats are 64-bit fixed-point sums made of 32-bit integer atomics, so
// they do not depend on the order subpaths run in. World space; radiance linear.
#define CAUSTICA_LIGHT_TRACE_PASS
#undef CAUSTICA_AOV          // no per-pixel features: the path tracer records them
#undef CAUSTICA_TRANSPARENT  // nor coverage
#undef CAUSTICA_MANIFOLD     // never compiled beside light tracing (shader_features.cpp)
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
#include "lib/environment.glsl"  // environmentPresent (path_scatter.glsl's sampleCasterMixture)
#endif
#if defined(CAUSTICA_PUNCTUAL) || defined(CAUSTICA_SPOT_EMITTERS)
#include "lib/punctual.glsl"
#endif
#include "lib/casters.glsl"
#ifdef CAUSTICA_GUIDING
#include "lib/caustic_cells.glsl"  // casters.glsl's guide cells (unused here, but declared)
#endif
#include "lib/vertex.glsl"

layout(local_size_x = 64) in;

#include "lib/surface.glsl"
#include "lib/path_state.glsl"
#include "lib/path_scatter.glsl"
#include "lib/light_trace.glsl"

layout(std430, binding = CAUSTICA_BINDING_LIGHT_SPLATS) buffer LightSplats { uint splatWords[]; };
layout(location = 0) uniform uint subpaths;  // light subpaths per sample index

// Adds radiance v to the splat of pixel px for slot `slot` (the sample index within the dispatch): each
// channel in steps of casters.params.w, rounded up or down at random (rng) so that the rounding adds no
// bias, as 64-bit fixed point (low word, then a carry into the high word).
void addSplat(uvec2 px, uint slot, vec3 v, inout uvec4 rng) {
  uint base = kLightSplatWords * ((slot * frame.frame.y + px.y) * frame.frame.x + px.x);
  vec3 x = v / casters.params.w;
  for (uint c = 0u; c < 3u; ++c) {
    float steps = min(x[c], 1.8e19);  // below 2^64
    float u = rand01(rng);
    if (!(steps > 0.0)) continue;
    float hiF = floor(steps * (1.0 / 4294967296.0));
    uint lo = uint(min(floor(steps - hiF * 4294967296.0 + u), 4294967295.0));
    uint hi = uint(hiF);
    uint old = atomicAdd(splatWords[base + c], lo);
    if (old + lo < old) ++hi;  // the low word wrapped
    if (hi != 0u) atomicAdd(splatWords[base + 3u + c], hi);
  }
}

// Splats Lambertian vertex sf (albedo `albedo`, reached by subpath s along s.dir) into the pixel the
// camera sees it in, if it sees it: the path is complete with the eye. The camera's importance for a box
// pixel of area A (on the image plane at distance 1; orthographic: in scene units) is 1 / (A cos^3)
// per steradian at the eye, so the vertex adds beta f (cos_s in / cos_g in) cos_g(eye) / (A cos^3 d^2)
// (orthographic: beta f (cos_s in / cos_g in) cos_g(eye) / A), over the subpaths of its sample index. The
// ratio of the shading to the geometric cosine on the light's side is the adjoint BSDF's correction
// (Veach 1997, 5.3).
void connectEye(PathState s, Surface sf, vec3 albedo, uint slot) {
  vec3 wi = -s.dir;  // towards the light
  float cosSi = dot(wi, sf.ns), cosGi = dot(wi, sf.ng);  // sf.ng, sf.ns: on the side s arrived from
  if (!(cosSi > 0.0) || !(cosGi > 0.0)) return;
  vec3 v = sf.p - frame.camPos.xyz;
  vec3 right = frame.camRight.xyz, up = frame.camUp.xyz, fwd = frame.camForward.xyz;
  float depth = dot(v, fwd);
  if (!(depth > 0.0)) return;
  bool ortho = frame.camForward.w > 0.0;
  float dist = ortho ? depth : length(v);
  vec3 toEye = ortho ? -fwd : -v / dist;
  vec2 ndc = vec2(dot(v, right) / dot(right, right), dot(v, up) / dot(up, up)) / (ortho ? 1.0 : depth);
  if (!(abs(ndc.x) < 1.0 && abs(ndc.y) < 1.0)) return;
  float cosEye = dot(toEye, sf.ng);
  if (!(cosEye > 0.0)) return;
  vec2 size = vec2(frame.frame.xy);
  uvec2 px = min(uvec2(vec2((ndc.x + 1.0) * 0.5, (1.0 - ndc.y) * 0.5) * size), frame.frame.xy - 1u);
  float pixelArea = 4.0 * length(right) * length(up) / (size.x * size.y);
  float cosCam = depth / dist;
  float importance = ortho ? 1.0 / pixelArea : 1.0 / (pixelArea * cosCam * cosCam * cosCam * dist * dist);
  ++gShadowRays;
  if (traceOccluded(offsetRayOrigin(sf.p, sf.pError, sf.ng), toEye, dist)) return;
  vec3 value = s.beta * s.filt * albedo * (INV_PI * cosSi / cosGi * cosEye * importance / float(subpaths));
  uvec4 rng = s.rng;  // the rounding's numbers: a copy, so the subpath goes on as without the splat
  addSplat(px, slot, value, rng);
}

// Where subpath s leaves (sampleLtEmission, lib/light_trace.glsl): its origin, direction and throughput
// Le cos / pdf. False when nothing leaves.
bool startSubpath(inout PathState s) {
  if (frame.options.z == 0u) return false;
  float uCaster = rand01(s.rng);
  float uSelect = rand01(s.rng);
  vec2 uTri = rand2(s.rng);
  vec2 uDir = rand2(s.rng);
  LightSample ls;
  uint tri;
  vec3 w;
  float pdf;
  if (!sampleLtEmission(uCaster, uSelect, uTri, uDir, ls, tri, w, pdf)) return false;
  vec3 le = ls.le;
#ifdef CAUSTICA_SPOT_EMITTERS
  le *= spotEmitterFactor(materialAt(ls.material), w);
#endif
  float side = dot(w, ls.n);
  s.beta = le * (abs(side) / pdf);
  s.org = offsetRayOrigin(ls.p, ls.pError, side > 0.0 ? ls.n : -ls.n);
  s.dir = w;
  return maxComponent(s.beta) > 0.0;
}

void main() {
  // Subpath index over a 2D grid of work groups (one dimension holds at most 65535 groups); z: the slot.
  uint index = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64u;
  uint slot = gl_GlobalInvocationID.z;
  if (index >= subpaths || slot >= frame.options.w) return;
  PathState s;
  s.rng = rngSeed(index, frame.frame.z + slot, frame.frame.w ^ 0x6c8e9cf5u);  // not the eye paths' streams
  s.etaScale = 1.0;
  s.radiance = vec3(0.0);
  s.filt = vec3(1.0);
  s.lambda = 0.0;
  s.prevPdf = 0.0;
  s.prevDelta = true;
  s.prevP = s.prevN = vec3(0.0);
  s.sigma = vec3(0.0);
  s.firstDiffuse = false;
  s.depth = 0u;
  s.passThroughs = 0u;
  s.ltFamily = true;
  bool started = startSubpath(s);
  float beta0 = maxComponent(s.beta);
  uint maxDepth = frame.options.x;
  // Segment `seg` reaches a vertex; splatting it makes a path of seg + 1 segments, within the depth cap
  // as the path tracer counts it.
  for (uint seg = 1u; started && seg < maxDepth; ++seg) {
    ++gSecondaryRays;
    Hit hit;
    if (!traceClosest(s.org, s.dir, 3.0e38, hit)) break;
#ifdef CAUSTICA_VOLUME
    s.beta *= exp(-s.sigma * hit.t);
#endif
    Surface sf;
    if (!surfaceAt(hit, s.dir, true, sf) || ltLayered(sf)) break;
    vec4 base = materialBaseColor(sf.m, sf.uv, sf.color);
#ifdef CAUSTICA_OPACITY
    if (base.a < 1.0 && rand01(s.rng) >= base.a) break;  // passes through: not the family's
#endif
    BounceLobe lobe = chooseBounceLobe(s, sf, base.rgb);
    vec3 newDir;
    if (isDiffuseLobe(lobe)) {
      if (seg == 1u) break;  // lit straight from the emitter: next-event estimation's, not a caustic
      connectEye(s, sf, lobe.color, slot);
      vec3 t, b;
      orthonormalBasis(sf.ns, t, b);
      vec3 local = sampleCosineHemisphere(rand2(s.rng));
      newDir = normalize(local.x * t + local.y * b + local.z * sf.ns);
      float cosSo = dot(newDir, sf.ns), cosGo = dot(newDir, sf.ng);
      float cosSi = dot(-s.dir, sf.ns), cosGi = dot(-s.dir, sf.ng);
      if (!(cosSo > 0.0) || !(cosGo > 0.0) || !(cosSi > 0.0) || !(cosGi > 0.0)) break;
      s.beta *= lobe.color * (cosSi * cosGo / (cosGi * cosSo));  // f cos / pdf with the adjoint correction
      s.prevDelta = false;
    } else if (!isGlossyLobe(lobe)) {  // mirror or smooth glass: as the path tracer scatters, reversed
      vec3 wo = -s.dir;
      float etaBefore = s.etaScale;
      bool inAir = s.sigma == vec3(0.0);
      scatterDelta(s, sf, lobe, newDir);
      if (gDeltaFellBack) break;  // the eye paths' fallback to the geometric normal has no reverse
      // scatterDelta weighs a refraction by 1 / eta^2, radiance's change of scale; a light subpath carries
      // importance, which refraction does not scale (Veach 1997, 5.2; pbrt's TransportMode::Importance):
      // undone. (Kept, an emitter in glass lit the focus 2.25x too dark; the same factor the other way
      // round, 2.25x too bright: "light tracing is unbiased: an emitter inside glass".)
      float etaSq = s.etaScale / etaBefore;
      s.beta *= etaSq;
#ifdef CAUSTICA_VOLUME
      // Leaving an absorbing medium it never entered: the subpath began inside it, where an eye path
      // would have been absorbed (path_emission.glsl leaves such paths to the eye paths).
      if (inAir && etaSq != 1.0 && !sf.front && (sf.m.tex.z & kMatHasVolume) != 0u) break;
#endif
      float den = abs(dot(wo, sf.ng)) * abs(dot(newDir, sf.ns));
      if (!(den > 0.0)) break;
      s.beta *= abs(dot(wo, sf.ns)) * abs(dot(newDir, sf.ng)) / den;  // the adjoint correction
    } else {
      break;  // a glossy lobe: not the family's
    }
    if (seg >= 3u) {  // Russian roulette on the throughput relative to where the subpath started
      float q = min(maxComponent(s.beta * s.filt) / beta0, 1.0);
      if (rand01(s.rng) >= q) break;
      s.beta /= q;
    }
    continuePath(s, sf, newDir);
  }
  if (gSecondaryRays > 0u) atomicAdd(counters.secondaryRays, gSecondaryRays);
  if (gShadowRays > 0u) atomicAdd(counters.shadowRays, gShadowRays);
}
