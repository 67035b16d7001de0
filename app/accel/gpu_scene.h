// gpu_scene.h — packs a Scene and its BVH into the arrays the shaders read (gpu_layout.h) and builds
// the light tree over the emitters. (Which shader features a scene needs: gpu/shader_features.h.)
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "accel/bvh.h"
#include "accel/light_tree.h"
#include "scene/caustic_casters.h"
#include "scene/scene.h"
#include "shading/environment_sampling.h"

namespace caustica {

// Per material of `scene`: whether some triangle uses it (a material no triangle uses switches no
// shader feature on and adds no texcoords to the TriShade words).
std::vector<bool> usedMaterials(const Scene& scene);
// True when the material has a GGX lobe: a metal or glass part with roughness^2 >= kDeltaAlpha (or a
// metallicRoughness texture), or a diffuse part with a specular layer (specularF90 > 0).
bool hasRoughLobe(const Material& m);

// Which optional blocks the TriShade words of each triangle hold (gpu_layout.h), and where.
struct TriShadeLayout {
  bool texcoords = false;  // the material UV set (a used material reads a texture)
  bool colors = false;     // COLOR_0 as half floats (Scene::colors not empty)
  bool tangents = false;   // TANGENT, octahedral (Scene::tangents not empty, and texcoords)
  std::uint32_t colorOffset() const { return gpu::kTriShadeWords + (texcoords ? gpu::kTriShadeTexcoordWords : 0u); }
  std::uint32_t tangentOffset() const { return colorOffset() + (colors ? gpu::kTriShadeColorWords : 0u); }
  std::uint32_t stride() const { return tangentOffset() + (tangents ? gpu::kTriShadeTangentWords : 0u); }
  // CAUSTICA_TRISHADE_TEXCOORDS, _COLORS, _TANGENTS for the blocks present (tri_shade.glsl).
  std::vector<std::string> defines() const;
};

struct GpuScene {
  std::vector<gpu::BvhNode> nodes;
  std::size_t triangleCount = 0;        // triangles (TriGeom records), also when triGeom is not filled
  std::vector<gpu::TriGeom> triGeom;    // BVH leaf order
  std::vector<std::uint32_t> triShade;  // BVH leaf order, triShadeStride words per triangle (gpu_layout.h)
  TriShadeLayout triShadeLayout;        // the blocks those words hold
  std::uint32_t triShadeStride = gpu::kTriShadeWords;  // triShadeLayout.stride()
  std::vector<gpu::Material> materials;
  std::size_t emitterCount = 0;         // emissive triangles of positive power: the light tree's leaves
  LightTree lightTree;                  // light tree over the same triangles: what the shaders sample (binding 4)
  std::vector<std::uint32_t> texels;    // RGBA8 packed as unpackUnorm4x8 reads them
  std::vector<gpu::TexInfo> texInfo;
  float totalEmitterWeight = 0.0f;      // sum of luminance(emission) * area * sides
  double totalPower = 0.0;              // emitted power, pi * luminance * area * sides (scene units)
  std::vector<CausticCaster> casters;   // caustic casters (findCausticCasters), at most CAUSTICA_MAX_CASTERS
  glm::vec4 emitterSphere{0.0f, 0.0f, 0.0f, -1.0f};  // around every emitter (emitterBoundingSphere)
  gpu::PunctualParams punctual{};       // punctual lights and their selection probabilities (a UBO)
  // The environment map and its sampling CDFs (width 0: no environment light).
  EnvironmentDistribution environment;
  gpu::EnvironmentParams environmentParams{};  // the UBO: map size, rotation, background
  // Instanced scenes (packInstancedScene; instanceCount 0: a flat scene). `nodes` then holds the
  // two-level BVH's nodes, instanceCount InstanceRecords from node instanceRecordBase, instanceCount
  // InstanceShades, and the light-leaf table from texel lightLeafTableTexel (gpu_layout.h); TriGeom and
  // TriShade hold the meshes' stored triangles in object space.
  std::uint32_t instanceCount = 0, instanceRecordBase = 0, lightLeafTableTexel = 0;
  std::uint64_t instancedTriangles = 0;  // the triangles of every instance together (what flattening makes)
  // CAUSTICA_INSTANCED and its layout constants (none for a flat scene).
  std::vector<std::string> instanceDefines() const;
};

// `triangleArrays` false leaves triGeom and triShade empty: the Renderer packs and uploads them in
// slices (packTriangleRange), so the host never holds them whole.
GpuScene packScene(const Scene& scene, const Bvh& bvh, bool triangleArrays = true);
struct InstancedBvh;
// An instanced scene (Scene::instances not empty) and its two-level BVH (tlas.h, moved from: its
// nodes, tris and instances end up in the result). Emitters are every instance's emissive triangles
// (the light tree's leaves carry the instance); casters and the emitter sphere come from the world-space
// copies of only the meshes that hold specular or emissive triangles (flattenedSubset).
GpuScene packInstancedScene(const Scene& scene, InstancedBvh& bvh);
// TriGeom records and TriShade words of triangles [first, first + count) (BVH leaf order) of a scene
// packed by packScene (it needs g.lightTree.leafOf and g.triShadeStride), into geom and shade.
void packTriangleRange(const Scene& scene, const Bvh& bvh, const GpuScene& g, std::size_t first, std::size_t count,
                       std::vector<gpu::TriGeom>& geom, std::vector<std::uint32_t>& shade);

// Vertex k's shading normal (unit, or zero where the mesh has none) and texcoord of triangle `tri`
// (BVH leaf order) as the shaders decode them from GpuScene::triShade (tri_shade.glsl).
glm::vec3 shadeNormal(const GpuScene& g, std::size_t tri, int k);
glm::vec2 shadeUv(const GpuScene& g, std::size_t tri, int k);  // (0, 0) in scenes without textures
glm::vec4 shadeColor(const GpuScene& g, std::size_t tri, int k);  // (1, 1, 1, 1) without vertex colours
glm::vec4 shadeTangent(const GpuScene& g, std::size_t tri, int k);  // (0, 0, 0, 0) without tangents

// What the scene occupies on the GPU, in bytes, by storage block (gpu/renderer.cpp uploads these).
struct GpuSceneBytes {
  std::size_t nodes = 0, triGeom = 0, triShade = 0, materials = 0, lightTree = 0, textures = 0;
  std::size_t total() const { return nodes + triGeom + triShade + materials + lightTree + textures; }
};
GpuSceneBytes gpuSceneBytes(const GpuScene& g);

}  // namespace caustica
