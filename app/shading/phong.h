// phong.h — C++ twins of glsl/lib/point_lights.glsl (same names, same arithmetic): the radiant
// intensity of a grouped point light and the Phong BRDF of the raster and Whitted modes.
#pragma once
#include <glm/glm.hpp>

#include "shared/gpu_layout.h"

namespace caustica {

// Radiant intensity (per channel, W sr^-1) of light l towards unit direction w leaving it.
glm::vec3 pointLightIntensity(const gpu::PointLight& l, const glm::vec3& w);
// Lambert base / pi plus a normalised Blinn-Phong highlight (Fresnel 0.04) with exponent
// 2 / roughness^2 - 2 (at most 4096); none at roughness 1. Per steradian; n, wl, wv unit.
glm::vec3 phongBrdf(const glm::vec3& base, float roughness, const glm::vec3& n, const glm::vec3& wl, const glm::vec3& wv);

}  // namespace caustica
