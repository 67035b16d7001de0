// scene_builder.h — how the GL tests build scenes in memory: materials by kind, quads, boxes and UV
// spheres (counter-clockwise fronts, flat or radial normals), meshes of instanced scenes, cameras, and
// the bounds a finished scene needs. World space, scene units; radiance and albedo linear.
#pragma once
#include <array>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "scene/scene.h"
#include "util/math_constants.h"

namespace caustica::test {

// A Lambertian material of the given albedo, emitting `emission` (radiance) where it is non-zero.
inline Material diffuseMaterial(glm::vec3 albedo, glm::vec3 emission = glm::vec3(0.0f)) {
  Material m;
  m.baseColor = glm::vec4(albedo, 1.0f);
  m.emission = emission;
  return m;
}
inline Material diffuseMaterial(float albedo, float emission = 0.0f) {
  return diffuseMaterial(glm::vec3(albedo), glm::vec3(emission));
}

// An emitter of radiance `radiance` that reflects nothing (black base colour).
inline Material emitterMaterial(glm::vec3 radiance) { return diffuseMaterial(glm::vec3(0.0f), radiance); }
inline Material emitterMaterial(float radiance) { return emitterMaterial(glm::vec3(radiance)); }

// Clear glass of index `ior` (at 587.6 nm): white base colour, full transmission, smooth.
inline Material glassMaterial(float ior = 1.5f) {
  Material m;
  m.transmission = 1.0f;
  m.ior = ior;
  return m;
}

// A metal reflecting `color`, of GGX roughness `roughness` (0: a mirror).
inline Material metalMaterial(glm::vec3 color, float roughness = 0.0f) {
  Material m;
  m.baseColor = glm::vec4(color, 1.0f);
  m.metallic = 1.0f;
  m.roughness = roughness;
  return m;
}

// Appends a material; returns its index for the shapes below.
inline std::uint32_t addMaterial(Scene& s, const Material& m) {
  s.materials.push_back(m);
  return static_cast<std::uint32_t>(s.materials.size() - 1);
}

// A quad as two triangles with flat normals; a, b, c, d counter-clockwise seen from its front.
inline void addQuad(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, std::uint32_t material) {
  glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
  for (auto tri : {std::array<glm::vec3, 3>{a, b, c}, std::array<glm::vec3, 3>{a, c, d}}) {
    Triangle t{};
    for (int i = 0; i < 3; ++i) {
      t.p[i] = tri[i];
      t.setNormal(i, n);
    }
    t.material = material;
    s.triangles.push_back(t);
  }
}

// An axis-aligned box between lo and hi of six flat quads (-x, +x, -y, +y, -z, +z), fronts outwards,
// or inwards (seen from inside: an enclosure).
inline void addBox(Scene& s, glm::vec3 lo, glm::vec3 hi, std::uint32_t material, bool inward = false) {
  glm::vec3 p[8];
  for (int i = 0; i < 8; ++i) p[i] = glm::vec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
  const int faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : faces) {
    if (inward) addQuad(s, p[f[0]], p[f[3]], p[f[2]], p[f[1]], material);
    else addQuad(s, p[f[0]], p[f[1]], p[f[2]], p[f[3]], material);
  }
}

// A UV sphere of 2 * segments^2 triangles with smooth (radial) normals, outward fronts.
inline void addSphere(Scene& s, glm::vec3 center, float radius, int segments, std::uint32_t material) {
  auto point = [&](int i, int j) {
    float theta = kPi * i / segments, phi = 2 * kPi * j / (2 * segments);
    return glm::vec3(std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi));
  };
  for (int i = 0; i < segments; ++i)
    for (int j = 0; j < 2 * segments; ++j) {
      glm::vec3 q[4] = {point(i, j), point(i + 1, j), point(i + 1, j + 1), point(i, j + 1)};
      for (auto idx : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
        Triangle t{};
        for (int k = 0; k < 3; ++k) {
          t.setNormal(k, q[idx[k]]);
          t.p[k] = center + radius * q[idx[k]];
        }
        if (glm::length(glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0])) == 0.0f) continue;  // pole slivers
        t.material = material;
        s.triangles.push_back(t);
      }
    }
}

// Sets the scene's bounds to those of its triangles (call once the triangles are in).
inline void finishBounds(Scene& s) {
  s.bounds = Bounds{};
  for (const Triangle& t : s.triangles)
    for (const glm::vec3& p : t.p) s.bounds.grow(p);
}

// Makes the triangles that add() appends one mesh (Scene::meshes) of an instanced scene; returns its index.
template <class Add>
std::uint32_t addMesh(Scene& s, Add&& add) {
  MeshRange r;
  r.firstTriangle = static_cast<std::uint32_t>(s.triangles.size());
  add();
  r.triangleCount = static_cast<std::uint32_t>(s.triangles.size()) - r.firstTriangle;
  s.meshes.push_back(r);
  return static_cast<std::uint32_t>(s.meshes.size() - 1);
}

// Sets an instanced scene's bounds to those of its instances' world-space triangles.
inline void finishInstancedBounds(Scene& s) {
  s.bounds = Bounds{};
  for (const Instance& in : s.instances) {
    const MeshRange& m = s.meshes[in.mesh];
    for (std::uint32_t i = m.firstTriangle; i < m.firstTriangle + m.triangleCount; ++i)
      for (const glm::vec3& p : s.triangles[i].p) s.bounds.grow(glm::vec3(in.world * glm::dvec4(glm::dvec3(p), 1.0)));
  }
}

// A camera at `position` looking along `forward` with `up` (both taken as given), vertical field of
// view yfov (radians).
inline Camera cameraAt(glm::vec3 position, glm::vec3 forward, glm::vec3 up, float yfov) {
  Camera c;
  c.position = position;
  c.forward = forward;
  c.up = up;
  c.yfov = yfov;
  return c;
}

// A camera at `eye` looking at `target`, its up the world's +y made orthogonal to the view (or -z
// when looking straight up or down), vertical field of view yfov (radians).
inline Camera lookAt(glm::vec3 eye, glm::vec3 target, float yfov) {
  Camera c;
  c.position = eye;
  c.forward = glm::normalize(target - eye);
  glm::vec3 worldUp = std::abs(c.forward.y) > 0.99f ? glm::vec3(0, 0, -1) : glm::vec3(0, 1, 0);
  c.up = glm::normalize(glm::cross(glm::cross(c.forward, worldUp), c.forward));
  c.yfov = yfov;
  return c;
}

// A glass ball far under a 16-cm lamp (0.007 sr from its centre: --manifold auto takes it) and a mirror
// ball close beside the lamp (0.04 sr: auto leaves it), over a diffuse floor, with a camera: the scene
// where auto sends photons through some casters only.
inline Scene lampOverGlassAndMirror() {
  Scene s;
  Material mirror = diffuseMaterial(0.9f);
  mirror.metallic = 1.0f;
  s.materials = {diffuseMaterial(0.8f), emitterMaterial(60.0f), glassMaterial(1.5f), mirror};
  addQuad(s, {-1.5f, 0, 1.5f}, {1.5f, 0, 1.5f}, {1.5f, 0, -1.5f}, {-1.5f, 0, -1.5f}, 0);
  const float h = 0.08f;
  addQuad(s, {-h, 2.5f, -h}, {h, 2.5f, -h}, {h, 2.5f, h}, {-h, 2.5f, h}, 1);
  addSphere(s, {0.0f, 0.62f, 0.0f}, 0.3f, 24, 2);
  addSphere(s, {0.5f, 2.0f, 0.0f}, 0.15f, 16, 3);
  finishBounds(s);
  s.cameras.push_back(lookAt({0.0f, 1.4f, 1.9f}, {0.0f, 0.0f, 0.0f}, 0.9f));
  return s;
}

}  // namespace caustica::test
