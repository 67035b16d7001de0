// bvh_traverse.cpp — the C++ twin of the binary-node stack traversal in glsl/lib/traverse.glsl (near
// child first, far child stacked with its entry distance); world space, t in units of |ray.dir|.
#include "accel/bvh_traverse.h"

#include "accel/ray_box.h"

namespace caustica {

namespace {

using raybox::bvhVisitNode;
using raybox::kBoxPad;
using raybox::safeInverse;

// Traversal shared by closest and any hit, in the GLSL twin's order: near child first, the far one on
// a fixed-size stack with its entry distance; a popped subtree that starts beyond the closest hit is
// skipped (closest hit only). Leaves are packed into the refs (gpu_layout.h, BvhNode).
template <bool kAnyHit>
Hit traverse(const std::vector<gpu::BvhNode>& nodes, const std::vector<gpu::TriGeom>& tris,
             const Ray& ray, float tmax) {
  Hit hit;
  if (nodes.empty()) return hit;
  const glm::vec3 invDir = safeInverse(ray.dir);
  const RayShear rs = makeRayShear(ray.dir);

  float closest = tmax;
  std::uint32_t stackRef[CAUSTICA_BVH_STACK];
  float stackT[CAUSTICA_BVH_STACK];
  std::uint32_t sp = 0;
  std::uint32_t ref = 0;  // the root, an inner node
  // Next stacked ref that may still hold a closer hit, or kInvalidIndex.
  auto pop = [&]() -> std::uint32_t {
    while (sp > 0) {
      --sp;
      if (kAnyHit || stackT[sp] <= closest * kBoxPad) return stackRef[sp];
    }
    return gpu::kInvalidIndex;
  };
  for (;;) {
    if ((ref & gpu::kBvhLeafBit) == 0) {
      const gpu::BvhNode& node = nodes[ref];
      std::uint32_t near, far;
      float farT;
      const int hits = bvhVisitNode(node, ray.origin, invDir, closest, near, far, farT);
      // The builder bounds the depth, so the stack never overflows; the guard only protects memory.
      if (hits == 2 && sp < CAUSTICA_BVH_STACK) {
        stackRef[sp] = far;
        stackT[sp] = farT;
        ++sp;
      }
      if (hits > 0) {
        ref = near;
        continue;
      }
    } else {
      if (intersectLeaf(tris, ref, ray.origin, rs, kAnyHit, closest, hit) && kAnyHit) return hit;
    }
    ref = pop();
    if (ref == gpu::kInvalidIndex) break;
  }
  return hit;
}

}  // namespace

Hit traceClosest(const std::vector<gpu::BvhNode>& nodes, const std::vector<gpu::TriGeom>& tris,
                 const Ray& ray, float tmax) {
  return traverse<false>(nodes, tris, ray, tmax);
}

bool traceOccluded(const std::vector<gpu::BvhNode>& nodes, const std::vector<gpu::TriGeom>& tris,
                   const Ray& ray, float tmax) {
  return traverse<true>(nodes, tris, ray, tmax).found();
}

}  // namespace caustica
