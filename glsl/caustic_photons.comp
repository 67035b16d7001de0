// caustic_photons.comp — the caustic photon passes: photons leave the emitters towards each caster,
// follow its specular chain (manifold NEE's table: a glass caster in and out, a mirror caster one
// reflection; caster guiding's: any chain of smooth events) and land on a diffuse surface, where each
// adds itself and its direction back towards the last event to its cell of the table (caustic_cells.glsl).
// Integer atomics only, and a key's slot is found by compare-and-swap in a fixed order of 8 slots, so the
// table holds the same cells and sums whatever order the photons run in, as long as no photon is dropped
// (app/gpu/caustic_cells.h).
#define CAUSTICA_PHOTON_PASS
#include "lib/bindings.glsl"
#include "lib/rng.glsl"
#include "lib/sampling.glsl"
#include "lib/spawn.glsl"
#include "lib/intersect.glsl"
#include "lib/traverse.glsl"
#include "lib/textures.glsl"
#include "lib/spectral.glsl"
#include "lib/microfacet.glsl"
#include "lib/materials.glsl"
#include "lib/lights.glsl"
#include "lib/casters.glsl"
#include "lib/surface.glsl"
#include "lib/caustic_cells.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = CAUSTICA_BINDING_CELL_KEYS) buffer CellKeys { uint keyWords[]; };  // 4 per bucket
layout(std430, binding = CAUSTICA_BINDING_CELLS) buffer Cells { uint cellWords[]; };         // 4 per slot
layout(std430, binding = CAUSTICA_BINDING_CELL_DROPS) buffer CellDrops { uint drops; };      // photons without a slot

// Per caster, `emitterEntries` entries (cumulative probability as float bits, light-tree leaf) in an order
// that does not depend on the scene's scale or place (photonEmitterTable, caustic_cells.h).
layout(std430, binding = CAUSTICA_BINDING_PHOTON_EMITTERS) readonly buffer PhotonEmitters { uvec2 photonEmitters[]; };

layout(location = 0) uniform uint photons;         // photons per caster (gl_GlobalInvocationID.x below it)
layout(location = 1) uniform uint emitterEntries;  // entries per caster of photonEmitters; 0: the light tree chooses
layout(location = 2) uniform uint table;           // kTableManifold or kTableGuide: which table the pass fills

const uint kTableManifold = 0u;  // manifold NEE's: photons follow their caster's own chain exactly
const uint kTableGuide = 1u;     // caster guiding's: photons follow any chain of smooth events (Fresnel-sampled)
const uint kMaxGuideEvents = 8u; // smooth events a guide photon may make before it is dropped

// A point on the emitter photon `u` of caster `caster` leaves from: the first entry of the caster's
// table whose cumulative probability exceeds u (binary search), else (no table) the light tree's choice
// from the caster's centre.
bool samplePhotonEmitter(uint caster, vec3 centre, float u, vec2 uTri, out LightSample ls) {
  if (emitterEntries == 0u) return sampleLight(centre, vec3(0.0), u, uTri, ls);
  if (frame.options.z == 0u) return false;
  uint first = caster * emitterEntries, end = first + emitterEntries, len = emitterEntries;
  while (len > 0u) {
    uint step = len / 2u;
    if (uintBitsToFloat(photonEmitters[first + step].x) <= u) {
      first += step + 1u;
      len -= step + 1u;
    } else {
      len = step;
    }
  }
  if (first >= end) return false;
  uvec4 link = lightNodeLink(photonEmitters[first].y);
#ifdef CAUSTICA_INSTANCED
  gLightInstance = link.y >> kLightNodeInstanceShift;
#endif
  return sampleLightTriangle(centre, link.x, 1.0, uTri, ls);
}

// Where photon rng leaves for caster `caster`: a point on an emitter (samplePhotonEmitter; `from`) and a
// uniform direction in the cone of the caster's sphere (dir), its ray starting at org. False when the
// emitter faces away or the point lies inside the sphere.
bool launchPhoton(uint caster, inout uvec4 rng, out vec3 from, out vec3 org, out vec3 dir) {
  from = org = dir = vec3(0.0);
  vec4 sphere = casters.sphere[caster];
  LightSample ls;
  if (!samplePhotonEmitter(caster, sphere.xyz, rand01(rng), rand2(rng), ls)) return false;
  vec3 axis;
  float omc;
  vec3 facing = ls.twoSided ? normalize(sphere.xyz - ls.p) : ls.n;
  if (!casterCone(ls.p, facing, sphere, axis, omc)) return false;
  dir = sampleUniformCone(axis, omc, rand2(rng));
  float side = dot(dir, ls.n);
  if (!(side > 0.0 || ls.twoSided)) return false;
  from = ls.p;
  org = offsetRayOrigin(ls.p, ls.pError, side > 0.0 ? ls.n : -ls.n);
  return true;
}

// Follows photon `index` of caster `caster` from an emitter through the caster's chain to a diffuse
// surface: its landing point and the unit direction from there back to the chain's last vertex.
bool tracePhoton(uint caster, uint index, out vec3 landing, out vec3 back) {
  landing = back = vec3(0.0);
  uvec4 rng = rngSeed(index, caster, 0x9e3779b9u);
  vec4 sphere = casters.sphere[caster];
  vec3 last, org, dir;
  if (!launchPhoton(caster, rng, last, org, dir)) return false;
  bool refractive = (casters.count.y & (1u << caster)) != 0u;
  uint events = refractive ? 2u : 1u;
  for (uint k = 0u; k <= events; ++k) {
    Hit hit;
    if (!traceClosest(org, dir, 3.0e38, hit)) return false;
    Surface sf;
    if (!surfaceAt(hit, dir, false, sf)) return false;
    vec2 metalRough = materialMetalRough(sf.m, sf.uv);
    if (k == events) {  // the receiver: a surface with a Lambertian part
      if (!((1.0 - metalRough.x) * (1.0 - sf.m.params.z) > 0.0)) return false;
      landing = sf.p;
      back = normalize(last - sf.p);
      return true;
    }
    vec3 d = sf.p - sphere.xyz;
    bool isSmooth = metalRough.y * metalRough.y < kDeltaAlpha;
    if (dot(d, d) > sphere.w * sphere.w || !isSmooth) return false;
    vec3 next;
    if (refractive) {
      float eta = sf.front ? sf.m.params.w : 1.0 / sf.m.params.w;
      if (!((1.0 - metalRough.x) * sf.m.params.z > 0.0) || !refractDir(dir, sf.ns, 1.0 / eta, next) ||
          dot(next, sf.ng) >= 0.0)
        return false;
      org = offsetRayOrigin(sf.p, sf.pError, -sf.ng);
    } else {
      next = reflect(dir, sf.ns);
      if (!(metalRough.x > 0.0) || dot(next, sf.ng) <= 0.0) return false;
      org = offsetRayOrigin(sf.p, sf.pError, sf.ng);
    }
    dir = next;
    last = sf.p;
  }
  return false;
}

// Follows photon `index` of caster `caster` for the guide table: from an emitter towards the caster,
// then through smooth glass (reflection or refraction chosen by Fresnel) and mirror surfaces of any
// caster until it reaches a surface with a Lambertian part: its landing point, the unit direction from
// there back to its last smooth event, and the caster that event belongs to. Photons whose first hit
// is not on the caster, or that meet a rough or unowned specular surface, are dropped.
bool traceGuidePhoton(uint caster, uint index, out vec3 landing, out vec3 back, out uint last, out uint cls) {
  landing = back = vec3(0.0);
  last = caster;
  cls = 1u;
  bool refractive = (casters.count.y & (1u << caster)) != 0u;
  bool own = true;  // every event so far on the caster, refracted (glass) or reflected (mirror)
  uvec4 rng = rngSeed(index, caster, 0x7f4a7c15u);
  vec3 lastP, org, dir;
  if (!launchPhoton(caster, rng, lastP, org, dir)) return false;
  for (uint k = 0u; k <= kMaxGuideEvents; ++k) {
    Hit hit;
    if (!traceClosest(org, dir, 3.0e38, hit)) return false;
    Surface sf;
    if (!surfaceAt(hit, dir, false, sf)) return false;
    vec2 metalRough = materialMetalRough(sf.m, sf.uv);
    bool lambertian = (1.0 - metalRough.x) * (1.0 - sf.m.params.z) > 0.0;
    if (lambertian) {  // the receiver
      if (k == 0u) return false;  // direct light, not a caustic
      cls = own && k == (refractive ? 2u : 1u) ? 0u : 1u;
      landing = sf.p;
      back = normalize(lastP - sf.p);
      return true;
    }
    uint owner = casterOwning(sf.p);
    bool isSmooth = metalRough.y * metalRough.y < kDeltaAlpha;
    if (owner >= uint(CAUSTICA_MAX_CASTERS) || (k == 0u && owner != caster) || !isSmooth) return false;
    vec3 next;
    if (metalRough.x > 0.0) {  // a mirror (metal, no Lambertian part)
      next = reflect(dir, sf.ns);
      if (dot(next, sf.ng) <= 0.0) return false;
      own = own && owner == caster && !refractive;
    } else {                   // smooth glass
      float eta = sf.front ? sf.m.params.w : 1.0 / sf.m.params.w;
      bool transmitted;
      sampleDielectric(dir, sf.ns, eta, rand01(rng), next, transmitted);
      if (transmitted ? dot(next, sf.ng) >= 0.0 : dot(next, sf.ng) <= 0.0) return false;
      own = own && owner == caster && refractive && transmitted;
    }
    org = offsetRayOrigin(sf.p, sf.pError, dot(next, sf.ng) > 0.0 ? sf.ng : -sf.ng);
    dir = next;
    lastP = sf.p;
    last = owner;
  }
  return false;
}

void main() {
  uint index = gl_GlobalInvocationID.x, caster = gl_GlobalInvocationID.y;
  // Casters outside count.w (--manifold auto's choice) get no photons: no cells, so manifold NEE
  // never joins through them and a bounce through them keeps weight 1 (path_manifold.glsl).
  // The guide table: photons to the casters of guide.y (guideCasterMask).
  if (index >= photons || caster >= casters.count.x) return;
  if (((table == kTableManifold ? casters.count.w : casters.guide.y) & (1u << caster)) == 0u) return;
  vec3 landing, back;
  uint owner = caster, cls = 0u;
  if (!(table == kTableGuide ? traceGuidePhoton(caster, index, landing, back, owner, cls)
                             : tracePhoton(caster, index, landing, back)))
    return;
  uint key = table == kTableGuide ? guideCellKey(owner, cls, landing) : casterCellKey(owner, landing);
  if (key == 0u) return;
  uint mask = table == kTableGuide ? casters.guide.x : casters.count.z;
  // The key's slot: the first of its 8 slots (first bucket, then second) that holds it or was empty. A
  // slot once keyed keeps its key, so every photon of a cell finds the same slot.
  uvec2 b = cellBuckets(key) & mask;
  int slot = -1;
  for (uint j = 0u; j < 8u && slot < 0; ++j) {
    uint s = 4u * (j < 4u ? b.x : b.y) + (j & 3u);
    uint prev = atomicCompSwap(keyWords[s], 0u, key);
    if (prev == 0u || prev == key) slot = int(s);
  }
  if (slot < 0) {
    atomicAdd(drops, 1u);
    return;
  }
  ivec3 d = ivec3(round(back * kCellDirScale));
  uint w = 4u * uint(slot);
  atomicAdd(cellWords[w], 1u);
  atomicAdd(cellWords[w + 1u], uint(d.x));
  atomicAdd(cellWords[w + 2u], uint(d.y));
  atomicAdd(cellWords[w + 3u], uint(d.z));
}
