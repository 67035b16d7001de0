// bvh_subtree.h — the sequential heart of the BVH build (internal, bvh_build.cpp): one subtree built
// depth-first, its 64-byte gpu::BvhNode written straight into place; the leaf refs it packs.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "accel/bvh_build_types.h"
#include "shared/gpu_layout.h"
#include "util/error.h"

namespace caustica::bvhbuild {

// Depth, leaf count and SAH cost (relative to the root's surface area) of a built part of the tree.
struct BuildStats {
  int depth = 0;
  int leafCount = 0;
  double sah = 0.0;
};

// A subtree left for the threaded phase: its root (an inner node) and where the single-threaded
// build would have numbered its descendants: after `marker` nodes of the top of the tree.
struct Deferred {
  WorkItem item;
  std::uint32_t marker;
};

// Ref of a leaf over prims [first, first + count) (gpu_layout.h, BvhNode).
inline std::uint32_t leafRef(std::uint32_t first, std::uint32_t count) {
  if (first > gpu::kBvhFirstMask || count > gpu::kBvhMaxLeafSize || count == 0)
    throw Error("bvh_subtree.h: leaf out of the packed range (internal error)");
  return gpu::kBvhLeafBit | count << gpu::kBvhCountShift | first;
}

inline glm::vec3 xyz(F4 v) { return glm::vec3(v[0], v[1], v[2]); }

// Builds the subtree of the inner node `root` (whose slot out[root.node] exists) depth-first, writing
// 64-byte nodes straight into `out`: a node's inner children get the next free slots when it is split
// (left, then right), so the numbering is the depth-first one of packing a finished tree. With
// `deferred`, inner nodes of fewer than deferBelow prims are not built but appended to it.
void buildSubtree(const BuildContext& ctx, const WorkItem& root, std::vector<gpu::BvhNode>& out, BuildStats& st,
                  std::vector<Deferred>* deferred, std::uint32_t deferBelow);

}  // namespace caustica::bvhbuild
