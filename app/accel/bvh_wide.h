// bvh_wide.h — the 4-wide BVH (gpu::BvhWideNode, 112 bytes) collapsed from the binary SAH tree, and the
// C++ twins of the GLSL 4-wide traversal in glsl/lib/traverse.glsl (traceClosest/traceOccluded).
#pragma once
#include <cstdint>
#include <limits>
#include <vector>

#include "accel/bvh.h"
#include "shared/gpu_layout.h"

namespace caustica {

struct BvhWide {
  std::vector<gpu::BvhWideNode> nodes;  // nodes[0] is the root; depth-first order, parents first
  int depth = 0;        // deepest level of wide nodes (root = 1)
  int stackNeed = 0;    // most stack entries the traversal can hold (<= CAUSTICA_BVH_WIDE_STACK, checked)
};

// Collapses the binary tree (Bvh::nodes: gpu::BvhNode, both children's boxes and refs per inner node,
// nodes[0] the root) into 4-wide nodes: each wide node starts from a binary node's two children and
// repeatedly opens the inner child of largest surface area until it has four children or only leaves.
// Leaves stay as they are (same refs, same TriGeom order); empty slots are dropped, so a one-leaf tree
// gets a root with that leaf in slot 0 and an empty tree a root of empty slots. Throws caustica::Error
// if the traversal stack could overflow (never for a tree that buildBvh accepts).
BvhWide packBvhWideNodes(const std::vector<gpu::BvhNode>& binary);

// Closest hit with t in (0, tmax) through the 4-wide nodes. Twin of traceClosest() in traverse.glsl.
// tmax is clamped to 3e38, as the shaders' callers pass it (an empty slot's box lies at +inf).
Hit traceClosest(const std::vector<gpu::BvhWideNode>& nodes, const std::vector<gpu::TriGeom>& tris,
                 const Ray& ray, float tmax = 3.0e38f);

// Any hit with t in (0, tmax). Twin of traceOccluded() in traverse.glsl.
bool traceOccluded(const std::vector<gpu::BvhWideNode>& nodes, const std::vector<gpu::TriGeom>& tris,
                   const Ray& ray, float tmax);

}  // namespace caustica
