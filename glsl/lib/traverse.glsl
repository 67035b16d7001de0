// traverse.glsl — closest-hit and any-hit BVH traversal over the 64-byte BVH nodes and the triangle
// positions, both read through buffer textures (bindings.glsl). Twin of traceClosest()/traceOccluded()
// in app/accel/bvh.cpp; keep the two in step. Include bindings.glsl, spawn.glsl and intersect.glsl first.
//
// Packing relied on (glsl/shared/gpu_layout.h, built by buildBvh/packTriGeom):
//   BvhNode i = texels 4i..4i+3 of bvhNodeTexels: (lmin, left ref), (lmax, 0), (rmin, right ref),
//     (rmax, 0); boxes as float bits in world space. A ref with kBvhLeafBit clear is an inner node's
//     index; else a leaf over triGeom[first .. first + count - 1] (first = ref & kBvhFirstMask,
//     count = ref >> kBvhCountShift & 15; count 0: an empty slot). nodes[0] is the root.
//   TriGeom i = texels 3i..3i+2 of triGeomTexels: v0.xyz, v1.xyz, v2.xyz as float bits, world space.
//   Tree depth (root = 1) is < CAUSTICA_BVH_STACK and near-first traversal pushes at most one ref per
//   level, so the stack cannot overflow; the sp check only guards memory against a malformed tree.
//
// Loop shape (for SIMD drivers such as llvmpipe, which run 8 invocations in lock-step and execute both
// sides of every branch): an inner loop descends through inner nodes until every lane holds a leaf,
// then the lanes test their leaves' triangles together. The visiting order is plain near-first
// depth-first, the same as the C++ twin's, so ties between equal t resolve the same way. A popped
// subtree whose entry distance is beyond the closest hit so far is skipped.

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

// Positions of triangle i (leaf order).
void bvhTriangle(uint i, out vec3 p0, out vec3 p1, out vec3 p2) {
  p0 = uintBitsToFloat(texelFetch(triGeomTexels, int(3u * i)).xyz);
  p1 = uintBitsToFloat(texelFetch(triGeomTexels, int(3u * i + 1u)).xyz);
  p2 = uintBitsToFloat(texelFetch(triGeomTexels, int(3u * i + 2u)).xyz);
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
// Closest hit with 0 < t < tmax. On a miss returns false with hit.t = tmax and hit.tri = kInvalidIndex.
bool traceClosest(vec3 org, vec3 dir, float tmax, out Hit hit) {
  hit.t = tmax;
  hit.u = 0.0;
  hit.v = 0.0;
  hit.tri = kInvalidIndex;
  vec3 invDir = safeInverse(dir);
  RayShear rs = makeRayShear(dir);

  uint stackRef[CAUSTICA_BVH_STACK];
  float stackT[CAUSTICA_BVH_STACK];
  uint sp = 0u;
  uint ref = 0u;  // the root, an inner node
  while (true) {
    // Inner nodes until this lane holds a leaf (an empty stack ends as the empty leaf kBvhEmptyRef).
    while ((ref & kBvhLeafBit) == 0u) {
      uint near, far;
      float farT;
      uint hits = bvhVisitNode(ref, org, invDir, hit.t, near, far, farT);
      if (hits == 2u && sp < uint(CAUSTICA_BVH_STACK)) {
        stackRef[sp] = far;
        stackT[sp] = farT;
        ++sp;
      }
      if (hits > 0u) {
        ref = near;
      } else {
        ref = kBvhEmptyRef;
        while (sp > 0u) {
          --sp;
          if (stackT[sp] <= hit.t * kBvhBoxPad) {
            ref = stackRef[sp];
            break;
          }
        }
      }
    }
    uint first = ref & kBvhFirstMask;
    uint count = (ref >> kBvhCountShift) & 15u;
    for (uint i = first; i < first + count; ++i) {
      vec3 p0, p1, p2;
      bvhTriangle(i, p0, p1, p2);
      float t, u, v;
      if (intersectTriangleSheared(org, rs, p0, p1, p2, hit.t, t, u, v)) {
        hit.t = t;
        hit.u = u;
        hit.v = v;
        hit.tri = i;
      }
    }
    // Next: the nearest stacked subtree that can still hold a closer hit.
    ref = kInvalidIndex;
    while (sp > 0u) {
      --sp;
      if (stackT[sp] <= hit.t * kBvhBoxPad) {
        ref = stackRef[sp];
        break;
      }
    }
    if (ref == kInvalidIndex) break;
  }
  return hit.tri != kInvalidIndex;
}

// Any hit with 0 < t < tmax (shadow rays). An includer may define CAUSTICA_OCCLUDER_FILTER(tri) (a
// bool expression of the triangle's leaf-order index) before including this file: triangles for which
// it is false do not occlude (Whitted: emitters cast no shadows there).
bool traceOccluded(vec3 org, vec3 dir, float tmax) {
  vec3 invDir = safeInverse(dir);
  RayShear rs = makeRayShear(dir);

  uint stackRef[CAUSTICA_BVH_STACK];
  uint sp = 0u;
  uint ref = 0u;
  while (true) {
    while ((ref & kBvhLeafBit) == 0u) {
      uint near, far;
      float farT;
      uint hits = bvhVisitNode(ref, org, invDir, tmax, near, far, farT);
      if (hits == 2u && sp < uint(CAUSTICA_BVH_STACK)) stackRef[sp++] = far;
      if (hits > 0u) {
        ref = near;
      } else if (sp > 0u) {
        ref = stackRef[--sp];
      } else {
        ref = kBvhEmptyRef;
      }
    }
    uint first = ref & kBvhFirstMask;
    uint count = (ref >> kBvhCountShift) & 15u;
    for (uint i = first; i < first + count; ++i) {
      vec3 p0, p1, p2;
      bvhTriangle(i, p0, p1, p2);
      float t, u, v;
#ifdef CAUSTICA_OCCLUDER_FILTER
      if (intersectTriangleSheared(org, rs, p0, p1, p2, tmax, t, u, v) && CAUSTICA_OCCLUDER_FILTER(i)) return true;
#else
      if (intersectTriangleSheared(org, rs, p0, p1, p2, tmax, t, u, v)) return true;
#endif
    }
    if (sp == 0u) break;
    ref = stackRef[--sp];
  }
  return false;
}
#endif  // CAUSTICA_INSTANCED
