// traverse_instanced.glsl — two-level (instanced) traversal: twin of traverse<>() in app/accel/tlas.cpp;
// keep the two in step. Include traverse.glsl first (which includes this file under CAUSTICA_INSTANCED:
// traceClosest/traceOccluded then call traceInstanced; docs/instancing.md); tested against
// the C++ twin by tests/gpu/traverse_gpu_test.cpp.
//
// Layout (InstancedBvh, gpu_layout.h InstanceRecord): bvhNodeTexels holds the top-level nodes (root 0),
// then every mesh's bottom-level nodes (refs rebased), then at node index recordBase + i the 4 texels
// of InstanceRecord i (top-level leaf order). triGeomTexels holds the meshes' object-space triangles.
// A leaf ref in the top level is one instance (first = record index); below it, triangles as usual.
// The ray is moved into object space without normalizing the direction, so t stays the world t.

const int kInstancedStack = 2 * CAUSTICA_BVH_STACK;

// World-to-object rows of record `record`, and its bottom-level root (texel 3 .x).
void instanceRecord(uint recordBase, uint record, out vec4 r0, out vec4 r1, out vec4 r2, out uint root, out uint sceneInstance) {
  int base = int(4u * (recordBase + record));
  r0 = uintBitsToFloat(texelFetch(bvhNodeTexels, base));
  r1 = uintBitsToFloat(texelFetch(bvhNodeTexels, base + 1));
  r2 = uintBitsToFloat(texelFetch(bvhNodeTexels, base + 2));
  uvec4 w = texelFetch(bvhNodeTexels, base + 3);
  root = w.x;
  sceneInstance = w.z;
}

// Closest hit with 0 < t < tmax; hit.tri indexes triGeom, inst = the scene instance (kInvalidIndex on a miss).
// With anyHit, returns at the first hit.
bool traceInstanced(vec3 worldOrg, vec3 worldDir, float tmax, uint recordBase, bool anyHit, out Hit hit, out uint inst) {
  hit.t = tmax;
  hit.u = 0.0;
  hit.v = 0.0;
  hit.tri = kInvalidIndex;
  inst = kInvalidIndex;
  vec3 org = worldOrg, dir = worldDir;
  vec3 invDir = safeInverse(dir);
  RayShear rs = makeRayShear(dir);
  uint stackRef[kInstancedStack];
  float stackT[kInstancedStack];
  uint sp = 0u;
  bool inInstance = false;
  uint instSp = 0u, current = kInvalidIndex;
  uint ref = 0u;
  while (true) {
    if ((ref & kBvhLeafBit) == 0u) {
      uint near, far;
      float farT;
      uint hits = bvhVisitNode(ref, org, invDir, hit.t, near, far, farT);
      if (hits == 2u && sp < uint(kInstancedStack)) {
        stackRef[sp] = far;
        stackT[sp] = farT;
        ++sp;
      }
      if (hits > 0u) {
        ref = near;
        continue;
      }
    } else if (ref != kBvhEmptyRef) {
      uint first = ref & kBvhFirstMask;
      if (!inInstance) {
        vec4 r0, r1, r2;
        uint root, sceneInstance;
        instanceRecord(recordBase, first, r0, r1, r2, root, sceneInstance);
        org = vec3(dot(r0.xyz, worldOrg) + r0.w, dot(r1.xyz, worldOrg) + r1.w, dot(r2.xyz, worldOrg) + r2.w);
        dir = vec3(dot(r0.xyz, worldDir), dot(r1.xyz, worldDir), dot(r2.xyz, worldDir));
        invDir = safeInverse(dir);
        rs = makeRayShear(dir);
        inInstance = true;
        instSp = sp;
        current = sceneInstance;
        ref = root;
        continue;
      }
      uint count = (ref >> kBvhCountShift) & 15u;
      for (uint i = first; i < first + count; ++i) {
        vec3 p0, p1, p2;
        uint material = bvhTriangle(i, p0, p1, p2);
        float t, u, v;
        if (intersectTriangleSheared(org, rs, p0, p1, p2, hit.t, t, u, v)) {
#ifdef CAUSTICA_OCCLUDER_FILTER
          if (anyHit && !CAUSTICA_OCCLUDER_FILTER(i, material)) continue;  // traverse.glsl's filter (Whitted)
#endif
          hit.t = t;
          hit.u = u;
          hit.v = v;
          hit.tri = i;
          inst = current;
          if (anyHit) return true;
        }
      }
    }
    // Pop: back to world space when the stack returns to its height at the instance's entry.
    ref = kInvalidIndex;
    while (true) {
      if (inInstance && sp == instSp) {
        org = worldOrg;
        dir = worldDir;
        invDir = safeInverse(dir);
        rs = makeRayShear(dir);
        inInstance = false;
      }
      if (sp == 0u) break;
      --sp;
      if (anyHit || stackT[sp] <= hit.t * kBvhBoxPad) {
        ref = stackRef[sp];
        break;
      }
    }
    if (ref == kInvalidIndex) break;
  }
  return hit.tri != kInvalidIndex;
}
