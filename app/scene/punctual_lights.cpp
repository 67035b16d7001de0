// punctual_lights.cpp — KHR_lights_punctual lights: spot falloff, power, GPU packing with
// power-proportional selection, and --light-radius (point and spot lights as small emissive spheres).
#include "scene/punctual_lights.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>

#include "scene/scene.h"
#include "shading/sampling.h"
#include "util/error.h"
#include "util/math_constants.h"

namespace caustica {

const char* punctualTypeName(PunctualType t) {
  switch (t) {
    case PunctualType::Point: return "point";
    case PunctualType::Spot: return "spot";
    case PunctualType::Directional: return "directional";
  }
  return "?";
}

float spotFalloff(float cosTheta, float cosOuter, float cosInner) {
  const float scale = 1.0f / std::max(1.0e-3f, cosInner - cosOuter);
  const float t = std::clamp((cosTheta - cosOuter) * scale, 0.0f, 1.0f);
  return t * t;
}

double punctualPower(const PunctualLight& light, const Bounds& bounds) {
  const double i = std::max(0.0, double(luminance(glm::max(light.intensity, glm::vec3(0.0f)))));
  switch (light.type) {
    case PunctualType::Point: return 4.0 * kPiD * i;
    case PunctualType::Spot:
      return 2.0 * kPiD * i * (1.0 - 0.5 * (std::cos(double(light.innerCone)) + std::cos(double(light.outerCone))));
    case PunctualType::Directional: {
      double r = bounds.empty() ? 1.0 : 0.5 * glm::length(glm::dvec3(bounds.max) - glm::dvec3(bounds.min));
      if (!(r > 0.0) || !std::isfinite(r)) r = 1.0;
      return kPiD * r * r * i;
    }
  }
  return 0.0;
}

gpu::PunctualParams packPunctualLights(const std::vector<PunctualLight>& lights, const Bounds& bounds,
                                       const std::string& path) {
  if (lights.size() > CAUSTICA_MAX_PUNCTUAL)
    throw Error(path + ": the scene has " + std::to_string(lights.size()) + " punctual lights; caustica renders at most " +
                std::to_string(CAUSTICA_MAX_PUNCTUAL));
  gpu::PunctualParams p{};
  std::vector<double> power(lights.size());
  double total = 0.0;
  for (std::size_t i = 0; i < lights.size(); ++i) total += power[i] = punctualPower(lights[i], bounds);
  if (!(total > 0.0) || !std::isfinite(total)) return p;  // no light emits: nothing to sample
  double cumulative = 0.0;
  std::uint32_t n = 0;
  for (std::size_t i = 0; i < lights.size(); ++i) {
    if (!(power[i] > 0.0)) continue;  // never chosen: left out
    const PunctualLight& l = lights[i];
    gpu::PunctualLight& g = p.light[n++];
    std::uint32_t type = l.type == PunctualType::Point ? gpu::kPunctualPoint
                         : l.type == PunctualType::Spot ? gpu::kPunctualSpot
                                                        : gpu::kPunctualDirectional;
    g.position = glm::vec4(l.position, float(type));
    g.direction = glm::vec4(glm::normalize(l.direction), std::cos(l.outerCone));
    g.intensity = glm::vec4(glm::max(l.intensity, glm::vec3(0.0f)), std::cos(l.innerCone));
    cumulative += power[i];
    g.select = glm::vec4(float(power[i] / total), float(cumulative / total), 0.0f, 0.0f);
  }
  p.light[n - 1].select.y = 1.0f;  // exactly 1, so every u in [0, 1) finds a light
  p.count.x = n;
  return p;
}

namespace {
// Unit icosphere: the icosahedron subdivided twice (320 triangles), outward counter-clockwise fronts.
std::vector<std::array<glm::vec3, 3>> unitIcosphere() {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<glm::vec3> v = {{-1, t, 0}, {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                              {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},   {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : v) p = glm::normalize(p);
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < 2; ++level) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back(glm::normalize(v[std::size_t(a)] + v[std::size_t(b)]));
      return mid[key] = int(v.size()) - 1;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& tri : f) {
      int a = midpoint(tri[0], tri[1]), b = midpoint(tri[1], tri[2]), c = midpoint(tri[2], tri[0]);
      next.push_back({tri[0], a, c});
      next.push_back({tri[1], b, a});
      next.push_back({tri[2], c, b});
      next.push_back({a, b, c});
    }
    f = std::move(next);
  }
  std::vector<std::array<glm::vec3, 3>> out;
  for (const auto& tri : f) {
    std::array<glm::vec3, 3> q = {v[std::size_t(tri[0])], v[std::size_t(tri[1])], v[std::size_t(tri[2])]};
    if (glm::dot(glm::cross(q[1] - q[0], q[2] - q[0]), q[0] + q[1] + q[2]) < 0.0f) std::swap(q[1], q[2]);
    out.push_back(q);
  }
  return out;
}
}  // namespace

void applyLightRadius(Scene& scene, float radius) {
  if (!(radius > 0.0f) || !std::isfinite(radius)) throw Error("--light-radius needs a positive number of scene units");
  static const std::vector<std::array<glm::vec3, 3>> sphere = unitIcosphere();
  std::vector<PunctualLight> kept;
  for (const PunctualLight& l : scene.punctualLights) {
    if (l.type == PunctualType::Directional) {
      kept.push_back(l);
      continue;
    }
    // Same power as the point light: a convex Lambertian emitter of radiance L and area A emits
    // pi L A; a point light of intensity I emits 4 pi I, so L = 4 I / A (= I / (pi R^2) for a true sphere).
    double area = 0.0;
    for (const auto& q : sphere)
      area += 0.5 * double(glm::length(glm::cross(q[1] - q[0], q[2] - q[0]))) * double(radius) * double(radius);
    Material m;
    m.name = "light-radius sphere of " + l.name;
    m.baseColor = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
    m.emission = glm::vec3(glm::dvec3(l.intensity) * (4.0 / area));
    const auto material = static_cast<std::uint32_t>(scene.materials.size());
    scene.materials.push_back(m);
    if (l.type == PunctualType::Spot)
      scene.spotEmitters.push_back({material, glm::normalize(l.direction), std::cos(l.innerCone), std::cos(l.outerCone)});
    for (const auto& q : sphere) {
      Triangle t{};
      for (int k = 0; k < 3; ++k) {
        t.p[k] = l.position + radius * q[std::size_t(k)];
        t.setNormal(k, q[std::size_t(k)]);
        scene.bounds.grow(t.p[k]);
      }
      t.material = material;
      scene.triangles.push_back(t);
      if (!scene.texcoords.empty()) scene.texcoords.emplace_back();  // (0, 0): the sphere reads no texture
      if (!scene.colors.empty()) scene.colors.emplace_back();        // white
      if (!scene.tangents.empty()) scene.tangents.emplace_back();    // none
    }
  }
  scene.punctualLights = std::move(kept);
}

}  // namespace caustica
