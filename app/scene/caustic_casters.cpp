// casters.cpp — connected components of specular triangles and their bounding spheres.
#include "scene/caustic_casters.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <unordered_map>

#include "shading/microfacet.h"

namespace caustica {

namespace {

struct UnionFind {
  std::vector<std::uint32_t> parent;
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) { parent[find(a)] = find(b); }
};

struct PositionKey {
  std::uint32_t x, y, z;
  bool operator==(const PositionKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct PositionHash {
  size_t operator()(const PositionKey& k) const {
    return (static_cast<size_t>(k.x) * 73856093u) ^ (static_cast<size_t>(k.y) * 19349663u) ^
           (static_cast<size_t>(k.z) * 83492791u);
  }
};
PositionKey keyOf(const glm::vec3& p) {
  auto bits = [](float f) {
    if (f == 0.0f) f = 0.0f;  // -0 and +0 are one position
    std::uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
  };
  return {bits(p.x), bits(p.y), bits(p.z)};
}

// Smallest sphere centred on the bounds' centre that holds every point.
glm::vec4 boundingSphere(const std::vector<glm::vec3>& points) {
  Bounds b;
  for (const auto& p : points) b.grow(p);
  glm::vec3 c = 0.5f * (b.min + b.max);
  float r2 = 0.0f;
  for (const auto& p : points) r2 = std::max(r2, glm::dot(p - c, p - c));
  return glm::vec4(c, std::sqrt(r2) * 1.0001f);  // a hair larger, so rounding cannot leave a vertex out
}

}  // namespace

std::vector<CausticCaster> findCausticCasters(const Scene& scene, int maxCasters) {
  if (maxCasters <= 0) return {};
  std::vector<std::uint32_t> tris;
  for (std::uint32_t i = 0; i < scene.triangles.size(); ++i) {
    const Triangle& t = scene.triangles[i];
    if (t.material >= scene.materials.size()) continue;
    const Material& m = scene.materials[t.material];
    if (m.metallic > 0.0f || m.transmission > 0.0f) tris.push_back(i);
  }
  if (tris.empty()) return {};

  // Triangles sharing a vertex position belong to one object (flat-shaded meshes repeat positions).
  UnionFind uf(tris.size());
  std::unordered_map<PositionKey, std::uint32_t, PositionHash> owner;
  for (std::uint32_t k = 0; k < tris.size(); ++k)
    for (const glm::vec3& p : scene.triangles[tris[k]].p) {
      auto [it, inserted] = owner.emplace(keyOf(p), k);
      if (!inserted) uf.unite(k, it->second);
    }
  std::unordered_map<std::uint32_t, std::vector<glm::vec3>> components;
  std::unordered_map<std::uint32_t, bool> refractive, smooth;
  for (std::uint32_t k = 0; k < tris.size(); ++k) {
    std::uint32_t root = uf.find(k);
    const Triangle& t = scene.triangles[tris[k]];
    const Material& m = scene.materials[t.material];
    components[root].insert(components[root].end(), std::begin(t.p), std::end(t.p));
    refractive[root] |= m.transmission > 0.0f;
    smooth[root] |= m.roughness * m.roughness < kDeltaAlpha;  // a texture only lowers roughness
  }

  float diagonal = scene.bounds.empty() ? 0.0f : glm::length(scene.bounds.max - scene.bounds.min);
  struct Object {
    glm::vec4 sphere;
    bool refractive, smooth;
    std::vector<glm::vec3> points;
  };
  std::vector<Object> objects;
  for (auto& [root, pts] : components) {
    glm::vec4 s = boundingSphere(pts);
    if (!(s.w > 0.0f) || !std::isfinite(s.w) || s.w > 0.25f * diagonal) continue;
    objects.push_back({s, refractive[root], smooth[root], std::move(pts)});
  }
  // Deterministic order whatever the hash map did: by centre, then radius.
  std::sort(objects.begin(), objects.end(), [](const Object& a, const Object& b) {
    for (int i = 0; i < 4; ++i)
      if (a.sphere[i] != b.sphere[i]) return a.sphere[i] < b.sphere[i];
    return false;
  });
  if (objects.size() <= static_cast<size_t>(maxCasters)) {
    std::vector<CausticCaster> out;
    for (const auto& o : objects) out.push_back({o.sphere, o.refractive, o.smooth});
    return out;
  }

  // Too many objects: group neighbours along the widest axis of their centres, one sphere per group.
  Bounds centres;
  for (const auto& o : objects) centres.grow(glm::vec3(o.sphere));
  glm::vec3 ext = centres.max - centres.min;
  int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
  std::stable_sort(objects.begin(), objects.end(),
                   [axis](const Object& a, const Object& b) { return a.sphere[axis] < b.sphere[axis]; });
  std::vector<CausticCaster> out;
  size_t n = objects.size();
  for (int g = 0; g < maxCasters; ++g) {
    size_t begin = n * g / maxCasters, end = n * (g + 1) / maxCasters;
    std::vector<glm::vec3> pts;
    bool refracts = false, anySmooth = false;
    for (size_t i = begin; i < end; ++i) {
      pts.insert(pts.end(), objects[i].points.begin(), objects[i].points.end());
      refracts |= objects[i].refractive;
      anySmooth |= objects[i].smooth;
    }
    if (!pts.empty()) out.push_back({boundingSphere(pts), refracts, anySmooth});
  }
  return out;
}

float triangleSolidAngle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  const double la = glm::length(glm::dvec3(a)), lb = glm::length(glm::dvec3(b)), lc = glm::length(glm::dvec3(c));
  const glm::dvec3 da(a), db(b), dc(c);
  const double num = std::abs(glm::dot(da, glm::cross(db, dc)));
  const double den = la * lb * lc + glm::dot(da, db) * lc + glm::dot(da, dc) * lb + glm::dot(db, dc) * la;
  return static_cast<float>(2.0 * std::atan2(num, den));
}

bool manifoldAutoEligible(const CausticCaster& c) {
  return c.smooth && c.emitterSolidAngle > 0.0f && c.emitterSolidAngle < kManifoldAutoSolidAngle;
}

void rateCastersForManifold(std::vector<CausticCaster>& casters, const Scene& emitters) {
  for (CausticCaster& c : casters) {
    const glm::vec3 centre(c.sphere);
    double sum = 0.0;
    for (const Triangle& t : emitters.triangles) {
      if (t.material >= emitters.materials.size() || !emitters.materials[t.material].isEmissive()) continue;
      const glm::vec3 a = t.p[0] - centre, b = t.p[1] - centre, d = t.p[2] - centre;
      const glm::vec3 n = glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]);  // the emitting (front) side
      if (!emitters.materials[t.material].doubleSided && !(glm::dot(n, -(a + b + d)) > 0.0f)) continue;
      sum += triangleSolidAngle(a, b, d);
    }
    c.emitterSolidAngle = static_cast<float>(sum);
    c.manifoldAuto = manifoldAutoEligible(c);
  }
}

glm::vec4 emitterBoundingSphere(const Scene& scene) {
  std::vector<glm::vec3> pts;
  for (const Triangle& t : scene.triangles)
    if (t.material < scene.materials.size() && scene.materials[t.material].isEmissive())
      pts.insert(pts.end(), std::begin(t.p), std::end(t.p));
  if (pts.empty()) return glm::vec4(0.0f, 0.0f, 0.0f, -1.0f);
  return boundingSphere(pts);
}

}  // namespace caustica
