// instancing_test.cpp — instanced rendering (docs/instancing.md): a scene kept as meshes
// and instances (two-level BVH, world-space shading from object space, instanced emitters in the light
// tree) renders as its flattened copy does, in the path tracer (naive and mis) and in Whitted.
#include <doctest/doctest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "gl_test_util.h"
#include "accel/tlas.h"
#include "accel/gpu_scene.h"

using namespace caustica;
using namespace caustica::test;

namespace {

glm::dmat4 placed(glm::dvec3 at, double degrees, glm::dvec3 axis, glm::dvec3 scale) {
  glm::dmat4 m = glm::translate(glm::dmat4(1.0), at);
  m = glm::rotate(m, glm::radians(degrees), glm::normalize(axis));
  return glm::scale(m, scale);
}

// A box room (one mesh), three spheres of one diffuse mesh (rotated and non-uniformly scaled, mirrored,
// uniformly scaled), a mirror sphere, and two instances of one one-sided lamp (one mirrored).
Scene instancedTestScene() {
  Scene s;
  s.path = "instancing-test";
  s.materials = {diffuseMaterial(0.8f), diffuseMaterial(glm::vec3(0.8f, 0.25f, 0.2f)),
                 emitterMaterial(glm::vec3(1.5f, 1.4f, 1.25f)), metalMaterial(glm::vec3(0.9f))};
  const auto mesh = [&](auto add) { return addMesh(s, add); };
  const std::uint32_t room = mesh([&] {
    addQuad(s, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, {-2, 0, -2}, 0);     // floor, facing +y
    addQuad(s, {-2, 0, -2}, {2, 0, -2}, {2, 2.5f, -2}, {-2, 2.5f, -2}, 0);  // back wall, facing +z
    addQuad(s, {-2, 0, 2}, {-2, 0, -2}, {-2, 2.5f, -2}, {-2, 2.5f, 2}, 1);  // left wall, facing +x
    addQuad(s, {2, 0, -2}, {2, 0, 2}, {2, 2.5f, 2}, {2, 2.5f, -2}, 0);     // right wall, facing -x
    addQuad(s, {-2, 2.5f, -2}, {2, 2.5f, -2}, {2, 2.5f, 2}, {-2, 2.5f, 2}, 0);  // ceiling, facing -y
  });
  const std::uint32_t ball = mesh([&] { addSphere(s, glm::vec3(0.0f), 1.0f, 6, 0); });
  const std::uint32_t shiny = mesh([&] { addSphere(s, glm::vec3(0.0f), 1.0f, 6, 3); });
  // The lamp: a trapezoid (facing -y) whose two triangles' boxes differ, so the light tree orders them by
  // position, not by input order, and the instanced and flattened renders choose lights alike.
  const std::uint32_t light = mesh([&] { addQuad(s, {-1, 0, -1}, {1, 0, -1}, {0.6f, 0, 1}, {-0.6f, 0, 1}, 2); });
  const auto instance = [&](std::uint32_t m, glm::dmat4 world) { s.instances.push_back({m, world}); };
  instance(room, glm::dmat4(1.0));
  instance(ball, placed({-0.9, 0.45, -0.6}, 35.0, {1, 1, 0}, {0.6, 0.35, 0.45}));
  instance(ball, placed({0.9, 0.5, 0.2}, 20.0, {0, 1, 1}, {-0.5, 0.45, 0.4}));  // mirrored
  instance(ball, placed({-0.3, 0.3, 0.9}, 0.0, {0, 1, 0}, {0.3, 0.3, 0.3}));
  instance(shiny, placed({0.6, 1.2, -1.3}, 10.0, {1, 0, 0}, {0.4, 0.4, 0.4}));
  instance(light, placed({-0.3, 2.4, 0.0}, 0.0, {0, 1, 0}, {1.2, 1.0, 0.9}));
  instance(light, placed({1.3, 2.2, -1.0}, 25.0, {0, 0, 1}, {-0.3, 1.0, 0.3}));  // mirrored, tilted
  finishInstancedBounds(s);
  return s;
}

Camera testCamera() {
  Camera c;
  c.position = glm::vec3(0.0f, 1.25f, 4.6f);
  c.forward = glm::normalize(glm::vec3(0.0f, -0.12f, -1.0f));
  c.up = glm::normalize(glm::cross(glm::cross(c.forward, glm::vec3(0, 1, 0)), c.forward));
  c.yfov = 0.75f;
  return c;
}

// Per-block channel means of an image (bx x by blocks).
std::vector<double> blockMeans(const Image& img, int bx, int by) {
  std::vector<double> sum(std::size_t(bx * by * 3), 0.0), n(sum.size(), 0.0);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const std::size_t b = std::size_t(((y * by / img.height) * bx + x * bx / img.width) * 3 + c);
        sum[b] += img.rgb[std::size_t((y * img.width + x) * 3 + c)];
        n[b] += 1.0;
      }
  for (std::size_t i = 0; i < sum.size(); ++i) sum[i] /= n[i];
  return sum;
}

}  // namespace

TEST_CASE("instancing: instanced and flattened renders agree (path naive, path mis, Whitted)") {
  const Scene inst = instancedTestScene();
  Scene flat = inst;
  flattenInstances(flat);
  REQUIRE(flat.instances.empty());
  const Camera cam = testCamera();
  // Tolerances from the measured differences (seeds 1-4, 64 spp, 12 blocks; docs/big-scenes.md): the
  // worst block differed by 0.20 % (naive: paths part on rounding, then Russian roulette), 0.15 % (mis),
  // 0.0001 % (Whitted). A 0.5 % bias of a block fails in each.
  struct Case {
    const char* name;
    RenderMode mode;
    Integrator integrator;
    double tolerance;  // relative, per block
  };
  for (const Case& k : {Case{"path naive", RenderMode::Path, Integrator::Naive, 0.003},
                        Case{"path mis", RenderMode::Path, Integrator::Mis, 0.0025},
                        Case{"whitted", RenderMode::Whitted, Integrator::Mis, 0.0005}}) {
    const std::string name = k.name;
    CAPTURE(name);
    RenderSettings s = smallSettings(48, 36, k.integrator,
                                     std::getenv("INST_SEED") ? std::uint32_t(std::atoi(std::getenv("INST_SEED"))) : 11u);
    s.mode = k.mode;
    // Light tracing's subpaths leave through the light tree, which packs instanced emitters in another
    // order: not the same paths (render_test.cpp compares its instanced caster statistically).
    s.lightTracing = false;
    const int spp = 64;
    // The same seeds: both renders trace the same paths up to rounding, so their difference is far
    // below either's noise and a small bias of the instanced one shows.
    const RenderResult a = renderScene(inst, cam, s, spp);
    const RenderResult b = renderScene(flat, cam, s, spp);
    CHECK(hasDefine(a.defines, "CAUSTICA_INSTANCED"));
    CHECK_FALSE(hasDefine(b.defines, "CAUSTICA_INSTANCED"));
    if (const char* png = std::getenv("CAUSTICA_INSTANCING_PNG")) {  // to look at: CAUSTICA_INSTANCING_PNG=/tmp/x
      writeImage(std::string(png) + "-" + name + "-instanced.png", a.image);
      writeImage(std::string(png) + "-" + name + "-flattened.png", b.image);
    }
    const double meanA = meanOf(a.image), meanB = meanOf(b.image);
    CHECK(meanB > 0.05);
    CHECK(meanA == Rel(meanB, k.tolerance));
    const std::vector<double> ma = blockMeans(a.image, 4, 3), mb = blockMeans(b.image, 4, 3);
    double worst = 0.0;
    for (std::size_t i = 0; i < ma.size(); i += 3) {  // per block: the sum of its channel means
      const double x = ma[i] + ma[i + 1] + ma[i + 2], y = mb[i] + mb[i + 1] + mb[i + 2];
      CAPTURE(i / 3);
      CHECK(y > 0.01);
      CHECK(x == Rel(y, k.tolerance));
      worst = std::max(worst, std::abs(x - y) / y);
    }
    MESSAGE(name << ": image mean " << meanA << " vs " << meanB << "; worst block differs by " << 100.0 * worst << " %");
  }
}

TEST_CASE("instancing: 64 instances of a sphere keep one sphere on the GPU") {
  Scene s;
  s.materials.resize(2);
  s.materials[1].emission = glm::vec3(4.0f);
  addSphere(s, glm::vec3(0.0f), 1.0f, 16, 0);
  s.meshes.push_back({0, std::uint32_t(s.triangles.size()), -1});
  const std::size_t sphere = s.triangles.size();
  addQuad(s, {-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}, 1);
  s.meshes.push_back({std::uint32_t(sphere), 2, -1});
  for (int i = 0; i < 64; ++i) s.instances.push_back({0, placed({2.5 * (i % 8), 0, 2.5 * (i / 8)}, 0, {0, 1, 0}, {1, 1, 1})});
  s.instances.push_back({1, placed({9, 6, 9}, 0.0, {1, 0, 0}, {10, 1, 10})});  // facing down
  s.bounds.grow(glm::vec3(-1, -1, -1));
  s.bounds.grow(glm::vec3(19, 6, 19));
  ShaderLibrary& library = testShaderLibrary();
  RenderSettings settings;
  settings.width = settings.height = 8;
  Renderer r(library, s, autoCamera(s.bounds), settings);
  CHECK(r.gpuScene().instanceCount == 65);
  CHECK(r.gpuScene().instancedTriangles == 64 * sphere + 2);
  CHECK(r.gpuBytes().triGeom == (sphere + 2) * sizeof(gpu::TriGeom));
  CHECK(r.gpuScene().emitterCount == 2);
  r.renderPass(4);
  CHECK(meanOf(r.image()) > 0.0);
}

