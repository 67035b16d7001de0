// traverse.glsl — closest-hit and any-hit BVH traversal over the 112-byte 4-wide BVH nodes and the
// triangle positions, both read through buffer textures (bindings.glsl). Twin of traceClosest()/
// traceOccluded() over gpu::BvhWideNode in app/accel/bvh_wide.cpp; keep the two in step. Also holds the
// binary node visit (bvhVisitNode, twin of app/accel/ray_box.h) that traverse_instanced.glsl uses:
// instanced scenes (CAUSTICA_INSTANCED) trace through the binary two-level BVH instead of the wide nodes.
// Include bindings.glsl, spawn.glsl and intersect.glsl first.
//
// Packing relied on (glsl/shared/gpu_layout.h, built by buildBvh/packBvhWideNodes/packTriGeom):
//   BvhWideNode i = texels 7i..7i+6 of bvhWideTexels: minX, maxX, minY, maxY, minZ, maxZ (component k =
//     child k, float bits, world space), then the four child refs. A ref is a wide node's index (bit 31
//     clear) or a leaf as in BvhNode; an unused slot is kBvhEmptyRef with a box at +inf, never entered.
//     bvhWideTexels' node 0 is the root. Stack use is bounded by packBvhWideNodes (<= CAUSTICA_BVH_WIDE_STACK).
//   BvhNode i = texels 4i..4i+3 of bvhNodeTexels: (lmin, left ref), (lmax, 0), (rmin, right ref),
//     (rmax, 0); boxes as float bits in world space. A ref with kBvhLeafBit clear is an inner node's
//     index; else a leaf over triGeom[first .. first + count - 1] (first = ref & kBvhFirstMask,
//     count = ref >> kBvhCountShift & 15; count 0: an empty slot). nodes[0] is the root.
//   TriGeom i = texels 3i..3i+2 of triGeomTexels: v0.xyz, v1.xyz, v2.xyz as float bits, world space
//     (a zero-area triangle as v0 three times); v0.w = material index bits.
//   Binary tree depth (root = 1) is < CAUSTICA_BVH_STACK and the binary near-first traversal
//   (traverse_instanced.glsl) pushes at most one ref per level; the sp checks only guard memory.
//
// Loop shape (for SIMD drivers such as llvmpipe, which run 8 invocations in lock-step and execute both
// sides of every branch): an inner loop descends through inner nodes until every lane holds a leaf,
// then the lanes test their leaves' triangles together. At a wide node the entered children are sorted
// by entry distance (a 5-exchange network): the nearest is visited next, the others stacked (refs
// only), nearest on top — the same order as the C++ twin's, so ties between equal t resolve the same
// way. A popped subtree beyond the closest hit so far is not skipped on the stack: its node visit
// enters none of its children (their boxes end before hit.t), so no distances are stacked. The stack's
// top eight refs are kept in registers and the inner loop never indexes the local array (see
// BVH_INNER_STEP; docs/architecture.md, "Traversal").

struct Hit {
  float t;   // distance along dir (units of |dir|)
  float u;   // barycentric weight of v1
  float v;   // barycentric weight of v2
  uint tri;  // index into triGeom[] (leaf order), kInvalidIndex when nothing was hit
#ifdef CAUSTICA_INSTANCED
  uint inst; // the Scene::instances index of the hit (instanced scenes: tri is a stored, object-space triangle)
#endif
};

// Relative widening of a box's exit distance (as in intersectAabb): a stacked subtree is skipped only
// when its entry distance exceeds the closest hit by more than rounding.
const float kBvhBoxPad = 1.0 + 1.0 / 1048576.0;

// Tests both children of inner node `index` against the ray within tmax. Returns how many were hit;
// near = the ref to visit next (the nearer one when both), far = the other one with its entry distance.
uint bvhVisitNode(uint index, vec3 org, vec3 invDir, float tmax, out uint near, out uint far, out float farT) {
  uvec4 a = texelFetch(bvhNodeTexels, int(4u * index));
  uvec4 b = texelFetch(bvhNodeTexels, int(4u * index + 1u));
  uvec4 c = texelFetch(bvhNodeTexels, int(4u * index + 2u));
  uvec4 d = texelFetch(bvhNodeTexels, int(4u * index + 3u));
  float tl, tr;
  bool hl = intersectAabb(org, invDir, uintBitsToFloat(a.xyz), uintBitsToFloat(b.xyz), tmax, tl);
  bool hr = intersectAabb(org, invDir, uintBitsToFloat(c.xyz), uintBitsToFloat(d.xyz), tmax, tr);
  bool leftFirst = hl && (!hr || tl <= tr);
  near = leftFirst ? a.w : c.w;
  far = leftFirst ? c.w : a.w;
  farT = leftFirst ? tr : tl;
  return (hl ? 1u : 0u) + (hr ? 1u : 0u);
}

// Positions of triangle i (leaf order); returns its material index (TriGeom.v0.w, the first texel's
// fourth word), for a CAUSTICA_OCCLUDER_FILTER that would otherwise fetch the triangle again.
uint bvhTriangle(uint i, out vec3 p0, out vec3 p1, out vec3 p2) {
  uvec4 a = texelFetch(triGeomTexels, int(3u * i));
  p0 = uintBitsToFloat(a.xyz);
  p1 = uintBitsToFloat(texelFetch(triGeomTexels, int(3u * i + 1u)).xyz);
  p2 = uintBitsToFloat(texelFetch(triGeomTexels, int(3u * i + 2u)).xyz);
  return a.w;
}

// Entry distance given to a child the ray misses: above any entered child's (<= tmax * kBvhBoxPad <= 3e38 * pad).
const float kBvhMissT = 3.4e38;

// Swaps (ta, ra) and (tb, rb) when tb is strictly nearer.
void bvhSortPair(inout float ta, inout uint ra, inout float tb, inout uint rb) {
  bool s = tb < ta;
  float t0 = ta;
  uint r0 = ra;
  ta = s ? tb : ta;
  tb = s ? t0 : tb;
  ra = s ? rb : ra;
  rb = s ? r0 : rb;
}

// min and max for operands that are never NaN, as selects: GLSL min/max compile on llvmpipe to
// vminps/vmaxps plus a NaN test and a masked move (its NaN-safe min/max); `a < b ? a : b` is one
// vminps. The slab distances below are never NaN: invDir is finite and nonzero (safeInverse of a unit
// direction without NaN components), boxes are finite or +inf (empty slots), so (bound - org) * invDir is a number or +-inf.
// Where a and b are zeros of both signs the result's sign may differ from min/max; the distances are
// only compared, never used as values, so the traversal is the same.
// `precise` keeps NIR from folding the select back into fmin/fmax (its rule is for inexact selects).
vec4 bvhMin(vec4 a, vec4 b) {
  precise vec4 m = mix(b, a, lessThan(a, b));
  return m;
}
vec4 bvhMax(vec4 a, vec4 b) {
  precise vec4 m = mix(b, a, greaterThan(a, b));
  return m;
}

// Tests the four children of wide node `index` against the ray within tmax (intersectAabb on each
// component). Returns how many it enters; ref/t = the children sorted by entry distance (units of
// |dir|), entered ones first, missed ones after at kBvhMissT.
uint bvhVisitWide(uint index, vec3 org, vec3 invDir, float tmax, out uvec4 ref, out vec4 t) {
  int base = int(7u * index);
  vec4 x0 = (uintBitsToFloat(texelFetch(bvhWideTexels, base)) - org.x) * invDir.x;
  vec4 x1 = (uintBitsToFloat(texelFetch(bvhWideTexels, base + 1)) - org.x) * invDir.x;
  vec4 y0 = (uintBitsToFloat(texelFetch(bvhWideTexels, base + 2)) - org.y) * invDir.y;
  vec4 y1 = (uintBitsToFloat(texelFetch(bvhWideTexels, base + 3)) - org.y) * invDir.y;
  vec4 z0 = (uintBitsToFloat(texelFetch(bvhWideTexels, base + 4)) - org.z) * invDir.z;
  vec4 z1 = (uintBitsToFloat(texelFetch(bvhWideTexels, base + 5)) - org.z) * invDir.z;
  ref = texelFetch(bvhWideTexels, base + 6);
  vec4 hx = bvhMax(x0, x1), hy = bvhMax(y0, y1), hz = bvhMax(z0, z1);
  hx = mix(hx, vec4(3.0e38), equal(hx, vec4(0.0)));
  hy = mix(hy, vec4(3.0e38), equal(hy, vec4(0.0)));
  hz = mix(hz, vec4(3.0e38), equal(hz, vec4(0.0)));
  vec4 tnear = bvhMax(bvhMax(bvhMin(x0, x1), bvhMin(y0, y1)), bvhMax(bvhMin(z0, z1), vec4(0.0)));
  vec4 tfar = bvhMin(bvhMin(hx, hy), bvhMin(hz, vec4(tmax))) * kBvhBoxPad;
  bvec4 entered = lessThanEqual(tnear, tfar);
  t = mix(vec4(kBvhMissT), tnear, entered);
  bvhSortPair(t.x, ref.x, t.y, ref.y);
  bvhSortPair(t.z, ref.z, t.w, ref.w);
  bvhSortPair(t.x, ref.x, t.z, ref.z);
  bvhSortPair(t.y, ref.y, t.w, ref.w);
  bvhSortPair(t.y, ref.y, t.z, ref.z);
  uvec4 e = uvec4(entered);
  return e.x + e.y + e.z + e.w;
}

// The two-level traversal (traceInstanced) and the instances' world-space triangles (instances.glsl,
// empty without CAUSTICA_INSTANCED). Included always: the shader library expands #include before the
// preprocessor runs, and a file is expanded once.
#include "traverse_instanced.glsl"
#include "instances.glsl"

#ifdef CAUSTICA_INSTANCED
// Instanced scenes: both queries go through the two-level traversal.

bool traceClosest(vec3 org, vec3 dir, float tmax, out Hit hit) {
  uint inst;
  bool found = traceInstanced(org, dir, tmax, CAUSTICA_INSTANCE_RECORD_BASE, false, hit, inst);
  hit.inst = inst;
  return found;
}

bool traceOccluded(vec3 org, vec3 dir, float tmax) {
  Hit hit;
  uint inst;
  return traceInstanced(org, dir, tmax, CAUSTICA_INSTANCE_RECORD_BASE, true, hit, inst);
}
#else
// The wide traversal's stack (traceClosest, traceOccluded) is split in two: the top eight refs live in
// registers, a (a.x the topmost) then b, tn of them; the rest lie below them in the local array
// stackRef[0..sp-1]. On llvmpipe an indexed write of a local array is, at each call site, a
// read-modify-write of every lane with a branch on the lane's mask bit, and a read is a gather; the
// inner node loop touches registers only. A push that would overflow the eight registers ends the
// lane's inner loop as an empty leaf with the node kept in pendNode; the outer loop then moves the
// bottom four registers to the array and the node is visited again. The array is read only when the
// registers are empty, also in the outer loop. One stack (LIFO) all the same: the same order of visits
// as the C++ twin's. Both are rare (measured on five bundled scenes: at most 0.001 overflows and 0.004 array
// pops per ray, docs/architecture.md "Traversal"), but each array access site costs on every pass of its loop.

// Pushes r.y, r.z, r.w (the first k, 0..3; r.y on top) onto the register stack (a, b).
void bvhRegPush(inout uvec4 a, inout uvec4 b, uvec4 r, uint k) {
  b = k == 3u ? uvec4(a.yzw, b.x) : (k == 2u ? uvec4(a.zw, b.xy) : (k == 1u ? uvec4(a.w, b.xyz) : b));
  a = k == 3u ? uvec4(r.yzw, a.x) : (k == 2u ? uvec4(r.yz, a.xy) : (k == 1u ? uvec4(r.y, a.xyz) : a));
}

// Removes the top of the register stack (a.x).
void bvhRegPop(inout uvec4 a, inout uvec4 b) {
  a = uvec4(a.yzw, b.x);
  b = b.yzww;
}

// One step of the inner node loop after bvhVisitWide (hits, r) of node ref: pushes entered children
// 1..hits-1 (child 1 on top; packBvhWideNodes guarantees sp + tn + 3 <= the stack size, the check only
// guards memory) and sets ref to child 0, else the top of the registers, else the empty leaf (the outer
// loop pops the array). When the push does not fit the registers, the lane leaves the inner loop as the
// empty leaf with pendNode = ref: the outer loop moves the bottom four registers to the array and the
// node is visited again (same ray, same hit.t: the same children). Selects only, no branches.
#define BVH_INNER_STEP \
      uint k = (hits > 1u && sp + tn + 3u <= uint(CAUSTICA_BVH_WIDE_STACK)) ? hits - 1u : 0u; \
      bool fits = tn + k <= 8u; \
      uint kk = fits ? k : 0u; \
      bool pop = hits == 0u && tn > 0u; \
      uint next = hits > 0u ? r.x : (tn > 0u ? a.x : kBvhEmptyRef); \
      uvec4 pa = uvec4(a.yzw, b.x); \
      uvec4 pb = b.yzww; \
      bvhRegPush(a, b, r, kk); \
      a = pop ? pa : a; \
      b = pop ? pb : b; \
      tn = tn + kk - (pop ? 1u : 0u); \
      pendNode = fits ? pendNode : ref; \
      ref = fits ? next : kBvhEmptyRef;

// The outer loop's step after a leaf: a pending node (tn >= 6: the bottom four registers go to the
// array, deepest first, and the node is visited again), else a pop from the registers, else from the
// array, else done.
#define BVH_OUTER_STEP \
    if (pendNode != kInvalidIndex) { \
      stackRef[sp] = tn == 8u ? b.w : (tn == 7u ? b.z : b.y); \
      stackRef[sp + 1u] = tn == 8u ? b.z : (tn == 7u ? b.y : b.x); \
      stackRef[sp + 2u] = tn == 8u ? b.y : (tn == 7u ? b.x : a.w); \
      stackRef[sp + 3u] = tn == 8u ? b.x : (tn == 7u ? a.w : a.z); \
      sp += 4u; \
      tn -= 4u; \
      ref = pendNode; \
      pendNode = kInvalidIndex; \
    } else if (tn > 0u) { \
      ref = a.x; \
      bvhRegPop(a, b); \
      --tn; \
    } else if (sp > 0u) { \
      ref = stackRef[--sp]; \
    } else { \
      break; \
    }

#define BVH_STACK_VARS \
  uint stackRef[CAUSTICA_BVH_WIDE_STACK]; \
  uint sp = 0u; \
  uvec4 a = uvec4(0u), b = uvec4(0u); \
  uint tn = 0u; \
  uint pendNode = kInvalidIndex;

// Closest hit with 0 < t < tmax. On a miss returns false with hit.t = tmax and hit.tri = kInvalidIndex.
bool traceClosest(vec3 org, vec3 dir, float tmax, out Hit hit) {
  hit.t = tmax;
  hit.u = 0.0;
  hit.v = 0.0;
  hit.tri = kInvalidIndex;
  vec3 invDir = safeInverse(dir);
  RayShear rs = makeRayShear(dir);

  // Refs only, as in traceOccluded: a popped subtree is entered even when its entry distance is beyond
  // the closest hit (bvhVisitWide then enters none of its children, or its leaf's triangles fail the
  // t < hit.t test), so the hit is the same (docs/architecture.md, "Traversal").
  BVH_STACK_VARS
  uint ref = 0u;  // the root, an inner node
  while (true) {
    // Inner nodes until this lane holds a leaf (or the empty leaf: see BVH_INNER_STEP).
    // Both loops test at the bottom: on llvmpipe a top-tested loop runs one masked body more than its
    // trip count when its last lane leaves (docs/architecture.md, "Writing shaders for llvmpipe": 1.15-1.24x).
    if ((ref & kBvhLeafBit) == 0u) do {
      uvec4 r;
      vec4 t;
      uint hits = bvhVisitWide(ref, org, invDir, hit.t, r, t);
      BVH_INNER_STEP
    } while ((ref & kBvhLeafBit) == 0u);
    uint first = ref & kBvhFirstMask;
    uint count = (ref >> kBvhCountShift) & 15u;
    uint i = first;
    if (count > 0u) do {
      vec3 p0, p1, p2;
      bvhTriangle(i, p0, p1, p2);
      float t, u, v;
      if (intersectTriangleSheared(org, rs, p0, p1, p2, hit.t, t, u, v)) {
        hit.t = t;
        hit.u = u;
        hit.v = v;
        hit.tri = i;
      }
    } while (++i < first + count);
    BVH_OUTER_STEP
  }
  return hit.tri != kInvalidIndex;
}

// Any hit with 0 < t < tmax (shadow rays). An includer may define CAUSTICA_OCCLUDER_FILTER(tri, material)
// (a bool expression of the triangle's leaf-order index and its material index, TriGeom.v0.w) before
// including this file: triangles for which it is false do not occlude (Whitted: emitters cast no
// shadows there). The material comes with the positions' texels (no second fetch of the triangle).
bool traceOccluded(vec3 org, vec3 dir, float tmax) {
  vec3 invDir = safeInverse(dir);
  RayShear rs = makeRayShear(dir);

  BVH_STACK_VARS
  uint ref = 0u;
  while (true) {
    if ((ref & kBvhLeafBit) == 0u) do {
      uvec4 r;
      vec4 t;
      uint hits = bvhVisitWide(ref, org, invDir, tmax, r, t);
      BVH_INNER_STEP
    } while ((ref & kBvhLeafBit) == 0u);
    uint first = ref & kBvhFirstMask;
    uint count = (ref >> kBvhCountShift) & 15u;
    uint i = first;
    if (count > 0u) do {
      vec3 p0, p1, p2;
      uint material = bvhTriangle(i, p0, p1, p2);
      float t, u, v;
#ifdef CAUSTICA_OCCLUDER_FILTER
      if (intersectTriangleSheared(org, rs, p0, p1, p2, tmax, t, u, v) && CAUSTICA_OCCLUDER_FILTER(i, material)) return true;
#else
      if (intersectTriangleSheared(org, rs, p0, p1, p2, tmax, t, u, v)) return true;
#endif
    } while (++i < first + count);
    BVH_OUTER_STEP
  }
  return false;
}
#endif  // CAUSTICA_INSTANCED
