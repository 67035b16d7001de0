// bvh.h — binned-SAH BVH over triangles in the GPU layout (gpu::BvhNode, 64 bytes: both children's boxes
// in the parent): the build (bvh_build.cpp, bvh_subtree.cpp, bvh_split.cpp) and the packed tree's
// triangles, bounds and SAH cost (bvh_layout.cpp). Traversal: bvh_traverse.h; triangle test: intersect.h.
#pragma once
#include <cstdint>
#include <vector>

#include "shared/gpu_layout.h"
#include "scene/scene.h"

namespace caustica {

struct BvhBuildOptions {
  int bins = 16;            // SAH bins per axis
  // Meshes of fewer than secondBinsBelow triangles are also built with secondBins bins (0: not), and the
  // tree of lower SAH cost is kept (costs ~1 ms per 4,000 triangles; docs/architecture.md, "BVH build").
  int secondBins = 32;
  std::size_t secondBinsBelow = 65536;
  int maxLeafSize = 4;      // leaves never hold more triangles than this (at most gpu::kBvhMaxLeafSize)
  float costTraversal = 1.0f;   // SAH cost of visiting an inner node
  float costIntersect = 1.0f;   // SAH cost of one ray-triangle test
  int threads = 0;          // build threads; 0: one per hardware thread (meshes under 65,536 triangles use one)
};

struct Bvh {
  // GPU layout, written by the builder directly: one node per inner node of the binary tree, holding both
  // children's boxes and refs (leaves packed into the ref); nodes[0] is the root; a node's inner children
  // get consecutive slots when it is split, depth-first, left first (so children follow their parent).
  // A one-leaf tree is a root with that leaf and an empty slot, an empty tree a root with two empty slots.
  std::vector<gpu::BvhNode> nodes;
  std::vector<std::uint32_t> order;  // leaf order -> index into the input triangle array
  int depth = 0;                     // deepest level (root = 1); always < CAUSTICA_BVH_STACK
  int leafCount = 0;
  float sahCost = 0.0f;              // SAH cost of the tree, relative to the root's surface area
};

// Builds over the triangles' positions. Degenerate (zero-area) triangles are kept; they never hit.
// The result does not depend on BvhBuildOptions::threads (bit for bit).
// Throws caustica::Error if the tree would be deeper than the GPU traversal stack allows.
Bvh buildBvh(const std::vector<Triangle>& triangles, const BvhBuildOptions& options = {});
// The same over `count` triangles at `triangles` (a mesh's range of Scene::triangles, without a copy).
Bvh buildBvh(const Triangle* triangles, std::size_t count, const BvhBuildOptions& options = {});

// World-space bounds of everything under the root (both children's boxes); false for an empty tree.
bool bvhBounds(const std::vector<gpu::BvhNode>& nodes, glm::vec3& lo, glm::vec3& hi);

// SAH cost of a packed tree relative to the root's surface area (the root's area taken as 1 when it is 0
// or not finite): costTraversal per inner node and costIntersect per triangle, each weighted by its
// box's area. Equals Bvh::sahCost up to rounding (summed in another order).
double bvhSahCost(const std::vector<gpu::BvhNode>& nodes, float costTraversal = 1.0f, float costIntersect = 1.0f);

// Packs triangle positions in BVH leaf order (TriGeom.v0.w carries the material index bits; zero-area
// triangles as one point, packedTrianglePositions in intersect.h).
std::vector<gpu::TriGeom> packTriGeom(const std::vector<Triangle>& triangles, const Bvh& bvh);
// packTriGeom of `count` triangles at `triangles`, appended to `out`.
void appendTriGeom(const Triangle* triangles, std::size_t count, const Bvh& bvh, std::vector<gpu::TriGeom>& out);

}  // namespace caustica
