// phong.cpp — the point-light lobe and Phong BRDF of the raster and Whitted modes (twins of point_lights.glsl).
#include "shading/phong.h"

#include "scene/punctual_lights.h"

#include <algorithm>
#include <cmath>

namespace caustica {

glm::vec3 pointLightIntensity(const gpu::PointLight& l, const glm::vec3& w) {
  if (l.cone.z > 0.5f) return glm::vec3(l.intensity) * spotFalloff(glm::dot(glm::vec3(l.axis), w), l.cone.x, l.cone.y);
  return glm::vec3(l.intensity) * (std::max(0.0f, glm::dot(glm::vec3(l.axis), w)) + l.position.w);
}

glm::vec3 phongBrdf(const glm::vec3& base, float roughness, const glm::vec3& n, const glm::vec3& wl, const glm::vec3& wv) {
  glm::vec3 f = base * 0.31830988618379067154f;
  if (roughness < 1.0f) {
    float shininess = std::min(2.0f / std::max(roughness * roughness, 1.0e-4f) - 2.0f, 4096.0f);
    glm::vec3 h = glm::normalize(wl + wv);
    f += glm::vec3(0.04f * (shininess + 8.0f) / (8.0f * 3.14159265358979323846f) *
                   std::pow(std::max(glm::dot(n, h), 0.0f), shininess));
  }
  return f;
}

}  // namespace caustica
