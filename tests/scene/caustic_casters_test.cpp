// casters_test.cpp — findCausticCasters: one bounding sphere per glass or mirror object, none for
// diffuse scenes or oversized mirrors, and grouping when there are more objects than the shader takes.
#include <doctest/doctest.h>

#include "scene/assets.h"
#include "scene/caustic_casters.h"
#include "accel/bvh.h"
#include "accel/gpu_scene.h"
#include "shading/sampling.h"
#include "shared/gpu_layout.h"

using namespace caustica;

static_assert(CasterVertex::kMax == CAUSTICA_MAX_CASTERS, "the C++ twin must hold as many casters as the shader");

namespace {
bool holds(const CausticCaster& c, const glm::vec3& p) {
  return glm::length(p - glm::vec3(c.sphere)) <= c.sphere.w * (1.0f + 1e-5f);
}

// A small tetrahedron-ish pair of triangles sharing an edge, centred at c.
void addObject(Scene& scene, const glm::vec3& c, std::uint32_t material) {
  glm::vec3 a = c + glm::vec3(-0.05f, 0, 0), b = c + glm::vec3(0.05f, 0, 0), d = c + glm::vec3(0, 0.05f, 0),
            e = c + glm::vec3(0, 0, 0.05f);
  Triangle t1{}, t2{};
  t1.p[0] = a; t1.p[1] = b; t1.p[2] = d;
  t2.p[0] = b; t2.p[1] = a; t2.p[2] = e;  // shares the edge a-b
  t1.material = t2.material = material;
  scene.triangles.push_back(t1);
  scene.triangles.push_back(t2);
  for (const auto& t : {t1, t2})
    for (const auto& p : t.p) scene.bounds.grow(p);
}
}  // namespace

TEST_CASE("casters of the bundled scenes: the glass and mirror spheres, nothing in diffuse scenes") {
  Scene glass = loadScene(resolveScenePath("cornell-glass"));
  std::vector<CausticCaster> c = findCausticCasters(glass, CAUSTICA_MAX_CASTERS);
  REQUIRE(c.size() == 2);
  for (const auto& k : c) {
    CHECK(k.sphere.w == doctest::Approx(0.35).epsilon(0.02));  // both spheres have radius 0.35 (scripts/make-assets)
    CHECK(k.sphere.y == doctest::Approx(k.sphere.w).epsilon(0.02));  // resting on the floor
  }
  CHECK(c[0].refractive != c[1].refractive);  // one glass, one mirror
  for (const auto& t : glass.triangles) {
    const Material& m = glass.materials[t.material];
    if (m.metallic > 0.0f || m.transmission > 0.0f)
      for (const auto& p : t.p) CHECK((holds(c[0], p) || holds(c[1], p)));
  }
  CHECK(findCausticCasters(loadScene(resolveScenePath("cornell-dispersion")), CAUSTICA_MAX_CASTERS).size() == 2);
  CHECK(findCausticCasters(loadScene(resolveScenePath("cornell-box")), CAUSTICA_MAX_CASTERS).empty());
  GpuScene g = packScene(glass, buildBvh(glass.triangles));
  CHECK(g.casters.size() == 2);
  // The light (a 0.5 x 0.4 quad at the ceiling, y = 1.98) is inside the emitter sphere.
  CHECK(g.emitterSphere.w == doctest::Approx(std::sqrt(0.25 * 0.25 + 0.2 * 0.2)).epsilon(0.01));
  CHECK(g.emitterSphere.y == doctest::Approx(1.98).epsilon(0.01));
}

TEST_CASE("casters: more objects than the shader takes are grouped, every vertex stays covered") {
  Scene scene;
  Material diffuse, glass;
  glass.transmission = 1.0f;
  scene.materials = {diffuse, glass};
  for (int i = 0; i < 20; ++i) addObject(scene, glm::vec3(0.3f * i, 0.1f * (i % 3), 0.0f), 1);
  addObject(scene, glm::vec3(0.0f, 2.0f, 0.0f), 0);  // diffuse: ignored
  std::vector<CausticCaster> c = findCausticCasters(scene, CAUSTICA_MAX_CASTERS);
  REQUIRE(c.size() == CAUSTICA_MAX_CASTERS);
  for (const auto& t : scene.triangles) {
    if (t.material != 1) continue;
    for (const auto& p : t.p) {
      bool covered = false;
      for (const auto& s : c) covered |= holds(s, p);
      CHECK(covered);
    }
  }
  std::vector<CausticCaster> few = findCausticCasters(scene, 40);
  CHECK(few.size() == 20);  // one per object when they fit
  CHECK(few == findCausticCasters(scene, 40));  // deterministic
}

TEST_CASE("casters: a mirror wall wider than a quarter of the scene is not a caster") {
  Scene scene;
  Material mirror;
  mirror.metallic = 1.0f;
  scene.materials = {mirror};
  Triangle t{};
  t.p[0] = glm::vec3(-1, 0, -1); t.p[1] = glm::vec3(1, 0, -1); t.p[2] = glm::vec3(0, 0, 1);
  scene.triangles.push_back(t);
  for (const auto& p : t.p) scene.bounds.grow(p);
  scene.bounds.grow(glm::vec3(0, 2, 0));
  CHECK(findCausticCasters(scene, CAUSTICA_MAX_CASTERS).empty());
}
