// bvh.h — binned-SAH bounding volume hierarchy over triangles, flattened to the GPU layout
// (gpu::BvhNode, 32 bytes), and the C++ twin of the GLSL traversal in glsl/lib/traverse.glsl.
#pragma once
#include <cstdint>
#include <limits>
#include <vector>

#include "shared/gpu_layout.h"
#include "scene/scene.h"

namespace caustica {

struct BvhBuildOptions {
  int bins = 16;            // SAH bins per axis
  int maxLeafSize = 4;      // leaves never hold more triangles than this
  float costTraversal = 1.0f;   // SAH cost of visiting an inner node
  float costIntersect = 1.0f;   // SAH cost of one ray-triangle test
};

struct Bvh {
  std::vector<gpu::BvhNode> nodes;   // nodes[0] is the root; children of an inner node are adjacent
  std::vector<std::uint32_t> order;  // leaf order -> index into the input triangle array
  int depth = 0;                     // deepest level (root = 1); always < CAUSTICA_BVH_STACK
  int leafCount = 0;
  float sahCost = 0.0f;              // SAH cost of the tree, relative to the root's surface area
};

// Builds over the triangles' positions. Degenerate (zero-area) triangles are kept; they never hit.
// Throws caustica::Error if the tree would be deeper than the GPU traversal stack allows.
Bvh buildBvh(const std::vector<Triangle>& triangles, const BvhBuildOptions& options = {});

// Packs triangle positions in BVH leaf order (TriGeom.v0.w carries the material index bits).
std::vector<gpu::TriGeom> packTriGeom(const std::vector<Triangle>& triangles, const Bvh& bvh);

struct Ray {
  glm::vec3 origin{0.0f};
  glm::vec3 dir{0.0f, 0.0f, 1.0f};  // unit length for a trustworthy hit (intersectTriangle's t bound); t in units of |dir|
};

struct Hit {
  float t = std::numeric_limits<float>::infinity();
  float u = 0.0f, v = 0.0f;  // barycentrics of p1 and p2
  std::uint32_t tri = gpu::kInvalidIndex;  // index in TriGeom (leaf) order
  bool found() const { return tri != gpu::kInvalidIndex; }
};

// Watertight ray-triangle test (Woop, Benthin, Wald 2013). Twin of intersectTriangle() in intersect.glsl.
// Returns true and fills t,u,v when the ray hits with 0 < t < tmax.
bool intersectTriangle(const Ray& ray, const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2,
                       float tmax, float& t, float& u, float& v);

// Closest hit with t in (0, tmax). Twin of traceClosest() in traverse.glsl.
Hit traceClosest(const std::vector<gpu::BvhNode>& nodes, const std::vector<gpu::TriGeom>& tris,
                 const Ray& ray, float tmax = std::numeric_limits<float>::infinity());

// Any hit with t in (0, tmax). Twin of traceOccluded() in traverse.glsl.
bool traceOccluded(const std::vector<gpu::BvhNode>& nodes, const std::vector<gpu::TriGeom>& tris,
                   const Ray& ray, float tmax);

}  // namespace caustica
