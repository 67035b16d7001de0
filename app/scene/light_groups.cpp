// light_groups.cpp — grouping emissive triangles into the point lights of the raster and Whitted modes.
#include "scene/light_groups.h"

#include <algorithm>
#include <cstring>
#include <map>
#include <numeric>
#include <tuple>

#include "shading/sampling.h"

namespace caustica {

namespace {

struct UnionFind {
  std::vector<std::uint32_t> parent;
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t find(std::uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void join(std::uint32_t a, std::uint32_t b) { parent[find(a)] = find(b); }
};

// Exact vertex position as a map key: triangles of one mesh share their vertices bit for bit.
std::tuple<std::uint32_t, std::uint32_t, std::uint32_t> key(const glm::vec3& p) {
  std::uint32_t x, y, z;
  std::memcpy(&x, &p.x, 4);
  std::memcpy(&y, &p.y, 4);
  std::memcpy(&z, &p.z, 4);
  return {x, y, z};
}

struct Part {  // one connected emitter mesh (or, after k-means, a cluster of them)
  std::vector<std::uint32_t> tris;
  glm::dvec3 weightedCentre{0.0};
  double power = 0.0;
  glm::dvec3 centre() const { return power > 0.0 ? weightedCentre / power : weightedCentre; }
};

}  // namespace

std::vector<LightGroup> groupEmitters(const Scene& scene, int maxLights) {
  maxLights = std::max(1, maxLights);
  std::vector<std::uint32_t> emissive;
  std::vector<double> power;
  for (std::uint32_t i = 0; i < scene.triangles.size(); ++i) {
    const Triangle& t = scene.triangles[i];
    const Material& m = scene.materials[t.material];
    if (!m.isEmissive()) continue;
    double area = 0.5 * glm::length(glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]));
    double w = luminance(glm::max(m.emission, glm::vec3(0.0f))) * area * (m.doubleSided ? 2.0 : 1.0);
    if (!(w > 0.0)) continue;
    emissive.push_back(i);
    power.push_back(w);
  }
  if (emissive.empty()) return {};

  // Connected emitter meshes: triangles that share a vertex position.
  UnionFind uf(emissive.size());
  std::map<std::tuple<std::uint32_t, std::uint32_t, std::uint32_t>, std::uint32_t> firstAt;
  for (std::uint32_t e = 0; e < emissive.size(); ++e)
    for (const glm::vec3& p : scene.triangles[emissive[e]].p) {
      auto [it, fresh] = firstAt.emplace(key(p), e);
      if (!fresh) uf.join(e, it->second);
    }
  std::map<std::uint32_t, Part> byRoot;
  for (std::uint32_t e = 0; e < emissive.size(); ++e) {
    const Triangle& t = scene.triangles[emissive[e]];
    glm::dvec3 c = (glm::dvec3(t.p[0]) + glm::dvec3(t.p[1]) + glm::dvec3(t.p[2])) / 3.0;
    Part& part = byRoot[uf.find(e)];
    part.tris.push_back(e);
    part.weightedCentre += c * power[e];
    part.power += power[e];
  }
  std::vector<Part> parts;
  for (auto& kv : byRoot) parts.push_back(std::move(kv.second));
  std::sort(parts.begin(), parts.end(), [](const Part& a, const Part& b) { return a.power > b.power; });

  // More meshes than lights: power-weighted k-means over the meshes' centres, seeded with the
  // most powerful ones.
  if (static_cast<int>(parts.size()) > maxLights) {
    std::vector<glm::dvec3> centres;
    for (int k = 0; k < maxLights; ++k) centres.push_back(parts[k].centre());
    std::vector<int> assign(parts.size(), 0);
    for (int iter = 0; iter < 16; ++iter) {
      for (size_t i = 0; i < parts.size(); ++i) {
        double best = 1e300;
        for (int k = 0; k < maxLights; ++k) {
          glm::dvec3 d = parts[i].centre() - centres[k];
          double d2 = glm::dot(d, d);
          if (d2 < best) best = d2, assign[i] = k;
        }
      }
      std::vector<glm::dvec3> sum(maxLights, glm::dvec3(0.0));
      std::vector<double> w(maxLights, 0.0);
      for (size_t i = 0; i < parts.size(); ++i) sum[assign[i]] += parts[i].weightedCentre, w[assign[i]] += parts[i].power;
      for (int k = 0; k < maxLights; ++k)
        if (w[k] > 0.0) centres[k] = sum[k] / w[k];
    }
    std::vector<Part> merged(maxLights);
    for (size_t i = 0; i < parts.size(); ++i) {
      Part& m = merged[assign[i]];
      m.tris.insert(m.tris.end(), parts[i].tris.begin(), parts[i].tris.end());
      m.weightedCentre += parts[i].weightedCentre;
      m.power += parts[i].power;
    }
    merged.erase(std::remove_if(merged.begin(), merged.end(), [](const Part& p) { return p.tris.empty(); }), merged.end());
    std::sort(merged.begin(), merged.end(), [](const Part& a, const Part& b) { return a.power > b.power; });
    parts = std::move(merged);
  }

  std::vector<LightGroup> lights;
  for (const Part& part : parts) {
    LightGroup g;
    g.position = glm::vec3(part.centre());
    g.power = part.power;
    glm::dvec3 axis(0.0);  // luminance-weighted sum of area * normal over one-sided triangles
    glm::dvec3 intensity(0.0);
    for (std::uint32_t e : part.tris) {
      const Triangle& t = scene.triangles[emissive[e]];
      const Material& m = scene.materials[t.material];
      glm::dvec3 cr = glm::cross(glm::dvec3(t.p[1]) - glm::dvec3(t.p[0]), glm::dvec3(t.p[2]) - glm::dvec3(t.p[0]));
      double area = 0.5 * glm::length(cr);
      double sides = m.doubleSided ? 2.0 : 1.0;
      intensity += glm::dvec3(glm::max(m.emission, glm::vec3(0.0f))) * area * sides;
      if (!m.doubleSided) axis += 0.5 * cr * static_cast<double>(luminance(glm::max(m.emission, glm::vec3(0.0f))));
      for (const glm::vec3& p : t.p) g.radius = std::max(g.radius, glm::length(p - g.position));
      g.triangles.push_back(emissive[e]);
    }
    // |sum of lum * area * n| / sum of lum * area * sides: 1 for a flat one-sided light, 0 for a closed one.
    double flat = part.power > 0.0 ? std::min(1.0, glm::length(axis) / part.power) : 0.0;
    g.axis = glm::length(axis) > 0.0 ? glm::vec3(glm::normalize(axis) * flat) : glm::vec3(0.0f);
    g.isotropic = static_cast<float>((1.0 - flat) / 4.0);
    g.intensity = glm::vec3(intensity);
    lights.push_back(std::move(g));
  }
  return lights;
}

}  // namespace caustica
