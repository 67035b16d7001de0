// light_groups_test.cpp — the point lights of the raster and Whitted modes: emitters grouped by mesh,
// power-weighted centres, lobes, k-means past the light limit, power kept.
#include <doctest/doctest.h>

#include <array>

#include "scene/light_groups.h"

using namespace caustica;

namespace {

void quad(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, std::uint32_t material) {
  for (auto tri : {std::array<glm::vec3, 3>{a, b, c}, std::array<glm::vec3, 3>{a, c, d}})
    s.triangles.push_back(makeTriangle(tri[0], tri[1], tri[2], material));
}

// A downward-facing square light of side 2h centred at c.
void light(Scene& s, glm::vec3 c, float h, std::uint32_t material) {
  quad(s, c + glm::vec3(-h, 0, -h), c + glm::vec3(h, 0, -h), c + glm::vec3(h, 0, h), c + glm::vec3(-h, 0, h), material);
}

Scene baseScene() {
  Scene s;
  Material diffuse;
  Material emitter;
  emitter.emission = glm::vec3(4.0f, 2.0f, 1.0f);
  s.materials = {diffuse, emitter};
  quad(s, {-5, 0, 5}, {5, 0, 5}, {5, 0, -5}, {-5, 0, -5}, 0);  // a floor that does not emit
  return s;
}

}  // namespace

TEST_CASE("light groups: one flat light is one point light at its centre with its cosine lobe") {
  Scene s = baseScene();
  light(s, {1.0f, 3.0f, -2.0f}, 0.25f, 1);
  auto g = groupEmitters(s, 8);
  REQUIRE(g.size() == 1);
  CHECK(g[0].position.x == doctest::Approx(1.0f));
  CHECK(g[0].position.y == doctest::Approx(3.0f));
  CHECK(g[0].position.z == doctest::Approx(-2.0f));
  CHECK(g[0].triangles.size() == 2);
  // Radiance times area: (4, 2, 1) * 0.25; facing -y (the quad is clockwise seen from above).
  CHECK(g[0].intensity.r == doctest::Approx(1.0f));
  CHECK(g[0].intensity.b == doctest::Approx(0.25f));
  CHECK(g[0].axis.y == doctest::Approx(-1.0f));
  CHECK(g[0].isotropic == doctest::Approx(0.0f));
  // Intensity straight down is L * A, at 60 degrees half of it, upwards none.
  CHECK(g[0].intensityTowards({0, -1, 0}).r == doctest::Approx(1.0f));
  CHECK(g[0].intensityTowards(glm::normalize(glm::vec3(std::sqrt(3.0f), -1.0f, 0.0f))).r == doctest::Approx(0.5f));
  CHECK(g[0].intensityTowards({0, 1, 0}).r == doctest::Approx(0.0f));
}

TEST_CASE("light groups: a closed emitter shines evenly with a quarter of L * A") {
  Scene s = baseScene();
  // A unit cube with outward faces (each quad counter-clockwise seen from outside).
  glm::vec3 o(0, 2, 0);
  auto v = [&](float x, float y, float z) { return o + glm::vec3(x, y, z); };
  quad(s, v(0, 0, 1), v(1, 0, 1), v(1, 1, 1), v(0, 1, 1), 1);  // +z
  quad(s, v(1, 0, 0), v(0, 0, 0), v(0, 1, 0), v(1, 1, 0), 1);  // -z
  quad(s, v(1, 0, 1), v(1, 0, 0), v(1, 1, 0), v(1, 1, 1), 1);  // +x
  quad(s, v(0, 0, 0), v(0, 0, 1), v(0, 1, 1), v(0, 1, 0), 1);  // -x
  quad(s, v(0, 1, 1), v(1, 1, 1), v(1, 1, 0), v(0, 1, 0), 1);  // +y
  quad(s, v(0, 0, 0), v(1, 0, 0), v(1, 0, 1), v(0, 0, 1), 1);  // -y
  auto g = groupEmitters(s, 8);
  REQUIRE(g.size() == 1);
  CHECK(glm::length(g[0].axis) == doctest::Approx(0.0f).epsilon(1e-5));
  CHECK(g[0].isotropic == doctest::Approx(0.25f));
  CHECK(g[0].position.y == doctest::Approx(2.5f));
  // Six faces of area 1: L * A = 24 in red; a quarter of it in every direction.
  CHECK(g[0].intensityTowards({1, 0, 0}).r == doctest::Approx(6.0f));
}

TEST_CASE("light groups: separate meshes are separate lights; past the limit k-means keeps the power") {
  Scene s = baseScene();
  for (int i = 0; i < 12; ++i) light(s, {static_cast<float>(i % 4) * 3.0f, 4.0f, static_cast<float>(i / 4) * 3.0f}, 0.1f, 1);
  auto all = groupEmitters(s, 16);
  CHECK(all.size() == 12);
  auto g = groupEmitters(s, 8);
  REQUIRE(g.size() == 8);
  double total = 0.0;
  size_t tris = 0;
  for (const auto& l : g) total += l.intensity.r, tris += l.triangles.size();
  CHECK(total == doctest::Approx(12 * 4.0 * 0.04));
  CHECK(tris == 24);
  for (const auto& l : g) CHECK(l.position.y == doctest::Approx(4.0f));
  CHECK(groupEmitters(baseScene(), 8).empty());
}
