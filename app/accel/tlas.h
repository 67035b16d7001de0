// tlas.h — instancing's two-level BVH (docs/instancing.md): one bottom-level BVH per mesh of
// an instanced scene (Scene::meshes, object space, the ordinary builder), a top-level BVH over the
// instances' world boxes, and the C++ traversal that moves the ray into an instance's object space at
// a top-level leaf and back; its GLSL twin is glsl/lib/traverse_instanced.glsl.
#pragma once
#include <cstdint>
#include <limits>
#include <vector>

#include "accel/bvh.h"
#include "accel/intersect.h"
#include "shared/gpu_layout.h"
#include "scene/scene.h"

namespace caustica {

struct InstancedBvh {
  // nodes[0, topNodeCount): the top-level tree (root 0); then each mesh's bottom-level tree with its
  // inner refs and leaf triangle indices rebased into `nodes` and `tris`.
  std::vector<gpu::BvhNode> nodes;
  std::uint32_t topNodeCount = 0;
  std::vector<gpu::TriGeom> tris;            // object space, each mesh in its own leaf order
  std::vector<std::uint32_t> triSource;      // tris index -> Scene::triangles index
  std::vector<gpu::InstanceRecord> instances;  // top-level leaf order
  std::vector<std::uint32_t> meshRoot;       // Scene::meshes index -> its root node in `nodes`
  int depth = 0;                             // top-level depth + deepest bottom-level depth
};

// Builds from a scene with instances (throws caustica::Error for one without). Instances are placed
// with the float world-to-object matrix of (Scene::origin-rebased) Instance::world. The same as
// placeInstances(scene, buildMeshBvhs(scene, options), options).
InstancedBvh buildInstancedBvh(const Scene& scene, const BvhBuildOptions& options = {});

// The bottom level alone: one BVH per mesh of Scene::meshes, over its object-space triangles. It does
// not depend on the instances, so a rigid animation keeps it from frame to frame and only re-places
// the instances (Renderer::setScene; docs/animation.md).
struct MeshBvhs {
  std::vector<std::vector<gpu::BvhNode>> nodes;  // per mesh, refs local to the mesh
  std::vector<std::uint32_t> triOffset;         // per mesh: its first record in `tris`
  std::vector<gpu::TriGeom> tris;               // object space, each mesh in its own leaf order
  std::vector<std::uint32_t> triSource;         // tris index -> Scene::triangles index
  std::vector<glm::vec3> boundsMin, boundsMax;  // per mesh
  int depth = 0;                                // deepest mesh tree
};
MeshBvhs buildMeshBvhs(const Scene& scene, const BvhBuildOptions& options = {});
// The top level over `scene`'s instances of meshes built by buildMeshBvhs: copied (kept for the next
// frame) or moved (no second copy of the meshes' records).
InstancedBvh placeInstances(const Scene& scene, const MeshBvhs& meshes, const BvhBuildOptions& options = {});
InstancedBvh placeInstances(const Scene& scene, MeshBvhs&& meshes, const BvhBuildOptions& options = {});

struct InstancedHit {
  Hit hit;                                         // t in world units of the ray's dir; hit.tri indexes tris
  std::uint32_t instance = gpu::kInvalidIndex;     // Scene::instances index
};

// Closest hit with t in (0, tmax): twin of traceInstanced (glsl/lib/traverse_instanced.glsl).
InstancedHit traceClosest(const InstancedBvh& bvh, const Ray& ray, float tmax = std::numeric_limits<float>::infinity());
// Any hit with t in (0, tmax).
bool traceOccluded(const InstancedBvh& bvh, const Ray& ray, float tmax);

}  // namespace caustica
