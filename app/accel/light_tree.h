// light_tree.h — the light tree over the emissive triangles (Conty Estevez & Kulla 2018; the idea of
// pbrt-v4's BVHLightSampler): its builder, and the C++ twins of glsl/lib/light_tree.glsl that choose a
// triangle by importance from a shading point and give the probability of that choice.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "shared/gpu_layout.h"

namespace caustica {

// One emissive triangle for the builder (world space, TriGeom order index).
struct LightTreeItem {
  std::uint32_t tri = 0;  // triangle index in TriGeom (BVH leaf) order
  glm::vec3 v[3];         // vertices; the front face is counter-clockwise, normal cross(v1 - v0, v2 - v0)
  double power = 0.0;     // luminance(emission) * area * sides (> 0)
  bool twoSided = false;  // emits from both faces
  std::uint32_t instance = 0;  // instanced scenes: Scene::instances index, kept in the leaf's link.y (< 2^30)
  std::uint32_t source = 0;    // its place in an order that does not depend on the BVH (the scene's triangle
                               // order): LightTree::leavesBySource follows it
};

struct LightTree {
  std::vector<gpu::LightNode> nodes;  // node 0 is the root; children adjacent; one triangle per leaf
  std::vector<std::uint32_t> leafOf;  // per triangle (TriGeom order): its leaf node, or kInvalidIndex
  int maxDepth = 0;                   // deepest leaf (root = 0); at most CAUSTICA_LIGHT_TREE_DEPTH
  // Every leaf, in the order of its item's `source`: an order that scaling or moving the scene keeps
  // (the caustic photon pass, caustic_cells.h).
  std::vector<std::uint32_t> leavesBySource;
};

// Builds the tree: binary splits in 12 buckets per axis minimising power x orientation measure x
// surface area (Conty Estevez & Kulla's cost), falling back to splits by count where a leaf could get
// deeper than CAUSTICA_LIGHT_TREE_DEPTH. `triangleCount`: size of leafOf. Empty items: empty tree.
// The tree depends on the items' geometry up to scale and translation and on their `source` order,
// not on the order they are given in nor on the rounding of scaled or moved vertices (light_tree.cpp).
LightTree buildLightTree(std::vector<LightTreeItem> items, std::size_t triangleCount);

// ---- C++ twins of glsl/lib/light_tree.glsl (same names, same float arithmetic) ----
// An upper bound, up to a constant, of the light a node's triangles can send to point p (world space)
// on a surface with unit normal n (either side; n = 0: no surface): power x bounded emission cosine x
// bounded receiver cosine / clamped squared distance. 0 where no triangle below can light p.
float lightImportance(const gpu::LightNode& node, const glm::vec3& p, const glm::vec3& n);
// Descends from the root choosing each child in proportion to its importance, with u in [0, 1)
// rescaled at every level. Returns false where no triangle can light p; else tri (TriGeom order) and
// pmf, the probability of that choice.
bool sampleLightTree(const std::vector<gpu::LightNode>& nodes, const glm::vec3& p, const glm::vec3& n, float u,
                     std::uint32_t& tri, float& pmf);
// The probability that sampleLightTree(p, n) chooses the triangle of leaf `leaf`, by repeating the
// choices along its bit trail.
float lightTreePdf(const std::vector<gpu::LightNode>& nodes, const glm::vec3& p, const glm::vec3& n, std::uint32_t leaf);

}  // namespace caustica
