// light_groups.h — the point lights of the raster and Whitted modes: emissive triangles grouped by
// connected emitter mesh (then k-means when there are more meshes than lights) into a few lights at
// their power-weighted centres, each with a lobe that keeps a flat light's cosine falloff. No GL.
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace caustica {

struct LightGroup {
  glm::vec3 position{0.0f};       // power-weighted centre of the group's triangles (world space)
  glm::vec3 intensity{0.0f};      // sum of emitted radiance * area (* 2 double-sided): W sr^-1 along the axis
  glm::vec3 axis{0.0f};           // mean emitter normal; its length (0..1) is the flat part of the lobe
  float isotropic = 0.0f;         // (1 - |axis|) / 4: the part a closed emitter sends evenly
  float radius = 0.0f;            // farthest group vertex from `position` (scene units)
  double power = 0.0;             // luminance * area * sides summed (the grouping weight)
  std::vector<std::uint32_t> triangles;  // indices into Scene::triangles
  // Radiant intensity (per channel) towards unit direction w from the light.
  glm::vec3 intensityTowards(const glm::vec3& w) const {
    return intensity * (glm::max(0.0f, glm::dot(axis, w)) + isotropic);
  }
};

// At most `maxLights` groups (1..CAUSTICA_MAX_POINT_LIGHTS), most powerful first; empty when
// nothing emits. Emission textures are ignored (the factor alone sets the power).
std::vector<LightGroup> groupEmitters(const Scene& scene, int maxLights);

}  // namespace caustica
