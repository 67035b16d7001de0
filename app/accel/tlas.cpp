// tlas.cpp — instancing's two-level BVH and its C++ traversal (tlas.h, docs/instancing.md).
#include "accel/tlas.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "accel/ray_box.h"
#include "util/error.h"

namespace caustica {

namespace {

using raybox::bvhVisitNode;
using raybox::kBoxPad;
using raybox::safeInverse;
constexpr int kStack = 2 * CAUSTICA_BVH_STACK;  // one tree on top of the other

std::uint32_t rebase(std::uint32_t ref, std::uint32_t nodeOffset, std::uint32_t triOffset) {
  if ((ref & gpu::kBvhLeafBit) == 0) return ref + nodeOffset;
  if (ref == gpu::kBvhEmptyRef) return ref;
  const std::uint64_t first = std::uint64_t(ref & gpu::kBvhFirstMask) + triOffset;
  if (first > gpu::kBvhFirstMask) throw Error("tlas.cpp: more than 2^27 stored triangles");
  return (ref & ~gpu::kBvhFirstMask) | std::uint32_t(first);
}

template <bool kAnyHit>
InstancedHit traverse(const InstancedBvh& bvh, const Ray& ray, float tmax) {
  InstancedHit out;
  if (bvh.nodes.empty()) return out;
  glm::vec3 org = ray.origin, dir = ray.dir;
  glm::vec3 invDir = safeInverse(dir);
  RayShear rs = makeRayShear(dir);
  float closest = tmax;
  std::uint32_t stackRef[kStack];
  float stackT[kStack];
  std::uint32_t sp = 0;
  bool inInstance = false;
  std::uint32_t instSp = 0, instRecord = 0;
  auto leave = [&]() {
    org = ray.origin;
    dir = ray.dir;
    invDir = safeInverse(dir);
    rs = makeRayShear(dir);
    inInstance = false;
  };
  auto pop = [&]() -> std::uint32_t {
    for (;;) {
      if (inInstance && sp == instSp) leave();
      if (sp == 0) return gpu::kInvalidIndex;
      --sp;
      if (kAnyHit || stackT[sp] <= closest * kBoxPad) return stackRef[sp];
    }
  };
  std::uint32_t ref = 0;
  for (;;) {
    if ((ref & gpu::kBvhLeafBit) == 0) {
      const gpu::BvhNode& node = bvh.nodes[ref];
      std::uint32_t near, far;
      float farT;
      const int hits = bvhVisitNode(node, org, invDir, closest, near, far, farT);
      if (hits == 2 && sp < std::uint32_t(kStack)) {
        stackRef[sp] = far;
        stackT[sp] = farT;
        ++sp;
      }
      if (hits > 0) {
        ref = near;
        continue;
      }
    } else if (ref != gpu::kBvhEmptyRef) {
      const std::uint32_t first = ref & gpu::kBvhFirstMask;
      if (!inInstance) {
        // A top-level leaf: one instance. The ray moves into its object space with the same t.
        const gpu::InstanceRecord& r = bvh.instances[first];
        const glm::vec3 o = ray.origin, d = ray.dir;
        org = glm::vec3(glm::dot(glm::vec3(r.row0), o) + r.row0.w, glm::dot(glm::vec3(r.row1), o) + r.row1.w,
                        glm::dot(glm::vec3(r.row2), o) + r.row2.w);
        dir = glm::vec3(glm::dot(glm::vec3(r.row0), d), glm::dot(glm::vec3(r.row1), d), glm::dot(glm::vec3(r.row2), d));
        invDir = safeInverse(dir);
        rs = makeRayShear(dir);
        inInstance = true;
        instSp = sp;
        instRecord = first;
        ref = r.root;
        continue;
      }
      if (intersectLeaf(bvh.tris, ref, org, rs, kAnyHit, closest, out.hit)) {
        out.instance = bvh.instances[instRecord].sceneInstance;
        if (kAnyHit) return out;
      }
    }
    ref = pop();
    if (ref == gpu::kInvalidIndex) break;
  }
  return out;
}

}  // namespace

MeshBvhs buildMeshBvhs(const Scene& scene, const BvhBuildOptions& options) {
  if (scene.instances.empty()) throw Error("tlas.cpp: the scene has no instances (load it with keepInstances)");
  MeshBvhs out;
  out.nodes.resize(scene.meshes.size());
  out.triOffset.resize(scene.meshes.size());
  out.boundsMin.resize(scene.meshes.size());
  out.boundsMax.resize(scene.meshes.size());
  out.tris.reserve(scene.triangles.size());  // every stored triangle once
  out.triSource.reserve(scene.triangles.size());
  for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
    const MeshRange& range = scene.meshes[m];
    const Triangle* tris = scene.triangles.data() + range.firstTriangle;  // the mesh's range, not a copy
    Bvh b = buildBvh(tris, range.triangleCount, options);
    out.depth = std::max(out.depth, b.depth);
    out.triOffset[m] = std::uint32_t(out.tris.size());
    appendTriGeom(tris, range.triangleCount, b, out.tris);
    for (std::uint32_t o : b.order) out.triSource.push_back(range.firstTriangle + o);
    if (!bvhBounds(b.nodes, out.boundsMin[m], out.boundsMax[m])) out.boundsMin[m] = out.boundsMax[m] = glm::vec3(0.0f);
    out.nodes[m] = std::move(b.nodes);
  }
  return out;
}

InstancedBvh buildInstancedBvh(const Scene& scene, const BvhBuildOptions& options) {
  return placeInstances(scene, buildMeshBvhs(scene, options), options);
}

InstancedBvh placeInstances(const Scene& scene, const MeshBvhs& meshes, const BvhBuildOptions& options) {
  return placeInstances(scene, MeshBvhs(meshes), options);
}

InstancedBvh placeInstances(const Scene& scene, MeshBvhs&& meshes, const BvhBuildOptions& options) {
  if (scene.instances.empty()) throw Error("tlas.cpp: the scene has no instances (load it with keepInstances)");
  if (meshes.nodes.size() != scene.meshes.size()) throw Error("internal: placeInstances with another scene's meshes");
  InstancedBvh out;
  out.tris = std::move(meshes.tris);
  out.triSource = std::move(meshes.triSource);
  // Top level: each instance's world box (its mesh box's corners moved), as a degenerate "triangle"
  // spanning the box with its centre as centroid; leaves of one instance.
  std::vector<Triangle> boxes(scene.instances.size());
  std::vector<glm::dmat4> worldToObject(scene.instances.size());
  glm::dmat4 rebase0(1.0);
  rebase0[3] = glm::dvec4(-scene.origin, 1.0);
  for (std::size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& in = scene.instances[i];
    const glm::dmat4 world = rebase0 * in.world;
    worldToObject[i] = glm::inverse(world);
    Bounds b;
    for (int c = 0; c < 8; ++c) {
      const glm::vec3& lo = meshes.boundsMin[in.mesh];
      const glm::vec3& hi = meshes.boundsMax[in.mesh];
      const glm::dvec4 p((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z, 1.0);
      b.grow(glm::vec3(glm::dvec3(world * p)));
    }
    // Widen by rounding: the object-space ray meets the mesh's own float box.
    const glm::vec3 pad = 1e-6f * (glm::abs(b.min) + glm::abs(b.max) + (b.max - b.min));
    boxes[i] = makeTriangle(b.min - pad, b.max + pad, 0.5f * (b.min + b.max));
  }
  BvhBuildOptions top = options;
  top.maxLeafSize = 1;
  Bvh tlas = buildBvh(boxes, top);
  out.depth = tlas.depth + meshes.depth;
  if (out.depth >= kStack) throw Error("tlas.cpp: two-level BVH depth " + std::to_string(out.depth) + " exceeds the stack");
  out.topNodeCount = std::uint32_t(tlas.nodes.size());
  out.nodes = std::move(tlas.nodes);
  out.instances.resize(scene.instances.size());
  for (std::size_t leaf = 0; leaf < tlas.order.size(); ++leaf) {
    const std::uint32_t i = tlas.order[leaf];
    const glm::dmat4& w2o = worldToObject[i];
    gpu::InstanceRecord& r = out.instances[leaf];
    r.row0 = glm::vec4(w2o[0][0], w2o[1][0], w2o[2][0], w2o[3][0]);
    r.row1 = glm::vec4(w2o[0][1], w2o[1][1], w2o[2][1], w2o[3][1]);
    r.row2 = glm::vec4(w2o[0][2], w2o[1][2], w2o[2][2], w2o[3][2]);
    r.mesh = scene.instances[i].mesh;
    r.sceneInstance = i;
    r.flags = 0;
  }
  out.meshRoot.resize(scene.meshes.size());
  for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
    const std::uint32_t nodeOffset = std::uint32_t(out.nodes.size());
    out.meshRoot[m] = nodeOffset;
    for (gpu::BvhNode n : meshes.nodes[m]) {
      n.left = rebase(n.left, nodeOffset, meshes.triOffset[m]);
      n.right = rebase(n.right, nodeOffset, meshes.triOffset[m]);
      out.nodes.push_back(n);
    }
    std::vector<gpu::BvhNode>().swap(meshes.nodes[m]);
  }
  for (gpu::InstanceRecord& r : out.instances) r.root = out.meshRoot[r.mesh];
  return out;
}

InstancedHit traceClosest(const InstancedBvh& bvh, const Ray& ray, float tmax) {
  return traverse<false>(bvh, ray, tmax);
}

bool traceOccluded(const InstancedBvh& bvh, const Ray& ray, float tmax) {
  return traverse<true>(bvh, ray, tmax).hit.found();
}

}  // namespace caustica
