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

// True when cross(p1 - p0, p2 - p0), computed in float, is exactly 0: a triangle that never hits.
bool isZeroAreaTriangle(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2);
// The positions a TriGeom stores for triangle p[3]: p itself, or, for a zero-area triangle, p[0] three
// times (the GLSL triangle test has no zero-area check: a point is rejected by its det == 0, see
// intersect.glsl). Every packer of TriGeom goes through this.
void packedTrianglePositions(const glm::vec3* p, glm::vec3& q0, glm::vec3& q1, glm::vec3& q2);

// Packs triangle positions in BVH leaf order (TriGeom.v0.w carries the material index bits; zero-area
// triangles as one point, packedTrianglePositions).
std::vector<gpu::TriGeom> packTriGeom(const std::vector<Triangle>& triangles, const Bvh& bvh);
// packTriGeom of `count` triangles at `triangles`, appended to `out`.
void appendTriGeom(const Triangle* triangles, std::size_t count, const Bvh& bvh, std::vector<gpu::TriGeom>& out);

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

// intersectTriangle with the ray's shear precomputed. Twin of intersectTriangleSheared() in intersect.glsl,
// which has no zero-area test of its own (it relies on packedTrianglePositions; the same hits on
// packed TriGeom, see there) and is written as straight-line code for llvmpipe (the same decisions).
bool intersectTriangleSheared(const glm::vec3& origin, const RayShear& rs, const glm::vec3& p0, const glm::vec3& p1,
                              const glm::vec3& p2, float tmax, float& t, float& u, float& v);

// The triangles of one leaf (`ref`: first | count << kBvhCountShift) against a sheared ray, as the C++
// traversals (one-level, 4-wide, two-level) test a leaf: each hit nearer than `closest` becomes `hit`
// and the new `closest`; with anyHit the first hit ends the test. Returns whether any triangle was hit.
bool intersectLeaf(const std::vector<gpu::TriGeom>& tris, std::uint32_t ref, const glm::vec3& origin,
                   const RayShear& rs, bool anyHit, float& closest, Hit& hit);

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
