// gpu_scene.h — packs a Scene and its BVH into the arrays the shaders read (gpu_layout.h), builds
// the emitter alias table, and decides which shader features the scene needs.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "accel/bvh.h"
#include "scene/caustic_casters.h"
#include "scene/scene.h"

namespace caustica {

// What the scene's materials need; each maps to one CAUSTICA_* shader define.
struct SceneFeatures {
  bool mirror = false, glass = false, volume = false, dispersion = false, textures = false, opacity = false;
  bool punctual = false;      // KHR_lights_punctual lights: CAUSTICA_PUNCTUAL (their NEE, in both integrators)
  bool spotEmitters = false;  // --light-radius spheres of spot lights: CAUSTICA_SPOT_EMITTERS
  std::vector<std::string> defines() const;  // material defines only (not integrator or dispersion mode)
  std::string describe() const;              // e.g. "mirror glass dispersion" or "diffuse only"
};
SceneFeatures sceneFeatures(const Scene& scene);

struct GpuScene {
  std::vector<gpu::BvhNode> nodes;
  std::vector<gpu::TriGeom> triGeom;    // BVH leaf order
  std::vector<gpu::TriShade> triShade;  // BVH leaf order
  std::vector<gpu::Material> materials;
  std::vector<gpu::Emitter> emitters;   // alias table, one slot per emissive triangle
  std::vector<std::uint32_t> texels;    // RGBA8 packed as unpackUnorm4x8 reads them
  std::vector<gpu::TexInfo> texInfo;
  float totalEmitterWeight = 0.0f;      // sum of luminance(emission) * area * sides
  double totalPower = 0.0;              // emitted power, pi * luminance * area * sides (scene units)
  std::vector<CausticCaster> casters;   // caustic casters (findCausticCasters), at most CAUSTICA_MAX_CASTERS
  glm::vec4 emitterSphere{0.0f, 0.0f, 0.0f, -1.0f};  // around every emitter (emitterBoundingSphere)
  gpu::PunctualParams punctual{};       // punctual lights and their selection probabilities (a UBO)
  SceneFeatures features;
};

GpuScene packScene(const Scene& scene, const Bvh& bvh);

// Vose's alias table over `weights` (non-negative, not all zero). Slot i holds item `items[i]`.
std::vector<gpu::Emitter> buildAliasTable(const std::vector<double>& weights, const std::vector<std::uint32_t>& items);

}  // namespace caustica
