// casters_test.cpp — findCausticCasters: one bounding sphere per glass or mirror object, none for
// diffuse scenes or oversized mirrors, and grouping when there are more objects than the shader takes.
#include <doctest/doctest.h>

#include <glm/gtc/constants.hpp>

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

TEST_CASE("casters: triangleSolidAngle against exact solid angles") {
  // The octant's triangle subtends an eighth of the sphere; a cube's face a sixth (two triangles).
  CHECK(triangleSolidAngle({1, 0, 0}, {0, 1, 0}, {0, 0, 1}) == doctest::Approx(glm::pi<double>() / 2).epsilon(1e-6));
  const glm::vec3 a(-1, -1, 1), b(1, -1, 1), c(1, 1, 1), d(-1, 1, 1);
  CHECK(triangleSolidAngle(a, b, c) + triangleSolidAngle(a, c, d) == doctest::Approx(4 * glm::pi<double>() / 6).epsilon(1e-6));
  // Far away it is area x cos / distance^2; winding does not matter.
  const float far = triangleSolidAngle({-0.01f, -0.01f, 10}, {0.01f, -0.01f, 10}, {0.01f, 0.01f, 10});
  CHECK(far == doctest::Approx(0.5 * 0.02 * 0.02 / 100).epsilon(1e-3));
  CHECK(far == triangleSolidAngle({0.01f, 0.01f, 10}, {0.01f, -0.01f, 10}, {-0.01f, -0.01f, 10}));
}

TEST_CASE("casters: rateCastersForManifold counts the emitters' emitting side, auto takes small ones only") {
  Scene scene;
  Material glass, lamp;
  glass.transmission = 1.0f;
  lamp.emission = glm::vec3(10.0f);
  scene.materials = {glass, lamp};
  addObject(scene, glm::vec3(0.0f), 0);
  // A 0.1 x 0.1 quad lamp 1 above the caster facing down (its front is the side its winding gives).
  auto addQuad = [&](float half, float y, bool down) {
    glm::vec3 p[4] = {{-half, y, -half}, {half, y, -half}, {half, y, half}, {-half, y, half}};
    Triangle t1{}, t2{};
    t1.p[0] = p[0]; t1.p[1] = down ? p[1] : p[2]; t1.p[2] = down ? p[2] : p[1];
    t2.p[0] = p[0]; t2.p[1] = down ? p[2] : p[3]; t2.p[2] = down ? p[3] : p[2];
    t1.material = t2.material = 1;
    scene.triangles.push_back(t1);
    scene.triangles.push_back(t2);
    for (const glm::vec3& q : p) scene.bounds.grow(q);  // the casters' size test is against the scene's
  };
  addQuad(0.05f, 1.0f, true);
  std::vector<CausticCaster> c = findCausticCasters(scene, CAUSTICA_MAX_CASTERS);
  REQUIRE(c.size() == 1);
  CHECK(c[0].smooth);
  rateCastersForManifold(c, scene);
  CHECK(c[0].emitterSolidAngle == doctest::Approx(0.01).epsilon(0.03));  // area / distance^2 (the centre is 0.0125 off)
  CHECK(c[0].manifoldAuto);
  // Facing away (one-sided): no light reaches the caster from it.
  scene.triangles.resize(2);
  addQuad(0.05f, 1.0f, false);
  rateCastersForManifold(c, scene);
  CHECK(c[0].emitterSolidAngle == 0.0f);
  CHECK_FALSE(c[0].manifoldAuto);
  scene.materials[1].doubleSided = true;  // ... unless double-sided
  rateCastersForManifold(c, scene);
  CHECK(c[0].emitterSolidAngle == doctest::Approx(0.01).epsilon(0.03));
  // A lamp 0.6 wide at the same height subtends more than auto's threshold.
  scene.triangles.resize(2);
  addQuad(0.3f, 1.0f, true);
  rateCastersForManifold(c, scene);
  CHECK(c[0].emitterSolidAngle > kManifoldAutoSolidAngle);
  CHECK_FALSE(c[0].manifoldAuto);
  // A rough caster never qualifies (manifold NEE's chains are smooth specular ones).
  scene.triangles.resize(2);
  addQuad(0.05f, 1.0f, true);
  scene.materials[0].roughness = 0.5f;
  c = findCausticCasters(scene, CAUSTICA_MAX_CASTERS);
  rateCastersForManifold(c, scene);
  CHECK_FALSE(c[0].smooth);
  CHECK_FALSE(c[0].manifoldAuto);
}

TEST_CASE("casters: which casters of the bundled scenes --manifold auto joins light through") {
  // Per scene, auto's choice per caster in findCausticCasters' order (docs/path-tracer.md's table).
  const std::vector<std::pair<std::string, std::vector<bool>>> expected = {
      {"lamp-caustics", {true, true}},        // a 4-cm lamp: glass ball and metal ring
      {"mirror-caustic", {true}},             // a small lamp seen in the standing mirror
      {"cornell-glass", {false, false}},      // the large ceiling lamp
      {"cornell-dispersion", {false, false}}, // the lens under the lamp; the prism (0.022 sr: measured a loss)
      {"cornell-materials", {false, false}},  // rough (GGX) mirror and glass
      {"sun-glass", {false}},                 // no emitters (the sun is the environment's)
  };
  for (const auto& [name, want] : expected) {
    CAPTURE(name);
    Scene s = loadScene(resolveScenePath(name));
    GpuScene g = packScene(s, buildBvh(s.triangles));
    REQUIRE(g.casters.size() == want.size());
    for (std::size_t i = 0; i < want.size(); ++i) {
      CAPTURE(i);
      CAPTURE(g.casters[i].emitterSolidAngle);
      CHECK(g.casters[i].manifoldAuto == want[i]);
    }
  }
}
