// bvh_wide.h — the 4-wide BVH (gpu::BvhWideNode, 112 bytes) collapsed from the binary SAH tree, and the
// C++ twins of the GLSL 4-wide traversal in glsl/lib/traverse.glsl (traceClosest/traceOccluded).
#pragma once
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "accel/bvh.h"
#include "accel/intersect.h"
#include "shared/gpu_layout.h"

namespace caustica {

// How packBvhWideNodes shapes the wide tree (docs/architecture.md, "The 4-wide tree", which says what
// was measured and how).
struct WideCollapseOptions {
  enum class Method {
    Greedy,  // open the inner child of largest surface area until four children
    Sah,     // dynamic programme over the binary tree minimising the SAH cost below (Ylitie et al. 2017 style)
  };
  Method method = Method::Sah;
  // Sah: a binary subtree of at most this many triangles may become one leaf (its triangles are
  // contiguous in leaf order); 0: binary leaves only. At most gpu::kBvhMaxLeafSize.
  int maxLeafSize = 4;
  // Sah costs, each weighted by the box's surface area: a wide node visit, one outer-loop step (a leaf
  // visited), one triangle test.
  float costNode = 1.0f;
  float costLeaf = 0.0f;
  float costTriangle = 1.0f;
};

struct BvhWide {
  std::vector<gpu::BvhWideNode> nodes;  // nodes[0] is the root; depth-first order, parents first
  int depth = 0;        // deepest level of wide nodes (root = 1)
  int stackNeed = 0;    // most stack entries the traversal can hold (<= CAUSTICA_BVH_WIDE_STACK, checked)
};

// Collapses the binary tree (Bvh::nodes: gpu::BvhNode, both children's boxes and refs per inner node,
// nodes[0] the root) into 4-wide nodes: each wide node starts from a binary node's two children and
// opens inner children until it has at most four: by the SAH (Method::Sah, the default: which nodes to
// open, and which subtrees of few triangles to merge into one leaf, chosen by a dynamic programme) or
// greedily (Method::Greedy: the inner child of largest surface area until four children or only leaves).
// TriGeom order is unchanged; leaves keep their binary refs unless merged (then first | count of the
// subtree's contiguous triangles); empty slots are dropped, so a one-leaf tree (always greedy)
// gets a root with that leaf in slot 0 and an empty tree a root of empty slots. Throws caustica::Error
// if the traversal stack could overflow (never for a tree that buildBvh accepts).
BvhWide packBvhWideNodes(const std::vector<gpu::BvhNode>& binary, const WideCollapseOptions& options = {});

// The binary build and wide collapse options of a flat scene's tree (renderer, `caustica info`).
struct BvhShape {
  BvhBuildOptions build;
  WideCollapseOptions collapse;
};
// The defaults, changed for experiments by $CAUSTICA_BVH_SHAPE, a comma-separated list of key=value:
// collapse=greedy|sah, wideleaf=N (collapse maxLeafSize), cn=, cl=, ct= (collapse costs), leaf=N
// (binary maxLeafSize), bct=, bci= (binary SAH costTraversal, costIntersect), bins=N (binary SAH bins), bins2=N
// (BvhBuildOptions::secondBins; 0: one build). Throws caustica::Error on a
// malformed value.
BvhShape bvhShapeFromEnv();
// The same from a string in that syntax ("" = the defaults).
BvhShape parseBvhShape(const std::string& spec);

// Closest hit with t in (0, tmax) through the 4-wide nodes. Twin of traceClosest() in traverse.glsl.
// tmax is clamped to 3e38, as the shaders' callers pass it (an empty slot's box lies at +inf).
Hit traceClosest(const std::vector<gpu::BvhWideNode>& nodes, const std::vector<gpu::TriGeom>& tris,
                 const Ray& ray, float tmax = 3.0e38f);

// Any hit with t in (0, tmax). Twin of traceOccluded() in traverse.glsl.
bool traceOccluded(const std::vector<gpu::BvhWideNode>& nodes, const std::vector<gpu::TriGeom>& tris,
                   const Ray& ray, float tmax);

}  // namespace caustica
