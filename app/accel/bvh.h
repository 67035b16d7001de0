// bvh.h — binned-SAH bounding volume hierarchy over triangles, flattened to the GPU layout
// (gpu::BvhNode, 64 bytes: both children's boxes in the parent), and the C++ twin of the GLSL
// traversal in glsl/lib/traverse.glsl.
#pragma once
#include <cstdint>
#include <limits>
#include <vector>

#include "shared/gpu_layout.h"
#include "scene/scene.h"

namespace caustica {

struct BvhBuildOptions {
  int bins = 16;            // SAH bins per axis
  int maxLeafSize = 4;      // leaves never hold more triangles than this (at most gpu::kBvhMaxLeafSize)
  float costTraversal = 1.0f;   // SAH cost of visiting an inner node
  float costIntersect = 1.0f;   // SAH cost of one ray-triangle test
  int threads = 0;          // build threads; 0: one per hardware thread (meshes under 65,536 triangles use one)
};

// A node of the builder's binary tree (32 bytes): its own box and either two children (leftFirst,
// leftFirst + 1) or, with triCount > 0, a leaf over triangles [leftFirst, leftFirst + triCount) in leaf order.
struct BvhBinaryNode {
  glm::vec3 bmin;                 // world-space AABB minimum
  std::uint32_t leftFirst = 0;    // inner: index of the left child (right = left + 1); leaf: first triangle
  glm::vec3 bmax;                 // world-space AABB maximum
  std::uint32_t triCount = 0;     // 0 for an inner node
};

struct Bvh {
  std::vector<BvhBinaryNode> binary; // the builder's tree; binary[0] is the root, children adjacent
  std::vector<gpu::BvhNode> nodes;   // GPU layout: one node per inner node of `binary`; nodes[0] is the root
  std::vector<std::uint32_t> order;  // leaf order -> index into the input triangle array
  int depth = 0;                     // deepest level (root = 1); always < CAUSTICA_BVH_STACK
  int leafCount = 0;
  float sahCost = 0.0f;              // SAH cost of the tree, relative to the root's surface area
};

// Builds over the triangles' positions. Degenerate (zero-area) triangles are kept; they never hit.
// Throws caustica::Error if the tree would be deeper than the GPU traversal stack allows.
Bvh buildBvh(const std::vector<Triangle>& triangles, const BvhBuildOptions& options = {});

// The GPU nodes of a binary tree: each inner node becomes a gpu::BvhNode holding both children's boxes
// and refs (leaves packed into the ref); a one-leaf tree gets a root with that leaf and an empty slot,
// an empty tree a root with two empty slots. Inner nodes keep depth-first order (root first).
std::vector<gpu::BvhNode> packBvhNodes(const std::vector<BvhBinaryNode>& binary);

// World-space bounds of everything under the root (both children's boxes); false for an empty tree.
bool bvhBounds(const std::vector<gpu::BvhNode>& nodes, glm::vec3& lo, glm::vec3& hi);

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

// The ray-only part of the watertight test: the axis permuted to z and the shear onto +z. Twin of
// RayShear/makeRayShear() in intersect.glsl; the traversal computes it once per ray.
struct RayShear {
  int kz = 2;       // axis of the largest |dir| component
  float sx = 0.0f;  // -d.x / d.z of the permuted direction
  float sy = 0.0f;  // -d.y / d.z
  float sz = 0.0f;  // 1 / d.z (0 for a zero direction: nothing hits)
};
RayShear makeRayShear(const glm::vec3& dir);

// intersectTriangle with the ray's shear precomputed. Twin of intersectTriangleSheared() in intersect.glsl.
bool intersectTriangleSheared(const glm::vec3& origin, const RayShear& rs, const glm::vec3& p0, const glm::vec3& p1,
                              const glm::vec3& p2, float tmax, float& t, float& u, float& v);

// Watertight ray-triangle test (Woop, Benthin, Wald 2013). Twin of intersectTriangle() in intersect.glsl.
// Returns true and fills t,u,v when the ray hits with 0 < t < tmax.
bool intersectTriangle(const Ray& ray, const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2,
                       float tmax, float& t, float& u, float& v);

// Closest hit with t in (0, tmax) over the binary nodes: the reference for the 4-wide twin (bvh_wide.h)
// and the visiting order of bvhVisitNode() in traverse.glsl (used by traverse_instanced.glsl).
Hit traceClosest(const std::vector<gpu::BvhNode>& nodes, const std::vector<gpu::TriGeom>& tris,
                 const Ray& ray, float tmax = std::numeric_limits<float>::infinity());

// Any hit with t in (0, tmax) over the binary nodes (see traceClosest above).
bool traceOccluded(const std::vector<gpu::BvhNode>& nodes, const std::vector<gpu::TriGeom>& tris,
                   const Ray& ray, float tmax);

}  // namespace caustica
