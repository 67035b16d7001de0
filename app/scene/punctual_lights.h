// punctual_lights.h — glTF KHR_lights_punctual lights (point, spot, directional) in the scene model,
// their packing for the GPU (power-proportional selection) and --light-radius (spheres of emitters).
// Units: intensity in caustica radiance units times area (1 cd = 1 unit; docs/path-tracer.md "Punctual lights").
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "shared/gpu_layout.h"

namespace caustica {

struct Scene;
struct Bounds;

enum class PunctualType { Point, Spot, Directional };
const char* punctualTypeName(PunctualType t);

// One light instance: a glTF light placed by a node (the light shines down the node's -Z).
struct PunctualLight {
  std::string name;                   // light name, else "lights[i]"
  PunctualType type = PunctualType::Point;
  glm::vec3 position{0.0f};           // world space (after the scene's rebase); unused for directional
  glm::vec3 direction{0.0f, 0.0f, -1.0f};  // unit, world space: where the light shines (spot axis, sun rays)
  // color * intensity. Point and spot: luminous intensity in cd, taken as radiant intensity (radiance
  // units x area) with factor 1, so irradiance at distance d is intensity / d^2. Directional:
  // illuminance in lux, taken as irradiance on a surface facing the light.
  glm::vec3 intensity{1.0f};
  float innerCone = 0.0f;             // spot: radians, 0 <= inner < outer <= pi/2
  float outerCone = 0.7853982f;       // spot: radians
};

// A sphere emitter made from a spot light by --light-radius: its triangles use material `material`,
// whose emission is weighted by the spot's cone falloff in the direction it leaves the sphere.
struct SpotEmitter {
  std::uint32_t material = 0;
  glm::vec3 axis{0.0f, 0.0f, -1.0f};  // unit, world space
  float cosInner = 1.0f, cosOuter = 0.0f;
};

// glTF's recommended smooth spot falloff (KHR_lights_punctual): 0 outside the outer cone, 1 inside the
// inner one, a squared linear ramp in cos(angle) between. Twin of spotFalloff in glsl/lib/punctual.glsl.
float spotFalloff(float cosTheta, float cosOuter, float cosInner);

// Power (luminance of emitted flux) of one light, used for selection: point 4 pi I, spot
// 2 pi I (1 - (cos inner + cos outer) / 2) (pbrt-v4's estimate of the smooth cone), directional
// E pi r^2 with r the radius of the scene's bounding sphere.
double punctualPower(const PunctualLight& light, const Bounds& bounds);

// The lights in the UBO layout with their selection probabilities (proportional to power).
// Throws Error naming `path` if there are more than CAUSTICA_MAX_PUNCTUAL.
gpu::PunctualParams packPunctualLights(const std::vector<PunctualLight>& lights, const Bounds& bounds,
                                       const std::string& path);

// --light-radius R: replaces every point and spot light by a sphere of emissive triangles (an
// icosphere of 320 triangles, radius R, black) emitting the same power, so bounces can hit it and
// caustics of those lights appear. Spot spheres emit with the spot's falloff (SpotEmitter).
// Directional lights stay as they are. R must be > 0 (throws Error otherwise).
void applyLightRadius(Scene& scene, float radius);

}  // namespace caustica
