// environment_sampling.h — C++ twin of glsl/lib/environment.glsl (same names, same arithmetic):
// equirectangular lookup and importance sampling of an environment map by a piecewise-constant 2-D
// distribution on luminance x sin(theta) (marginal CDF over rows, conditional CDFs within rows).
// Directions are unit world-space vectors (glTF axes); pdfs are per steradian.
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "scene/environment.h"

namespace caustica {

// What the shader reads from its two textures, as vectors (row 0 = top of the map, v = 0).
struct EnvironmentDistribution {
  int width = 0, height = 0;
  std::vector<float> rgb;             // width * height * 3 radiance (the map's texels)
  std::vector<float> conditionalCdf;  // width * height: sum of weights of texels 0..x of row y / row sum (last = 1)
  std::vector<float> marginalCdf;     // height: sum of row sums of rows 0..y / total (last = 1)
  float cosRotation = 1.0f, sinRotation = 0.0f;  // the map's rotation about +Y
};
// The sampling weight of texel (x, y) is luminance(rgb) * sin(theta at the row's centre). Throws
// Error if the map is empty or larger than 16384 texels a side.
EnvironmentDistribution buildEnvironmentDistribution(const Environment& env);

// Map coordinates (u, v) in [0,1]^2 of world direction d under the rotation (cos, sin) about +Y.
glm::vec2 envDirectionToUv(const glm::vec3& d, float cosRot, float sinRot);
// The world direction at map coordinates uv (inverse of envDirectionToUv).
glm::vec3 envUvToDirection(const glm::vec2& uv, float cosRot, float sinRot);
// Radiance arriving along -d, i.e. seen looking in direction d (nearest texel: piecewise constant,
// like the sampling distribution).
glm::vec3 environmentRadiance(const EnvironmentDistribution& e, const glm::vec3& d);
// Solid-angle density of sampleEnvironment at direction d.
float environmentPdf(const EnvironmentDistribution& e, const glm::vec3& d);
// Draws a direction from two uniform numbers in [0,1): dir, its radiance and its pdf (per sr).
// False (nothing drawn) only for a direction at a pole, where the density is undefined.
bool sampleEnvironment(const EnvironmentDistribution& e, const glm::vec2& u, glm::vec3& dir, glm::vec3& le, float& pdf);

}  // namespace caustica
