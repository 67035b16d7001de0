// traverse.glsl — closest-hit and any-hit BVH traversal over nodes[] and triGeom[] (bindings.glsl).
// Twin of traceClosest()/traceOccluded() in app/accel/bvh.cpp. Include bindings.glsl, spawn.glsl and intersect.glsl first.
//
// Packing relied on (glsl/shared/gpu_layout.h, built by buildBvh/packTriGeom):
//   BvhNode (32 bytes): bmin, bmax = world-space box; triCount == 0: inner node whose children are
//     bvhNode(leftFirst) and bvhNode(leftFirst + 1) (always at higher indices than the parent);
//     triCount > 0: leaf over triGeomAt(leftFirst .. leftFirst + triCount - 1).
//   bvhNode(0) is the root; an empty scene has a root with bmin > bmax, rejected before any child is read.
//   TriGeom: v0.xyz, v1.xyz, v2.xyz = world-space vertices in leaf order (v0.w = material bits, unused here).
//   Tree depth (root = 1) is < CAUSTICA_BVH_STACK, and near-first traversal pushes at most one node per
//   level, so the stack cannot overflow; the sp check only guards memory against a malformed tree.

struct Hit {
  float t;   // distance along dir (units of |dir|)
  float u;   // barycentric weight of v1
  float v;   // barycentric weight of v2
  uint tri;  // index into triGeom[] (leaf order), kInvalidIndex when nothing was hit
};

// Closest hit with 0 < t < tmax. On a miss returns false with hit.t = tmax and hit.tri = kInvalidIndex.
bool traceClosest(vec3 org, vec3 dir, float tmax, out Hit hit) {
  hit.t = tmax;
  hit.u = 0.0;
  hit.v = 0.0;
  hit.tri = kInvalidIndex;
  if (!(bvhNode(0).bmin.x <= bvhNode(0).bmax.x)) return false;  // empty scene
  vec3 invDir = safeInverse(dir);
  float tnear;
  if (!intersectAabb(org, invDir, bvhNode(0).bmin, bvhNode(0).bmax, tmax, tnear)) return false;

  uint stack[CAUSTICA_BVH_STACK];
  uint sp = 0u;
  uint index = 0u;
  while (true) {
    BvhNode node = bvhNode(index);
    uint leftFirst = node.leftFirst;
    uint triCount = node.triCount;
    if (triCount > 0u) {
      for (uint i = leftFirst; i < leftFirst + triCount; ++i) {
        float t, u, v;
        TriGeom tg = triGeomAt(i);
        if (intersectTriangle(org, dir, tg.v0.xyz, tg.v1.xyz, tg.v2.xyz, hit.t,
                              t, u, v)) {
          hit.t = t;
          hit.u = u;
          hit.v = v;
          hit.tri = i;
        }
      }
    } else {
      uint left = leftFirst;
      float tl, tr;
      BvhNode nl = bvhNode(left), nr = bvhNode(left + 1u);
      bool hl = intersectAabb(org, invDir, nl.bmin, nl.bmax, hit.t, tl);
      bool hr = intersectAabb(org, invDir, nr.bmin, nr.bmax, hit.t, tr);
      if (hl && hr) {
        uint first = tl <= tr ? left : left + 1u;
        if (sp < uint(CAUSTICA_BVH_STACK)) stack[sp++] = first == left ? left + 1u : left;
        index = first;
        continue;
      }
      if (hl || hr) {
        index = hl ? left : left + 1u;
        continue;
      }
    }
    if (sp == 0u) break;
    index = stack[--sp];
  }
  return hit.tri != kInvalidIndex;
}

// Any hit with 0 < t < tmax (shadow rays).
bool traceOccluded(vec3 org, vec3 dir, float tmax) {
  if (!(bvhNode(0).bmin.x <= bvhNode(0).bmax.x)) return false;  // empty scene
  vec3 invDir = safeInverse(dir);
  float tnear;
  if (!intersectAabb(org, invDir, bvhNode(0).bmin, bvhNode(0).bmax, tmax, tnear)) return false;

  uint stack[CAUSTICA_BVH_STACK];
  uint sp = 0u;
  uint index = 0u;
  while (true) {
    BvhNode node = bvhNode(index);
    uint leftFirst = node.leftFirst;
    uint triCount = node.triCount;
    if (triCount > 0u) {
      for (uint i = leftFirst; i < leftFirst + triCount; ++i) {
        float t, u, v;
        TriGeom tg = triGeomAt(i);
        if (intersectTriangle(org, dir, tg.v0.xyz, tg.v1.xyz, tg.v2.xyz, tmax,
                              t, u, v))
          return true;
      }
    } else {
      uint left = leftFirst;
      float tl, tr;
      BvhNode nl = bvhNode(left), nr = bvhNode(left + 1u);
      bool hl = intersectAabb(org, invDir, nl.bmin, nl.bmax, tmax, tl);
      bool hr = intersectAabb(org, invDir, nr.bmin, nr.bmax, tmax, tr);
      if (hl && hr) {
        uint first = tl <= tr ? left : left + 1u;
        if (sp < uint(CAUSTICA_BVH_STACK)) stack[sp++] = first == left ? left + 1u : left;
        index = first;
        continue;
      }
      if (hl || hr) {
        index = hl ? left : left + 1u;
        continue;
      }
    }
    if (sp == 0u) break;
    index = stack[--sp];
  }
  return false;
}
