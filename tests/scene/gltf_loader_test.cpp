// gltf_loader_test.cpp — tests of the glTF loader (app/scene/gltf_*.cpp): the shipped scenes, transforms,
// accessor formats, the material contract, cameras, textures, and that bad input only ever throws
// caustica::Error with a one-line message naming the file.
#include <doctest/doctest.h>
#include "scene/assets.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <stb_image_write.h>

#include "util/error.h"
#include "scene/scene.h"
#include "gltf_builder.h"

namespace {

using caustica::Scene;
using namespace caustica::test;

const caustica::Material* findMaterial(const Scene& s, const std::string& name) {
  for (const auto& m : s.materials)
    if (m.name == name) return &m;
  return nullptr;
}

}  // namespace

TEST_CASE("every shipped scene loads with triangles, lights, a camera and consistent normals") {
  const char* files[] = {"assets/scenes/cornell-box.gltf",          "assets/scenes/cornell-glass.gltf",
                         "assets/scenes/cornell-bunny-light.gltf",  "assets/scenes/cornell-textured.gltf",
                         "assets/scenes/cornell-dispersion.gltf",   "tests/data/scenes/furnace.gltf",
                         "tests/data/scenes/furnace-glass.gltf",    "tests/data/scenes/glass-in-white-enclosure.gltf",
                         "tests/data/scenes/small-cornell.gltf",    "assets/scenes/cornell-layers.gltf"};
  for (const std::string file : files) {
    CAPTURE(file);
    const Scene s = caustica::loadScene(source(file));
    CHECK(s.path == source(file));
    CHECK(!s.triangles.empty());
    CHECK(s.warnings.empty());
    REQUIRE(s.cameras.size() == 1);
    CHECK(!s.bounds.empty());
    bool emissive = false;
    for (const auto& m : s.materials) emissive = emissive || m.isEmissive();
    CHECK(emissive);
    std::size_t disagree = 0;
    for (const auto& t : s.triangles) {
      REQUIRE(t.material < s.materials.size());
      const glm::vec3 g = geometricNormal(t);
      for (int k = 0; k < 3; ++k) {
        const glm::vec3 n = t.normal(k);
        CHECK(std::abs(glm::length(n) - 1.0f) < 1e-4f);
        if (glm::dot(n, g) <= 0.0f) ++disagree;
      }
    }
    CHECK(disagree == 0);  // winding and shading normals agree everywhere
    const auto& cam = s.cameras[0];
    CHECK(std::abs(glm::length(cam.forward) - 1.0f) < 1e-5f);
    CHECK(std::abs(glm::dot(cam.forward, cam.up)) < 1e-5f);
  }
}

TEST_CASE("Cornell walls face into the box and the ceiling light faces down") {
  for (const char* file : {"assets/scenes/cornell-box.gltf", "assets/scenes/cornell-glass.gltf",
                           "tests/data/scenes/small-cornell.gltf"}) {
    CAPTURE(std::string(file));
    const Scene s = caustica::loadScene(source(file));
    const glm::vec3 centre(0.0f, 1.0f, 0.0f);
    std::size_t walls = 0, lights = 0;
    for (const auto& t : s.triangles) {
      const glm::vec3 g = geometricNormal(t);
      for (int axis = 0; axis < 3; ++axis) {
        const float v = t.p[0][axis];
        // A wall triangle is half of a 2 m x 2 m quad in a wall plane (box bottoms share the floor plane).
        const float area = 0.5f * glm::length(glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]));
        const bool onWall = std::abs(std::abs(v - centre[axis]) - 1.0f) < 1e-5f && t.p[1][axis] == v &&
                            t.p[2][axis] == v && std::abs(area - 2.0f) < 1e-4f;
        if (onWall) {
          ++walls;
          CHECK(glm::dot(g, centre - t.p[0]) > 0.0f);
        }
      }
      if (s.materials[t.material].isEmissive()) {
        ++lights;
        CHECK(near(g, glm::vec3(0.0f, -1.0f, 0.0f)));
        CHECK(t.p[0].y < 2.0f);
      }
    }
    CHECK(walls == 10);
    CHECK(lights == 2);
    const auto& cam = s.cameras[0];
    CHECK(near(cam.forward, glm::vec3(0.0f, 0.0f, -1.0f)));
    CHECK(cam.position.z > 1.0f);  // outside, looking in through the open side
  }
}

TEST_CASE("cornell-glass: glass and mirror spheres and the classic light") {
  const Scene s = caustica::loadScene(source("assets/scenes/cornell-glass.gltf"));
  const auto* glass = findMaterial(s, "glass");
  const auto* mirror = findMaterial(s, "mirror");
  const auto* light = findMaterial(s, "light");
  REQUIRE(glass);
  REQUIRE(mirror);
  REQUIRE(light);
  CHECK(glass->transmission == 1.0f);
  CHECK(glass->ior == doctest::Approx(1.5));
  CHECK(glass->metallic == 0.0f);
  CHECK(glass->roughness == 0.0f);
  CHECK(std::isinf(glass->attenuationDistance));
  CHECK(mirror->metallic == 1.0f);
  CHECK(mirror->roughness == 0.0f);
  CHECK(mirror->transmission == 0.0f);
  CHECK(mirror->baseColor.r == doctest::Approx(0.95));
  CHECK(light->emission.r == doctest::Approx(17.0).epsilon(1e-4));
  CHECK(light->emission.g == doctest::Approx(12.0).epsilon(1e-4));
  CHECK(light->emission.b == doctest::Approx(4.0).epsilon(1e-4));
  CHECK(!light->doubleSided);
  CHECK(s.cameras[0].yfov == doctest::Approx(0.6911));
  CHECK(s.cameras[0].aspect == doctest::Approx(1.0));
  // Sphere vertices lie on spheres of radius 0.35 resting on the floor.
  std::size_t sphereTriangles = 0;
  for (const auto& t : s.triangles) {
    if (&s.materials[t.material] != glass) continue;
    ++sphereTriangles;
    for (const auto& p : t.p)
      CHECK(glm::length(p - glm::vec3(-0.42f, 0.35f, 0.3f)) == doctest::Approx(0.35).epsilon(1e-4));
  }
  CHECK(sphereTriangles > 1000);
}

TEST_CASE("cornell-textured: textures decode with row 0 at the top and repeat") {
  const Scene s = caustica::loadScene(source("assets/scenes/cornell-textured.gltf"));
  REQUIRE(s.textures.size() == 2);
  int textured = 0;
  for (const auto& m : s.materials) {
    if (m.baseColorTexture < 0) continue;
    ++textured;
    REQUIRE(m.baseColorTexture < int(s.textures.size()));
    const auto& tex = s.textures[std::size_t(m.baseColorTexture)];
    CHECK(tex.width == 128);
    CHECK(tex.height == 128);
    CHECK(tex.rgba.size() == 128u * 128u * 4u);
    CHECK(tex.repeatS);
    CHECK(tex.repeatT);
    CHECK(!tex.mirrorS);
  }
  CHECK(textured == 2);
  // The checkerboard (nearest filtering) is light grey at (0,0) and blue 16 texels to the right;
  // the grid texture has a red mark in its top-left corner.
  const auto& checker = s.textures[0].nearest ? s.textures[0] : s.textures[1];
  const auto& grid = s.textures[0].nearest ? s.textures[1] : s.textures[0];
  CHECK(checker.nearest);
  CHECK(!grid.nearest);
  CHECK(checker.rgba[0] == 220);
  CHECK(checker.rgba[16 * 4 + 2] == 160);
  CHECK(checker.rgba[3] == 255);
  CHECK(grid.rgba[0] == 190);
  CHECK(grid.rgba[1] == 40);
  const std::size_t bottomLeft = std::size_t(127 * 128) * 4;
  CHECK(grid.rgba[bottomLeft] != 190);
  float maxU = 0.0f;
  for (std::size_t i = 0; i < s.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) maxU = std::max(maxU, caustica::triangleUv(s, i, k).x);
  CHECK(maxU > 1.5f);  // coordinates repeat the textures several times
}

TEST_CASE("cornell-dispersion, bunny light and furnaces follow the material contract") {
  {
    const Scene s = caustica::loadScene(source("assets/scenes/cornell-dispersion.gltf"));
    const auto* prism = findMaterial(s, "dispersive glass");
    REQUIRE(prism);
    CHECK(prism->dispersion == doctest::Approx(1.2));
    CHECK(prism->transmission == 1.0f);
    int prismTriangles = 0;
    for (const auto& t : s.triangles)
      if (&s.materials[t.material] == prism && (t.p[0].x + t.p[1].x + t.p[2].x) / 3.0f > 0.35f) {
        ++prismTriangles;  // the prism stands right of the sphere; it has no NORMAL: flat normals
        for (int k = 0; k < 3; ++k) CHECK(near(t.normal(k), geometricNormal(t), 1e-4f));
      }
    CHECK(prismTriangles == 8);
  }
  {
    const Scene s = caustica::loadScene(source("assets/scenes/cornell-bunny-light.gltf"));
    std::size_t emitters = 0;
    for (const auto& t : s.triangles)
      if (s.materials[t.material].isEmissive()) {
        ++emitters;
        CHECK(s.materials[t.material].doubleSided);
      }
    CHECK(emitters == 3674);
  }
  for (const char* file : {"tests/data/scenes/furnace.gltf", "tests/data/scenes/furnace-glass.gltf",
                           "tests/data/scenes/glass-in-white-enclosure.gltf"}) {
    CAPTURE(std::string(file));
    const Scene s = caustica::loadScene(source(file));
    const float albedo = std::string(file).find("white") != std::string::npos ? 0.0f : 0.5f;
    bool glass = false;
    for (const auto& m : s.materials) {
      if (m.transmission > 0.0f) {
        glass = true;
        CHECK(m.transmission == 1.0f);
        CHECK(!m.isEmissive());
        CHECK(m.baseColor == glm::vec4(1.0f));
        continue;
      }
      CHECK(m.baseColor.r == doctest::Approx(albedo));
      CHECK(m.metallic == 0.0f);
      CHECK(m.emission == glm::vec3(1.0f));
      CHECK(!m.doubleSided);
    }
    CHECK(glass == (std::string(file).find("glass") != std::string::npos));
    const glm::vec3 eye = s.cameras[0].position;
    CHECK(glm::all(glm::greaterThan(eye, s.bounds.min)));
    CHECK(glm::all(glm::lessThan(eye, s.bounds.max)));
    for (const auto& t : s.triangles)  // room walls face the camera inside
      if (s.materials[t.material].isEmissive()) CHECK(glm::dot(geometricNormal(t), eye - t.p[0]) > 0.0f);
  }
}

TEST_CASE("node transforms: negative scale flips the winding, normals use the inverse transpose") {
  TempDir dir;
  SUBCASE("negative scale") {
    Gltf g;
    const int mesh = g.mesh({{"attributes", {{"POSITION", g.positions(kTriangle)},
                                             {"NORMAL", g.accessor(kTriangleNormals, kFloat, "VEC3")}}},
                             {"material", g.diffuse()}});
    g.root({{"mesh", mesh}, {"scale", {-1.0, 1.0, 1.0}}});
    const Scene s = g.load(dir);
    REQUIRE(s.triangles.size() == 1);
    const auto& t = s.triangles[0];
    CHECK(near(t.normal(0), glm::vec3(0, 0, 1), 1e-4f));
    CHECK(near(geometricNormal(t), glm::vec3(0, 0, 1)));  // mirrored, and re-wound to face +z
    bool mirrored = false;
    for (const auto& p : t.p) mirrored = mirrored || near(p, glm::vec3(-1, 0, 0));
    CHECK(mirrored);
  }
  SUBCASE("rotation and non-uniform scale") {
    // A triangle in the plane x + y = 1 with its true normal; scaled x2 along x, rotated 90 deg about z.
    Gltf g;
    const float r = std::sqrt(0.5f);
    const int mesh = g.mesh({{"attributes", {{"POSITION", g.positions({1, 0, 0, 0, 1, 0, 1, 0, 1})},
                                             {"NORMAL", g.accessor(std::vector<float>{r, r, 0, r, r, 0, r, r, 0},
                                                                   kFloat, "VEC3")}}},
                             {"material", g.diffuse()}});
    g.root({{"mesh", mesh}, {"rotation", {0.0, 0.0, r, r}}, {"scale", {2.0, 1.0, 1.0}}, {"translation", {0, 0, 5}}});
    const Scene s = g.load(dir);
    REQUIRE(s.triangles.size() == 1);
    const auto& t = s.triangles[0];
    // (1,0,0) -> scale (2,0,0) -> rotate (0,2,0) -> translate; positions are relative to Scene::origin
    CHECK(near(t.p[0] + glm::vec3(s.origin), glm::vec3(0, 2, 5)));
    for (int k = 0; k < 3; ++k) {
      const glm::vec3 n = t.normal(k);
      CHECK(std::abs(glm::length(n) - 1.0f) < 1e-5f);
      CHECK(near(n, geometricNormal(t), 1e-4f));  // within the octahedral words' 4.3e-5 rad  // a plain M * n would tilt the normal off the surface
    }
  }
  SUBCASE("a small object far from the origin keeps its precision (rebased in double)") {
    // A 1 mm triangle translated by 1e6: in float world coordinates its vertices would round to
    // 0.0625; relative to Scene::origin (its centre, in double) they stay exact to ~1e-10.
    Gltf g;
    const int mesh = g.mesh({{"attributes", {{"POSITION", g.positions({0, 0, 0, 0.001f, 0, 0, 0, 0.001f, 0})}}},
                             {"material", g.diffuse()}});
    g.root({{"mesh", mesh}, {"translation", {1e6, -2e6, 3e6}}});
    const Scene s = g.load(dir);
    REQUIRE(s.triangles.size() == 1);
    const auto& t = s.triangles[0];
    CHECK(std::abs(s.origin.x - (1e6 + 0.0005)) < 1e-9);  // the centre of the triangle's box
    CHECK(std::abs(s.origin.y - (-2e6 + 0.0005)) < 1e-9);
    CHECK(s.origin.z == 3e6);
    CHECK(std::abs(t.p[1].x - t.p[0].x - 0.001f) < 1e-9f);
    CHECK(std::abs(t.p[2].y - t.p[0].y - 0.001f) < 1e-9f);
    CHECK(std::abs(t.p[0].x + 0.0005f) < 1e-9f);
  }
  SUBCASE("a scene near the origin keeps its glTF coordinates") {
    Gltf g;
    const int mesh = g.mesh({{"attributes", {{"POSITION", g.positions(kTriangle)}}}, {"material", g.diffuse()}});
    g.root({{"mesh", mesh}, {"translation", {0.5, 0, 0}}});
    const Scene s = g.load(dir);
    CHECK(s.origin == glm::dvec3(0.0));
  }
  SUBCASE("matrix equals TRS, and parents compose") {
    Gltf g;
    const int mesh = g.mesh({{"attributes", {{"POSITION", g.positions(kTriangle)}}}, {"material", g.diffuse()}});
    // TRS: translation (1,2,3), rotation 90 deg about y, scale 2, as a column-major matrix.
    g.root({{"mesh", mesh}, {"translation", {1, 2, 3}}, {"rotation", {0.0, std::sqrt(0.5), 0.0, std::sqrt(0.5)}},
            {"scale", {2, 2, 2}}});
    g.root({{"mesh", mesh}, {"matrix", {0, 0, -2, 0, 0, 2, 0, 0, 2, 0, 0, 0, 1, 2, 3, 1}}});
    const int child = g.add("nodes", {{"mesh", mesh}, {"scale", {3, 3, 3}}});
    g.root({{"translation", {0, 10, 0}}, {"children", {child}}});
    const Scene s = g.load(dir);
    REQUIRE(s.triangles.size() == 3);
    for (int k = 0; k < 3; ++k) CHECK(near(s.triangles[0].p[k], s.triangles[1].p[k]));
    CHECK(near(s.triangles[0].p[1], glm::vec3(1, 2, 1)));  // (1,0,0) -> (2,0,0) -> (0,0,-2) -> +T
    CHECK(near(s.triangles[2].p[2], glm::vec3(0, 13, 0)));
    CHECK(s.bounds.max.y == doctest::Approx(13.0));
  }
}

TEST_CASE("primitives: index types, non-indexed, strips, fans, flat normals, degenerate triangles") {
  TempDir dir;
  const std::vector<float> quad = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  SUBCASE("all index component types give the same triangles") {
    std::vector<std::vector<caustica::Triangle>> results;
    for (int type : {kByte, kShort, kUint}) {
      Gltf g;
      int indices = -1;
      if (type == kByte) indices = g.accessor(std::vector<std::uint8_t>{0, 1, 2, 0, 2, 3}, type, "SCALAR");
      if (type == kShort) indices = g.accessor(std::vector<std::uint16_t>{0, 1, 2, 0, 2, 3}, type, "SCALAR");
      if (type == kUint) indices = g.accessor(std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}, type, "SCALAR");
      g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", g.positions(quad)}}}, {"indices", indices}})}});
      const Scene s = g.load(dir);
      REQUIRE(s.triangles.size() == 2);
      results.push_back(s.triangles);
    }
    for (int k = 0; k < 3; ++k) {
      CHECK(near(results[0][1].p[k], results[1][1].p[k]));
      CHECK(near(results[0][1].p[k], results[2][1].p[k]));
    }
    CHECK(near(results[0][1].p[2], glm::vec3(0, 1, 0)));
  }
  SUBCASE("non-indexed triangles, flat normals when NORMAL is missing, default material") {
    Gltf g;
    g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", g.positions({0, 0, 0, 1, 0, 0, 0, 1, 0,  //
                                                                       0, 0, 1, 0, 1, 1, 0, 0, 2})}}}})}});
    const Scene s = g.load(dir);
    REQUIRE(s.triangles.size() == 2);
    CHECK(near(s.triangles[0].normal(1), glm::vec3(0, 0, 1), 1e-4f));
    CHECK(near(s.triangles[1].normal(2), glm::vec3(1, 0, 0), 1e-4f));
    REQUIRE(s.materials.size() == 1);
    CHECK(s.materials[0].metallic == 0.0f);
    CHECK(s.materials[0].baseColor.r == doctest::Approx(0.8));
    CHECK(hasWarning(s, "no material"));
  }
  SUBCASE("triangle strip and fan keep every triangle facing +z") {
    for (int mode : {5, 6}) {
      Gltf g;
      const std::vector<float> strip = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0, 2, 0};
      const std::vector<float> fan = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0.5f, 2, 0, 0, 1, 0};
      const int pos = g.positions(mode == 5 ? strip : fan);
      g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", pos}}}, {"mode", mode}})}});
      const Scene s = g.load(dir);
      CHECK(s.triangles.size() == 3);
      for (const auto& t : s.triangles) CHECK(near(geometricNormal(t), glm::vec3(0, 0, 1)));
    }
  }
  SUBCASE("zero-area triangles are dropped with a warning; points are skipped with a warning") {
    Gltf g;
    const int pos = g.positions({0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0});
    const int indices = g.accessor(std::vector<std::uint16_t>{0, 1, 2, 0, 1, 3}, kShort, "SCALAR");
    json points = {{"attributes", {{"POSITION", pos}}}, {"mode", 0}};
    json triangles = {{"attributes", {{"POSITION", pos}}}, {"indices", indices}};
    g.doc["meshes"].push_back({{"primitives", {points, triangles}}});
    g.root({{"mesh", 0}});
    const Scene s = g.load(dir);
    CHECK(s.triangles.size() == 1);
    CHECK(hasWarning(s, "degenerate"));
    CHECK(hasWarning(s, "POINTS"));
  }
}

TEST_CASE("accessors: normalized texcoords and sparse substitution") {
  TempDir dir;
  SUBCASE("normalized UNSIGNED_BYTE and UNSIGNED_SHORT texcoords") {
    for (int type : {kByte, kShort}) {
      Gltf g;
      const int uv = type == kByte ? g.accessor(std::vector<std::uint8_t>{0, 255, 51, 0, 255, 255}, type, "VEC2", true)
                                   : g.accessor(std::vector<std::uint16_t>{0, 65535, 13107, 0, 65535, 65535}, type,
                                                "VEC2", true);
      // A material that reads a texture: only then are texture coordinates kept (Scene::texcoords).
      const unsigned char png[4] = {255, 0, 0, 255};
      REQUIRE(stbi_write_png((dir.path / "one.png").string().c_str(), 1, 1, 4, png, 4));
      g.doc["images"] = {{{"uri", "one.png"}}};
      g.doc["textures"] = {{{"source", 0}}};
      const int textured = g.add("materials", {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
      g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", g.positions(kTriangle)}, {"TEXCOORD_0", uv}}},
                               {"material", textured}})}});
      const Scene s = g.load(dir);
      REQUIRE(s.triangles.size() == 1);
      REQUIRE(s.texcoords.size() == 1);
      CHECK(s.texcoords[0].uv[0].x == doctest::Approx(0.0));
      CHECK(s.texcoords[0].uv[0].y == doctest::Approx(1.0));
      CHECK(s.texcoords[0].uv[1].x == doctest::Approx(0.2));
      CHECK(s.texcoords[0].uv[2].y == doctest::Approx(1.0));
    }
  }
  SUBCASE("texture coordinates are kept only when a material reads a texture") {
    // The same TEXCOORD_0 without a textured material: nothing stored (24 B per triangle saved), and
    // triangleUv reads (0, 0); with one, one TriangleUv per triangle, untextured triangles included.
    const int kinds[2] = {0, 1};
    for (int withTexture : kinds) {
      CAPTURE(withTexture);
      Gltf g;
      const int uv = g.accessor(std::vector<float>{0.25f, 0.5f, 0.75f, 0.5f, 0.25f, 1.0f}, kFloat, "VEC2");
      const int pos = g.positions(kTriangle);
      g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv}}}})}});  // default material
      if (withTexture) {
        const unsigned char png[4] = {0, 255, 0, 255};
        REQUIRE(stbi_write_png((dir.path / "one.png").string().c_str(), 1, 1, 4, png, 4));
        g.doc["images"] = {{{"uri", "one.png"}}};
        g.doc["textures"] = {{{"source", 0}}};
        const int m = g.add("materials", {{"emissiveTexture", {{"index", 0}}}});
        g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv}}}, {"material", m}})}});
      }
      const Scene s = g.load(dir);
      REQUIRE(s.triangles.size() == std::size_t(1 + withTexture));
      CHECK(s.texcoords.size() == (withTexture ? s.triangles.size() : 0u));
      for (std::size_t i = 0; i < s.triangles.size(); ++i) {
        const glm::vec2 expect = withTexture ? glm::vec2(0.75f, 0.5f) : glm::vec2(0.0f);
        CHECK(caustica::triangleUv(s, i, 1) == expect);
      }
    }
  }
  SUBCASE("texcoords that are not normalized integers are rejected") {
    Gltf g;
    const int uv = g.accessor(std::vector<std::uint8_t>{0, 255, 51, 0, 255, 255}, kByte, "VEC2", false);
    g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", g.positions(kTriangle)}, {"TEXCOORD_0", uv}}}})}});
    const std::string error = loadError(dir.write("uv.gltf", g.text()));
    CHECK(error.find("uv.gltf") != std::string::npos);
    CHECK(error.find("TEXCOORD_0") != std::string::npos);
  }
  SUBCASE("sparse accessor over a bufferView and over zeros") {
    // Vertices 1 and 2 are substituted; with or without the base data the result is the same.
    for (bool withBase : {true, false}) {
      CAPTURE(withBase);
      Gltf g;
      const int pos = g.positions(kTriangle);
      const int sparseIndices = g.accessor(std::vector<std::uint8_t>{1, 2}, kByte, "SCALAR");
      const int sparseValues = g.accessor(std::vector<float>{1, 0, 0, 0, 3, 0}, kFloat, "VEC3");
      json acc = g.doc["accessors"][std::size_t(pos)];
      if (!withBase) acc.erase("bufferView");
      acc["sparse"] = {{"count", 2},
                       {"indices", {{"bufferView", g.doc["accessors"][std::size_t(sparseIndices)]["bufferView"]},
                                    {"componentType", kByte}}},
                       {"values", {{"bufferView", g.doc["accessors"][std::size_t(sparseValues)]["bufferView"]}}}};
      const int sparse = g.add("accessors", acc);
      g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", sparse}}}})}});
      const Scene s = g.load(dir);
      REQUIRE(s.triangles.size() == 1);
      CHECK(near(s.triangles[0].p[0], glm::vec3(0, 0, 0)));
      CHECK(near(s.triangles[0].p[1], glm::vec3(1, 0, 0)));
      CHECK(near(s.triangles[0].p[2], glm::vec3(0, 3, 0)));
    }
  }
}

TEST_CASE("material contract: alpha modes, emission strength, glass extensions, defaults and warnings") {
  TempDir dir;
  Gltf g;
  const int pos = g.positions(kTriangle);
  auto material = [&](json m) {
    const int index = g.add("materials", m);
    g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", pos}}}, {"material", index}})}});
    return index;
  };
  json pbrAlpha = {{"baseColorFactor", {0.2, 0.4, 0.6, 0.3}}, {"metallicFactor", 0.0}};
  material({{"name", "opaque"}, {"pbrMetallicRoughness", pbrAlpha}});
  material({{"name", "blend"}, {"pbrMetallicRoughness", pbrAlpha}, {"alphaMode", "BLEND"}});
  material({{"name", "mask-low"}, {"pbrMetallicRoughness", pbrAlpha}, {"alphaMode", "MASK"}});
  material({{"name", "mask-high"}, {"pbrMetallicRoughness", pbrAlpha}, {"alphaMode", "MASK"}, {"alphaCutoff", 0.25}});
  material({{"name", "emitter"},
            {"pbrMetallicRoughness", {{"metallicFactor", 0.0}}},
            {"emissiveFactor", {1.0, 0.5, 0.0}},
            {"doubleSided", true},
            {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4.0}}}}}});
  material({{"name", "tinted glass"},
            {"pbrMetallicRoughness", {{"metallicFactor", 0.0}, {"roughnessFactor", 0.0}}},
            {"extensions",
             {{"KHR_materials_transmission", {{"transmissionFactor", 0.75}}},
              {"KHR_materials_ior", {{"ior", 1.33}}},
              {"KHR_materials_volume", {{"attenuationColor", {0.5, 0.9, 1.0}}, {"attenuationDistance", 0.2}}},
              {"KHR_materials_dispersion", {{"dispersion", 0.5}}}}}});
  material({{"name", "rough mirror"}, {"pbrMetallicRoughness", {{"metallicFactor", 0.6}, {"roughnessFactor", 0.4}}}});
  material({{"name", "spec default"}});
  material({{"name", "plastic"},
            {"pbrMetallicRoughness", {{"metallicFactor", 0.0}, {"roughnessFactor", 0.3}}},
            {"extensions",
             {{"KHR_materials_specular", {{"specularFactor", 0.5}, {"specularColorFactor", {1.0, 0.5, 0.25}}}},
              {"KHR_materials_ior", {{"ior", 2.0}}}}}});
  g.doc["extensionsUsed"] = {"KHR_materials_emissive_strength", "KHR_materials_transmission", "KHR_materials_ior",
                             "KHR_materials_volume", "KHR_materials_dispersion", "KHR_materials_specular",
                             "EXT_something_else"};
  const Scene s = g.load(dir);
  REQUIRE(s.materials.size() == 9);
  CHECK(findMaterial(s, "opaque")->baseColor.a == 1.0f);
  CHECK(findMaterial(s, "opaque")->baseColor.b == doctest::Approx(0.6));
  CHECK(findMaterial(s, "blend")->baseColor.a == doctest::Approx(0.3));
  CHECK(findMaterial(s, "mask-low")->baseColor.a == 0.0f);  // 0.3 < default cutoff 0.5
  CHECK(findMaterial(s, "mask-high")->baseColor.a == 1.0f);
  const auto* emitter = findMaterial(s, "emitter");
  CHECK(emitter->emission.r == doctest::Approx(4.0));
  CHECK(emitter->emission.g == doctest::Approx(2.0));
  CHECK(emitter->emission.b == 0.0f);
  CHECK(emitter->doubleSided);
  const auto* glass = findMaterial(s, "tinted glass");
  CHECK(glass->transmission == doctest::Approx(0.75));
  CHECK(glass->ior == doctest::Approx(1.33));
  CHECK(glass->attenuationColor.r == doctest::Approx(0.5));
  CHECK(glass->attenuationDistance == doctest::Approx(0.2));
  CHECK(glass->dispersion == doctest::Approx(0.5));
  CHECK(!glass->isEmissive());
  CHECK(findMaterial(s, "rough mirror")->metallic == doctest::Approx(0.6));
  const auto* spec = findMaterial(s, "spec default");  // glTF defaults: white, metallic 1, roughness 1
  CHECK(spec->baseColor == glm::vec4(1.0f));
  CHECK(spec->metallic == 1.0f);
  CHECK(spec->roughness == 1.0f);
  CHECK(spec->ior == doctest::Approx(1.5));
  CHECK(std::isinf(spec->attenuationDistance));
  // Roughness is rendered (GGX), so it is no longer warned about.
  CHECK(!hasWarning(s, "'rough mirror'"));
  CHECK(!hasWarning(s, "'spec default'"));
  CHECK(findMaterial(s, "rough mirror")->roughness == doctest::Approx(0.4));
  // The specular layer: glTF's F0 = ((ior - 1) / (ior + 1))^2 = 0.04 at ior 1.5 and F90 = 1 by default;
  // KHR_materials_specular scales F0 by specularColorFactor x specularFactor and F90 by specularFactor.
  CHECK(spec->specularF0.g == doctest::Approx(0.04));
  CHECK(spec->specularF90 == 1.0f);
  const auto* plastic = findMaterial(s, "plastic");
  CHECK(plastic->specularF0.r == doctest::Approx(0.5 / 9.0));  // ((2 - 1) / (2 + 1))^2 = 1/9
  CHECK(plastic->specularF0.g == doctest::Approx(0.25 / 9.0));
  CHECK(plastic->specularF0.b == doctest::Approx(0.125 / 9.0));
  CHECK(plastic->specularF90 == doctest::Approx(0.5));
  CHECK(!hasWarning(s, "'plastic'"));
  CHECK(!hasWarning(s, "'tinted glass'"));
  CHECK(hasWarning(s, "EXT_something_else"));
  for (const auto& w : s.warnings) CHECK(w.rfind(s.path + ": ", 0) == 0);

  SUBCASE("a required unsupported extension is an error") {
    g.doc["extensionsUsed"] = {"KHR_texture_basisu"};
    g.doc["extensionsRequired"] = {"KHR_texture_basisu"};
    const std::string error = loadError(dir.write("transform.gltf", g.text()));
    CHECK(error.find("transform.gltf: ") != std::string::npos);
    CHECK(error.find("KHR_texture_basisu") != std::string::npos);
  }
}

TEST_CASE("cameras: perspective and orthographic parameters, world transform, traversal order, automatic camera") {
  TempDir dir;
  Gltf g;
  g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", g.positions(kTriangle)}}}})}});
  g.add("cameras", {{"name", "second"}, {"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}}}});
  g.add("cameras", {{"name", "first"},
                    {"type", "perspective"},
                    {"perspective", {{"yfov", 0.9}, {"aspectRatio", 1.5}, {"znear", 0.1}}}});
  g.add("cameras", {{"name", "ortho"}, {"type", "orthographic"},
                    {"orthographic", {{"xmag", 3}, {"ymag", -1.5}, {"znear", 0.1}, {"zfar", 10}}}});
  const double r = std::sqrt(0.5);
  // "first" sits in a node that is traversed before the node holding "second", despite array order.
  g.root({{"camera", 1}, {"translation", {1, 2, 3}}, {"rotation", {0.0, r, 0.0, r}}});  // 90 deg about +y
  const int inner = g.add("nodes", {{"camera", 0}});
  g.root({{"translation", {0, 0, 7}}, {"children", {inner}}});
  g.root({{"camera", 2}});
  const Scene s = g.load(dir);
  REQUIRE(s.cameras.size() == 3);
  CHECK(s.cameras[0].name == "first");
  CHECK(!s.cameras[0].orthographic());
  CHECK(s.cameras[0].yfov == doctest::Approx(0.9));
  CHECK(s.cameras[0].aspect == doctest::Approx(1.5));
  CHECK(near(s.cameras[0].position, glm::vec3(1, 2, 3)));
  CHECK(near(s.cameras[0].forward, glm::vec3(-1, 0, 0)));  // -Z rotated 90 deg about +y
  CHECK(near(s.cameras[0].up, glm::vec3(0, 1, 0)));
  CHECK(s.cameras[1].name == "second");
  CHECK(s.cameras[1].aspect == 0.0f);
  CHECK(near(s.cameras[1].position, glm::vec3(0, 0, 7)));
  // Orthographic: half height ymag (its sign carries nothing), the file's aspect xmag / ymag.
  CHECK(s.cameras[2].name == "ortho");
  CHECK(s.cameras[2].orthographic());
  CHECK(s.cameras[2].orthoHeight == 1.5f);
  CHECK(s.cameras[2].aspect == 2.0f);
  CHECK(!hasWarning(s, "orthographic"));
  SUBCASE("a zero ymag is refused") {
    g.doc["cameras"][2]["orthographic"]["ymag"] = 0;
    CHECK(loadError(dir.write("ortho0.gltf", g.text())).find("cameras[2].orthographic.ymag is 0") != std::string::npos);
  }

  const caustica::Bounds bounds{glm::vec3(-1.0f, 0.0f, -3.0f), glm::vec3(1.0f, 2.0f, 1.0f)};
  const caustica::Camera automatic = caustica::autoCamera(bounds);
  CHECK(near(automatic.forward, glm::vec3(0, 0, -1)));
  CHECK(near(automatic.up, glm::vec3(0, 1, 0)));
  CHECK(automatic.yfov == doctest::Approx(40.0 * 3.14159265358979 / 180.0));
  const float tanHalf = std::tan(automatic.yfov / 2.0f);
  for (int corner = 0; corner < 8; ++corner) {
    const glm::vec3 p((corner & 1) ? bounds.max.x : bounds.min.x, (corner & 2) ? bounds.max.y : bounds.min.y,
                      (corner & 4) ? bounds.max.z : bounds.min.z);
    const glm::vec3 d = p - automatic.position;
    const float depth = glm::dot(d, automatic.forward);
    REQUIRE(depth > 0.0f);
    CHECK(std::abs(glm::dot(d, automatic.up)) <= tanHalf * depth * 1.0001f);
    CHECK(std::abs(d.x) <= tanHalf * depth * 1.0001f);  // fits a square image too
  }
  const caustica::Camera fallback = caustica::autoCamera(caustica::Bounds{});
  CHECK(std::isfinite(fallback.position.z));
}

TEST_CASE("textures: external PNG and JPEG files, samplers, emissive texture") {
  TempDir dir;
  // 2x2 RGBA PNG: top row red, green; bottom row blue, half-transparent white.
  const unsigned char png[16] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 128};
  REQUIRE(stbi_write_png((dir.path / "tiny.png").string().c_str(), 2, 2, 4, png, 8));
  std::vector<unsigned char> jpeg(16 * 16 * 3);
  for (std::size_t i = 0; i < jpeg.size(); i += 3) jpeg[i] = 200, jpeg[i + 1] = 100, jpeg[i + 2] = 50;
  REQUIRE(stbi_write_jpg((dir.path / "flat.jpg").string().c_str(), 16, 16, 3, jpeg.data(), 100));

  Gltf g;
  g.doc["images"] = {{{"uri", "tiny.png"}}, {{"uri", "flat.jpg"}}};
  g.doc["samplers"] = {{{"wrapS", 33071}, {"wrapT", 33648}, {"magFilter", 9728}}};
  g.doc["textures"] = {{{"source", 0}, {"sampler", 0}}, {{"source", 1}}};
  const int mat = g.add("materials",
                        {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"metallicFactor", 0.0}}},
                         {"emissiveFactor", {1, 1, 1}},
                         {"emissiveTexture", {{"index", 1}}}});
  g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", g.positions(kTriangle)}}}, {"material", mat}})}});
  const Scene s = g.load(dir);
  REQUIRE(s.textures.size() == 2);
  const auto& base = s.textures[std::size_t(s.materials[0].baseColorTexture)];
  const auto& emissive = s.textures[std::size_t(s.materials[0].emissiveTexture)];
  CHECK(base.width == 2);
  CHECK(base.height == 2);
  CHECK(std::vector<std::uint8_t>(base.rgba.begin(), base.rgba.end()) == std::vector<std::uint8_t>(png, png + 16));
  CHECK(!base.repeatS);
  CHECK(base.repeatT);
  CHECK(base.mirrorT);
  CHECK(base.nearest);
  CHECK(emissive.width == 16);
  CHECK(std::abs(int(emissive.rgba[0]) - 200) <= 3);
  CHECK(std::abs(int(emissive.rgba[1]) - 100) <= 3);
  CHECK(std::abs(int(emissive.rgba[2]) - 50) <= 3);
  CHECK(emissive.rgba[3] == 255);
  CHECK(emissive.repeatS);  // no sampler: REPEAT
}

TEST_CASE("textures: metallicRoughness, normal, MASK with texture alpha, KHR_texture_transform") {
  TempDir dir;
  const unsigned char png[16] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 128};
  REQUIRE(stbi_write_png((dir.path / "tiny.png").string().c_str(), 2, 2, 4, png, 8));
  Gltf g;
  g.doc["images"] = {{{"uri", "tiny.png"}}};
  g.doc["textures"] = {{{"source", 0}}};
  const json transform = {{"KHR_texture_transform", {{"offset", {0.0, 1.0}}, {"rotation", 1.57079632679}, {"scale", {0.5, 0.5}}}}};
  const int mat = g.add("materials", {{"pbrMetallicRoughness",
                                       {{"baseColorTexture", {{"index", 0}}},
                                        {"metallicRoughnessTexture", {{"index", 0}, {"extensions", transform}}}}},
                                      {"normalTexture", {{"index", 0}, {"scale", 0.5}}},
                                      {"alphaMode", "MASK"},
                                      {"alphaCutoff", 0.4}});
  g.doc["extensionsUsed"] = {"KHR_texture_transform"};
  g.doc["extensionsRequired"] = {"KHR_texture_transform"};
  g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", g.positions(kTriangle)}}}, {"material", mat}})}});
  const Scene s = g.load(dir);
  const caustica::Material& m = s.materials[0];
  CHECK(m.baseColorTexture == m.normalTexture);  // the same glTF texture without a transform: one entry
  CHECK(m.normalScale == 0.5f);
  CHECK(m.alphaFromTexture);
  CHECK(m.alphaCutoff == doctest::Approx(0.4));
  CHECK(m.baseColor.a == 1.0f);  // the cutoff is applied per hit to factor x texture alpha
  REQUIRE(m.metallicRoughnessTexture >= 0);
  REQUIRE(s.textures.size() == 2);
  const caustica::Texture& t = s.textures[std::size_t(m.metallicRoughnessTexture)];
  CHECK(t.pixelSource == m.baseColorTexture);  // shares the texels
  CHECK(t.rgba.empty());
  // The extension's example: rotation pi/2, offset (0, 1), scale 0.5 maps (u, v) to the lower left
  // quadrant: u' = 0.5 v, v' = 1 - 0.5 u.
  const auto apply = [&](glm::vec2 uv) {
    return glm::vec2(glm::dot(t.uvRow0, glm::vec3(uv, 1.0f)), glm::dot(t.uvRow1, glm::vec3(uv, 1.0f)));
  };
  CHECK(glm::length(apply({0, 0}) - glm::vec2(0.0f, 1.0f)) < 1e-6f);
  CHECK(glm::length(apply({1, 0}) - glm::vec2(0.0f, 0.5f)) < 1e-6f);
  CHECK(glm::length(apply({0, 1}) - glm::vec2(0.5f, 1.0f)) < 1e-6f);
  for (const auto& w : s.warnings) CHECK(w.find("normalTexture") == std::string::npos);
}

TEST_CASE("layers and unlit: KHR_materials_clearcoat, KHR_materials_sheen, KHR_materials_unlit and the factor textures") {
  TempDir dir;
  const unsigned char png[16] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 128};
  REQUIRE(stbi_write_png((dir.path / "tiny.png").string().c_str(), 2, 2, 4, png, 8));
  Gltf g;
  g.doc["images"] = {{{"uri", "tiny.png"}}, {{"uri", "tiny.png"}}};
  g.doc["textures"] = {{{"source", 0}}, {{"source", 1}}};
  const json transform = {{"KHR_texture_transform", {{"offset", {0.5, 0.0}}}}};
  const int coated = g.add(
      "materials",
      {{"name", "coated"},
       {"pbrMetallicRoughness", {{"metallicFactor", 0.0}, {"baseColorFactor", {0.5, 0.02, 0.01, 1.0}}}},
       {"extensions",
        {{"KHR_materials_clearcoat",
          {{"clearcoatFactor", 0.8},
           {"clearcoatRoughnessFactor", 0.1},
           {"clearcoatTexture", {{"index", 0}}},
           {"clearcoatRoughnessTexture", {{"index", 1}, {"extensions", transform}}},
           {"clearcoatNormalTexture", {{"index", 1}, {"scale", 0.5}}}}}}}});
  const int velvet = g.add("materials",
                           {{"name", "velvet"},
                            {"pbrMetallicRoughness", {{"metallicFactor", 0.0}}},
                            {"extensions",
                             {{"KHR_materials_sheen",
                               {{"sheenColorFactor", {0.9, 0.5, 0.1}},
                                {"sheenRoughnessFactor", 0.3},
                                {"sheenColorTexture", {{"index", 0}}},
                                {"sheenRoughnessTexture", {{"index", 1}}}}}}}});
  const int unlit = g.add("materials", {{"name", "unlit"},
                                        {"pbrMetallicRoughness",
                                         {{"baseColorFactor", {0.2, 0.4, 0.6, 1.0}},
                                          {"baseColorTexture", {{"index", 0}}},
                                          {"metallicFactor", 1.0}}},
                                        {"emissiveFactor", {1.0, 1.0, 1.0}},
                                        {"doubleSided", true},
                                        {"extensions", {{"KHR_materials_unlit", json::object()}}}});
  const int textured = g.add(
      "materials", {{"name", "textured factors"},
                    {"pbrMetallicRoughness", {{"metallicFactor", 0.0}}},
                    {"extensions",
                     {{"KHR_materials_transmission", {{"transmissionFactor", 0.5}, {"transmissionTexture", {{"index", 0}}}}},
                      {"KHR_materials_specular",
                       {{"specularFactor", 0.5},
                        {"specularColorFactor", {1.0, 0.5, 2.0}},
                        {"specularTexture", {{"index", 1}}},
                        {"specularColorTexture", {{"index", 0}}}}}}}});
  const int plain = g.add("materials", {{"name", "no layers"},
                                        {"pbrMetallicRoughness", {{"metallicFactor", 0.0}}},
                                        {"extensions",
                                         {{"KHR_materials_clearcoat", {{"clearcoatTexture", {{"index", 0}}}}},
                                          {"KHR_materials_sheen", {{"sheenRoughnessFactor", 0.5}}}}}});
  for (int m : {coated, velvet, unlit, textured, plain})
    g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", g.positions(kTriangle)}}}, {"material", m}})}});
  g.doc["extensionsUsed"] = {"KHR_materials_clearcoat", "KHR_materials_sheen", "KHR_materials_unlit",
                             "KHR_materials_transmission", "KHR_materials_specular", "KHR_texture_transform"};
  g.doc["extensionsRequired"] = {"KHR_materials_clearcoat", "KHR_materials_sheen", "KHR_materials_unlit"};
  const Scene s = g.load(dir);
  const caustica::Material* c = findMaterial(s, "coated");
  CHECK(c->clearcoat == doctest::Approx(0.8));
  CHECK(c->clearcoatRoughness == doctest::Approx(0.1));
  CHECK(c->clearcoatTexture >= 0);
  REQUIRE(c->clearcoatRoughnessTexture >= 0);
  CHECK(s.textures[std::size_t(c->clearcoatRoughnessTexture)].uvRow0.z == doctest::Approx(0.5));  // its transform
  CHECK(c->clearcoatNormalTexture >= 0);
  CHECK(c->clearcoatNormalScale == 0.5f);
  CHECK(c->hasClearcoat());
  CHECK(c->readsTextures());
  const caustica::Material* v = findMaterial(s, "velvet");
  CHECK(v->sheenColor == glm::vec3(0.9f, 0.5f, 0.1f));
  CHECK(v->sheenRoughness == doctest::Approx(0.3));
  CHECK(v->sheenColorTexture >= 0);
  CHECK(v->sheenRoughnessTexture >= 0);
  CHECK(v->hasSheen());
  // Unlit: an emitter of its base colour (factor x texture) that reflects nothing; the PBR fallbacks
  // (metal, emission) are not used, doubleSided is.
  const caustica::Material* u = findMaterial(s, "unlit");
  CHECK(u->unlit);
  CHECK(u->emission == glm::vec3(0.2f, 0.4f, 0.6f));
  CHECK(u->emissiveTexture >= 0);
  CHECK(u->baseColor == glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  CHECK(u->baseColorTexture == -1);  // OPAQUE: its alpha is not read
  CHECK(u->metallic == 0.0f);
  CHECK(u->specularF90 == 0.0f);
  CHECK(u->doubleSided);
  const caustica::Material* t = findMaterial(s, "textured factors");
  CHECK(t->transmissionTexture >= 0);
  CHECK(t->specularTexture >= 0);
  CHECK(t->specularColorTexture >= 0);
  CHECK(t->specularColorFactor == glm::vec3(1.0f, 0.5f, 2.0f));
  CHECK(t->specularFactor == 0.5f);
  CHECK(t->hasFactorTextures());
  // Layers that are off (no factor, no colour) keep no textures: nothing to read.
  const caustica::Material* p = findMaterial(s, "no layers");
  CHECK(!p->hasClearcoat());
  CHECK(!p->hasSheen());
  CHECK(p->clearcoatTexture == -1);
  CHECK(!p->readsTextures());
  for (const auto& w : s.warnings) {
    CAPTURE(w);
    CHECK(w.find("Texture") == std::string::npos);  // no texture is ignored any more
    CHECK(w.find("unsupported") == std::string::npos);
  }
}

TEST_CASE("textures: a material whose textures all name TEXCOORD_1 reads that set; mixed sets fall back to TEXCOORD_0") {
  TempDir dir;
  const unsigned char png[16] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 128};
  REQUIRE(stbi_write_png((dir.path / "tiny.png").string().c_str(), 2, 2, 4, png, 8));
  Gltf g;
  g.doc["images"] = {{{"uri", "tiny.png"}}};
  g.doc["textures"] = {{{"source", 0}}};
  const int uv0 = g.accessor(std::vector<float>{0.1f, 0.1f, 0.2f, 0.1f, 0.1f, 0.2f}, kFloat, "VEC2");
  const int uv1 = g.accessor(std::vector<float>{0.7f, 0.7f, 0.9f, 0.7f, 0.7f, 0.9f}, kFloat, "VEC2");
  const int set1 = g.add("materials", {{"name", "set1"},
                                       {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}, {"texCoord", 1}}}}},
                                       {"normalTexture", {{"index", 0}, {"texCoord", 1}}}});
  const int mixed = g.add("materials", {{"name", "mixed"},
                                        {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}, {"texCoord", 1}}}}},
                                        {"emissiveTexture", {{"index", 0}}}});
  const int pos = g.positions(kTriangle);
  g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv0}, {"TEXCOORD_1", uv1}}}, {"material", set1}})}});
  g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv0}, {"TEXCOORD_1", uv1}}}, {"material", mixed}})}});
  g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv0}}}, {"material", set1}})}});
  const Scene s = g.load(dir);
  REQUIRE(s.triangles.size() == 3);
  CHECK(findMaterial(s, "set1")->texCoord == 1);
  CHECK(findMaterial(s, "mixed")->texCoord == 0);
  CHECK(hasWarning(s, "TEXCOORD_0, TEXCOORD_1"));
  CHECK(hasWarning(s, "which the primitive lacks"));
  for (const caustica::Triangle& t : s.triangles) {
    const std::size_t i = std::size_t(&t - s.triangles.data());
    const bool readsSet1 = s.materials[t.material].name == "set1" && caustica::triangleUv(s, i, 1).x > 0.5f;
    const glm::vec2 expect = readsSet1 ? glm::vec2(0.9f, 0.7f) : glm::vec2(0.2f, 0.1f);
    CHECK(glm::length(caustica::triangleUv(s, i, 1) - expect) < 1e-6f);
  }
  int set1Triangles = 0;
  for (std::size_t i = 0; i < s.triangles.size(); ++i) set1Triangles += caustica::triangleUv(s, i, 0).x > 0.5f;
  CHECK(set1Triangles == 1);  // only the primitive that has TEXCOORD_1
}

TEST_CASE("external buffers: percent-encoded file names") {
  TempDir dir;
  Gltf g;
  g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", g.positions(kTriangle)}}}})}});
  dir.write("my data.bin", g.bin);
  json doc = g.doc;
  doc["buffers"] = json::array({{{"byteLength", g.bin.size()}, {"uri", "my%20data.bin"}}});
  const Scene s = caustica::loadScene(dir.write("external.gltf", doc.dump()));
  REQUIRE(s.triangles.size() == 1);
  CHECK(near(s.triangles[0].p[2], glm::vec3(0, 1, 0)));
}

TEST_CASE("bad input files throw caustica::Error naming the file and the problem") {
  // The files are generated by scripts/make-assets (bad_files, hostile_files).
  struct Case {
    const char* file;
    const char* expected;
  };
  const Case cases[] = {
      {"not-a-scene.txt", "unsupported file extension"},
      {"truncated.gltf", "invalid JSON"},
      {"not-json.gltf", "invalid JSON"},
      {"deep-nesting.gltf", "nested"},
      {"no-asset.gltf", "asset"},
      {"wrong-version.gltf", "asset.version"},
      {"string-for-number.gltf", "accessors[0].count"},
      {"string-for-index.gltf", "nodes[0].mesh"},
      {"unknown-required-extension.gltf", "EXT_caustica_unknown"},
      {"lines-only.gltf", "no triangles"},
      {"empty-scene.gltf", "no triangles"},
      {"degenerate-only.gltf", "zero area"},
      {"index-out-of-range.gltf", "index 99"},
      {"accessor-overrun.gltf", "overrun"},
      {"bufferview-overrun.gltf", "bufferViews[1]"},
      {"bad-stride.gltf", "byteStride"},
      {"bad-component-type.gltf", "component type"},
      {"mesh-index-out-of-range.gltf", "mesh"},
      {"material-index-out-of-range.gltf", "material"},
      {"bad-alpha-mode.gltf", "alphaMode"},
      {"nan-position.gltf", "NaN"},
      {"inf-position.gltf", "infinite"},
      {"cycle.gltf", "cycle"},
      {"two-parents.gltf", "two parents"},
      {"camera-yfov-zero.gltf", "yfov"},
      {"camera-yfov-negative.gltf", "yfov"},
      {"bad-sparse-index.gltf", "sparse"},
      {"missing-bin.gltf", "missing.bin"},
      {"bin-size-mismatch.gltf", "bin-size-mismatch.bin"},
      {"missing-image.gltf", "missing.png"},
      {"bad-image-data.gltf", "images[0]"},
      {"bad-magic.glb", "magic"},
      {"truncated.glb", "truncated"},
      {"bin-chunk-overrun.glb", "BIN chunk"},
      {"does-not-exist.gltf", "not found"},
      // Untrusted input (docs/untrusted-input.md): references out of the folder and declared sizes.
      {"escape-dotdot-buffer.gltf", "buffers[0].uri '../../../../../../../../etc/passwd' leads outside the scene's folder"},
      {"escape-absolute-buffer.gltf", "buffers[0].uri '/etc/hostname' leads outside the scene's folder"},
      {"escape-percent-encoded-buffer.gltf", "buffers[0].uri '%2e%2e/%2E%2E/%2e%2e/etc/passwd' leads outside"},
      {"escape-dotdot-image.gltf", "images[0].uri '../../../../../../../../etc/passwd' leads outside the scene's folder"},
      {"escape-absolute-image.gltf", "images[0].uri '/etc/passwd' leads outside the scene's folder"},
      {"huge-buffer-length.gltf", "buffers[0].byteLength is 1125899906842668, which brings the buffers to"},
      {"many-large-buffers.gltf", "buffers[11].byteLength is 104857600, which brings the buffers to 1100 MiB, more "
                                  "than the limit of 1024 MiB"},
      {"many-huge-images.gltf", "images[4] (8192x8192) brings the decoded textures to 1280 MiB, more than the "
                                "limit of 1024 MiB"},
      {"huge-accessor-count.gltf", "declared triangles to 1000000000000000, more than the limit of 16777216"},
      {"wide-node-tree.gltf", "nodes[17] (meshes[1]) brings the scene's declared triangles to 17000001"},
      {"deep-node-tree.gltf", "nodes[1023]: its world transform is not finite"},
      // Malformed compressed data (scripts/make-wild-data --corrupt, from tests/data/wild/).
      {"draco-truncated.glb", "KHR_draco_mesh_compression: the Draco data cannot be decoded"},
      {"draco-not-draco.glb", "KHR_draco_mesh_compression: not Draco data"},
      {"draco-count-mismatch.glb", "the Draco mesh has 4 points, but the accessor's count is 5"},
      {"draco-unknown-attribute.glb", "attributes.POSITION names no attribute of the Draco mesh"},
      {"meshopt-corrupt-vertices.glb", "EXT_meshopt_compression: the compressed data is corrupt (meshoptimizer's "
                                       "ATTRIBUTES decoder"},
      {"meshopt-truncated-indices.glb", "the compressed data is corrupt (meshoptimizer's TRIANGLES decoder"},
      {"meshopt-bad-stride.glb", "EXT_meshopt_compression.byteStride is 6; ATTRIBUTES need a multiple of 4"},
      {"meshopt-filter-stride.glb", "does not suit filter QUATERNION"},
      {"meshopt-image-in-fallback.glb", "images[0] lies in buffers[1], an EXT_meshopt_compression fallback buffer"},
      {"quantized-undeclared.glb", "has component type normalized SHORT; allowed: FLOAT"},
      {"webp-corrupt.glb", "images[0] could not be loaded: not a decodable WebP image"},
  };
  for (const Case& c : cases) {
    CAPTURE(std::string(c.file));
    const std::string path = source(std::string("tests/data/bad/") + c.file);
    const std::string error = loadError(path);
    CHECK(error.rfind(path + ": ", 0) == 0);
    CHECK(error.find(c.expected) != std::string::npos);
    CHECK(error.find('\n') == std::string::npos);
  }
  TempDir dir;
  fs::create_directories(dir.path / "folder.gltf");
  CHECK(loadError((dir.path / "folder.gltf").string()).find("directory") != std::string::npos);
  CHECK(loadError(dir.write("empty.glb", "")).find("empty") != std::string::npos);
}

TEST_CASE("mutated files only ever throw caustica::Error") {
  // Truncations and byte flips of a small valid scene (JSON and GLB); each must load or throw
  // caustica::Error (loadError fails the test on any other exception; a crash fails the run).
  TempDir dir;
  Gltf g;
  const int indices = g.accessor(std::vector<std::uint16_t>{0, 1, 2}, kShort, "SCALAR");
  g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", g.positions(kTriangle)},
                                           {"NORMAL", g.accessor(kTriangleNormals, kFloat, "VEC3")}}},
                           {"indices", indices},
                           {"material", g.diffuse()}})}});
  const std::string text = g.text();
  json glbDoc = g.doc;
  glbDoc["buffers"] = json::array({{{"byteLength", g.bin.size()}}});
  std::string glbJson = glbDoc.dump();
  while (glbJson.size() % 4) glbJson += ' ';
  std::string bin = g.bin;
  while (bin.size() % 4) bin += '\0';
  auto u32 = [](std::size_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };  // little-endian host
  const std::string glb = "glTF" + u32(2) + u32(12 + 8 + glbJson.size() + 8 + bin.size()) + u32(glbJson.size()) +
                          "JSON" + glbJson + u32(bin.size()) + std::string("BIN\0", 4) + bin;
  CHECK(caustica::loadScene(dir.write("valid.glb", glb)).triangles.size() == 1);
  CHECK(caustica::loadScene(dir.write("valid.gltf", text)).triangles.size() == 1);

  std::uint32_t seed = 12345;
  auto next = [&seed] { return seed = seed * 1664525u + 1013904223u; };
  int loaded = 0, rejected = 0;
  for (const std::string* original : {&text, &glb}) {
    const std::string ext = original == &glb ? ".glb" : ".gltf";
    for (std::size_t cut = 0; cut < original->size(); cut += 13) {
      const std::string error = loadError(dir.write("cut" + ext, original->substr(0, cut)));
      (error.empty() ? loaded : rejected)++;
    }
    for (int trial = 0; trial < 150; ++trial) {
      std::string bytes = *original;
      for (int flips = 1 + int(next() % 3); flips > 0; --flips)
        bytes[next() % bytes.size()] = char(next() >> 24);
      const std::string error = loadError(dir.write("flip" + ext, bytes));
      (error.empty() ? loaded : rejected)++;
      if (!error.empty()) CHECK(error.find('\n') == std::string::npos);
    }
  }
  CHECK(rejected > 0);
  CHECK(loaded > 0);
}

// ---- untrusted input (docs/untrusted-input.md) ---------------------------------------------------

// The error message for loading `path` with `options` ("" when it loads).
std::string loadError(const std::string& path, const caustica::LoadOptions& options) {
  try {
    caustica::loadScene(path, options);
  } catch (const caustica::Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    FAIL("non-caustica exception for ", path, ": ", e.what());
  }
  return "";
}

TEST_CASE("untrusted input: buffer and image files outside the scene's folder are refused by name") {
  // Layout: DIR/sc/scene.gltf refers to files around it; DIR/outside.bin, DIR/outside.png and
  // DIR/scx/data.bin lie outside the folder (scx shares sc's first letters: no string-prefix match).
  TempDir dir;
  Gltf g;
  g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", g.positions(kTriangle)}}}})}});
  const fs::path folder = dir.path / "sc";
  fs::create_directories(folder / "sub");
  fs::create_directories(dir.path / "scx");
  fs::create_directories(dir.path / "outdir");
  dir.write("outside.bin", g.bin);
  dir.write("scx/data.bin", g.bin);
  dir.write("outdir/data.bin", g.bin);
  dir.write("sc/inside.bin", g.bin);
  const unsigned char png[4] = {10, 20, 30, 255};
  REQUIRE(stbi_write_png((dir.path / "outside.png").string().c_str(), 1, 1, 4, png, 4));
  fs::create_symlink("../outside.bin", folder / "link.bin");                 // file symlink out
  fs::create_symlink(dir.path / "scx" / "data.bin", folder / "prefix.bin");  // absolute, to a sibling
  fs::create_symlink("../outdir", folder / "linkdir");                       // directory symlink out
  fs::create_symlink("inside.bin", folder / "inner.bin");                    // symlink that stays inside
  fs::create_symlink("../outside.png", folder / "image.png");

  auto sceneWith = [&](const std::string& bufferUri, const std::string& imageUri) {
    json doc = g.doc;
    doc["buffers"] = json::array({{{"byteLength", g.bin.size()}, {"uri", bufferUri}}});
    if (!imageUri.empty()) {
      doc["images"] = {{{"uri", imageUri}}};
      doc["textures"] = {{{"source", 0}}};
      doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"metallicFactor", 0.0}}}}};
      doc["meshes"][0]["primitives"][0]["material"] = 0;
    }
    return dir.write("sc/scene.gltf", doc.dump());
  };
  caustica::LoadOptions strict, lax;
  lax.allowOutsidePaths = true;
  const std::string absolute = (dir.path / "outside.bin").string();
  for (const std::string& uri : {std::string("../outside.bin"), absolute, std::string("sub/../../outside.bin"),
                                 std::string("%2e%2e/outside.bin"), std::string("link.bin"),
                                 std::string("prefix.bin"), std::string("linkdir/data.bin")}) {
    CAPTURE(uri);
    const std::string path = sceneWith(uri, "");
    const std::string error = loadError(path, strict);
    CHECK(error == path + ": buffers[0].uri '" + uri +
                       "' leads outside the scene's folder (use --allow-outside-paths to permit)");
    // Nothing about the target's size ("... is N bytes", the former leak); a bare number could be in the temp path.
    CHECK(error.find(" is " + std::to_string(g.bin.size()) + " bytes") == std::string::npos);
    CHECK(error.find("bytes") == std::string::npos);
    // Permitted, the same file loads.
    CHECK(loadError(path, lax) == "");
    CHECK(caustica::loadScene(path, lax).triangles.size() == 1);
  }
  // A symlink that stays inside the folder, and the folder reached through a symlink, are fine.
  CHECK(caustica::loadScene(sceneWith("inner.bin", ""), strict).triangles.size() == 1);
  fs::create_symlink(folder, dir.path / "sc-link");
  CHECK(caustica::loadScene((dir.path / "sc-link" / "scene.gltf").string(), strict).triangles.size() == 1);

  // Images: refused by name before tinygltf opens them; permitted, the texture is decoded.
  for (const std::string& uri : {std::string("../outside.png"), std::string("image.png"),
                                 (dir.path / "outside.png").string()}) {
    CAPTURE(uri);
    const std::string path = sceneWith("inside.bin", uri);
    CHECK(loadError(path, strict) == path + ": images[0].uri '" + uri +
                                         "' leads outside the scene's folder (use --allow-outside-paths to permit)");
    const Scene s = caustica::loadScene(path, lax);
    REQUIRE(s.textures.size() == 1);
    CHECK(s.textures[0].rgba == std::vector<std::uint8_t>{10, 20, 30, 255});
  }
}

TEST_CASE("untrusted input: buffers, textures and triangles over the limits are refused before loading") {
  TempDir dir;
  caustica::LoadOptions options;

  // Buffers: the declared byteLengths add up over the limit before any file is looked for.
  Gltf g;
  g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", g.positions(kTriangle)}}}})}});
  json doc = g.doc;
  doc["buffers"] = json::array({{{"byteLength", g.bin.size()}, {"uri", "data.bin"}},
                                {{"byteLength", 3u << 20}, {"uri", "absent.bin"}}});
  dir.write("data.bin", g.bin);
  const std::string buffers = dir.write("buffers.gltf", doc.dump());
  options.maxBufferBytes = 2u << 20;
  CHECK(loadError(buffers, options) ==
        buffers + ": buffers[1].byteLength is 3145728, which brings the buffers to 3 MiB, more than the limit of "
                  "2 MiB (use --max-buffer-mib to raise it)");
  options.maxBufferBytes = 4u << 20;  // under the limit the missing file is what is wrong
  CHECK(loadError(buffers, options).find("buffers[1].uri 'absent.bin': file not found") != std::string::npos);
  CHECK(loadError(buffers).find("file not found") != std::string::npos);  // the default limit is larger

  // Triangles: counted from the accessors over all mesh instances before any is decoded.
  Gltf t;
  const int mesh = t.mesh({{"attributes", {{"POSITION", t.positions(kTriangle)}}}});
  t.root({{"mesh", mesh}});
  t.root({{"mesh", mesh}, {"translation", {0, 0, 1}}});
  const std::string triangles = dir.write("triangles.gltf", t.text());
  options = {};
  options.maxTriangles = 1;
  CHECK(loadError(triangles, options) ==
        triangles + ": nodes[1] (meshes[0]) brings the scene's declared triangles to 2, more than the limit of 1 "
                    "(use --max-triangles to raise it)");
  options.maxTriangles = 2;
  CHECK(caustica::loadScene(triangles, options).triangles.size() == 2);

  // Textures: two 16x16 images decode to 1 KiB each; the header's size is checked before decoding.
  std::vector<unsigned char> pixels(16 * 16 * 4, 200);
  REQUIRE(stbi_write_png((dir.path / "a.png").string().c_str(), 16, 16, 4, pixels.data(), 64));
  Gltf x;
  x.doc["images"] = {{{"uri", "a.png"}}, {{"uri", "a.png"}}};
  x.root({{"mesh", x.mesh({{"attributes", {{"POSITION", x.positions(kTriangle)}}}})}});
  const std::string textures = dir.write("textures.gltf", x.text());
  options = {};
  options.maxTextureBytes = 1500;
  CHECK(loadError(textures, options) ==
        textures + ": images[1] (16x16) brings the decoded textures to 2048 bytes, more than the limit of "
                   "1500 bytes "
                   "(use --max-texture-mib to raise it)");
  options.maxTextureBytes = 2048;
  CHECK(loadError(textures, options) == "");
}

TEST_CASE("untrusted input: raising a limit lets a hostile file past that check") {
  caustica::LoadOptions raised;
  raised.maxBufferBytes = 4ull << 30;
  CHECK(loadError(source("tests/data/bad/many-large-buffers.gltf"), raised).find("buffers[1].uri 'part-0.bin': file not found") !=
        std::string::npos);
  raised.maxTriangles = 1ull << 60;  // then the accessor's byte range is what is wrong
  CHECK(loadError(source("tests/data/bad/huge-accessor-count.gltf"), raised).find("overrun bufferViews[1]") !=
        std::string::npos);
}

TEST_CASE("instancing: keepInstances stores each mesh once; flattenInstances gives the flattened scene") {
  TempDir dir;
  Gltf g;
  const float r = std::sqrt(0.5f);
  // Mesh 0: two triangles with normals and texcoords; mesh 1: one emissive triangle without normals.
  const int shaded = g.mesh({{"attributes",
                              {{"POSITION", g.positions({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1, 0.5f, 0, 1, 0})},
                               {"NORMAL", g.accessor(std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1, r, 0, r, r, 0, r, 0, r, r},
                                                     kFloat, "VEC3")},
                               {"TEXCOORD_0", g.accessor(std::vector<float>{0, 0, 1, 0, 0, 1, 1, 0, 1, 1, 0, 1},
                                                         kFloat, "VEC2")}}},
                             {"material", g.diffuse()}});
  const int light = g.add("materials", {{"emissiveFactor", {1.0, 0.5, 0.25}}});
  const int emitter = g.mesh({{"attributes", {{"POSITION", g.positions({0, 0, 0, 2, 0, 0, 0, 0, 2})}}},
                              {"material", light}});
  g.root({{"mesh", shaded}});
  g.root({{"mesh", shaded}, {"scale", {-1.0, 2.0, 1.0}}, {"translation", {3, 0, 0}}});
  g.root({{"mesh", emitter}, {"rotation", {0.0, 0.0, r, r}}, {"translation", {0, 4, 0}}});
  const int parent = g.root({{"translation", {0, 0, -2}}, {"children", json::array()}});
  const int t = g.accessor(std::vector<float>{0, 0, 0, 5, 0, 0, 0, 5, 0}, kFloat, "VEC3");
  const int q = g.accessor(std::vector<float>{0, 0, 0, 1, 0, r, 0, r, 0, 0, 0, 1}, kFloat, "VEC4");
  const int s3 = g.accessor(std::vector<float>{1, 1, 1, 1, 1, 1, 0.5f, 0.5f, 0.5f}, kFloat, "VEC3");
  const int child = g.add("nodes", {{"mesh", emitter},
                                    {"extensions", {{"EXT_mesh_gpu_instancing",
                                                     {{"attributes", {{"TRANSLATION", t}, {"ROTATION", q}, {"SCALE", s3}}}}}}}});
  g.doc["nodes"][std::size_t(parent)]["children"].push_back(child);
  g.doc["extensionsUsed"] = {"EXT_mesh_gpu_instancing"};
  const std::string path = dir.write("instanced.gltf", g.text());

  const Scene flat = caustica::loadScene(path);
  caustica::LoadOptions keep;
  keep.keepInstances = true;
  Scene inst = caustica::loadScene(path, keep);
  CHECK(flat.instances.empty());
  REQUIRE(flat.triangles.size() == 2 + 2 + 1 + 3);
  REQUIRE(inst.meshes.size() == 2);
  CHECK(inst.triangles.size() == 3);  // each mesh once
  CHECK(inst.instances.size() == 6);  // 3 nodes + 3 EXT_mesh_gpu_instancing instances
  CHECK(inst.meshes[0].triangleCount == 2);
  CHECK(inst.meshes[1].triangleCount == 1);
  CHECK(caustica::sceneHasLights(inst));
  CHECK(near(inst.bounds.min, flat.bounds.min));
  CHECK(near(inst.bounds.max, flat.bounds.max));

  caustica::flattenInstances(inst);
  CHECK(inst.instances.empty());
  CHECK(inst.meshes.empty());
  REQUIRE(inst.triangles.size() == flat.triangles.size());
  for (std::size_t i = 0; i < flat.triangles.size(); ++i) {
    const caustica::Triangle& a = flat.triangles[i];
    const caustica::Triangle& b = inst.triangles[i];
    CAPTURE(i);
    CHECK(a.material == b.material);
    for (int k = 0; k < 3; ++k) {
      CHECK(a.p[k] == b.p[k]);  // the same double arithmetic: bit for bit
      // flattenInstances transforms the stored (octahedral) normal and encodes it again: within 2 x 4.3e-5 rad
      CHECK(near(a.normal(k), b.normal(k), 1e-4f));
      CHECK(caustica::triangleUv(flat, i, k) == caustica::triangleUv(inst, i, k));
    }
  }
  // EXT_mesh_gpu_instancing in the flattened scene: instance 1 is rotated 90 deg about y and moved by (5,0,0),
  // instance 2 halved and moved by (0,5,0), all under the parent's (0,0,-2).
  CHECK(near(flat.triangles[5].p[1], glm::vec3(2, 0, -2)));
  CHECK(near(flat.triangles[6].p[1], glm::vec3(5, 0, -4)));
  CHECK(near(flat.triangles[7].p[1], glm::vec3(1, 5, -2)));
}

TEST_CASE("instancing: limits count stored triangles; bad EXT_mesh_gpu_instancing is refused") {
  TempDir dir;
  Gltf g;
  const int mesh = g.mesh({{"attributes", {{"POSITION", g.positions({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0})}}},
                           {"material", g.diffuse()}});
  for (int i = 0; i < 10; ++i) g.root({{"mesh", mesh}, {"translation", {double(i), 0.0, 0.0}}});
  const std::string path = dir.write("ten.gltf", g.text());
  caustica::LoadOptions opts;
  opts.maxTriangles = 12;  // 20 flattened triangles; 2 stored, and 10 instances (also bounded by it)
  CHECK_THROWS_AS(caustica::loadScene(path, opts), caustica::Error);
  opts.keepInstances = true;
  const Scene s = caustica::loadScene(path, opts);
  CHECK(s.triangles.size() == 2);
  CHECK(s.instances.size() == 10);
  opts.maxTriangles = 9;
  CHECK_THROWS_AS(caustica::loadScene(path, opts), caustica::Error);  // 10 instances

  Gltf bad;
  const int m = bad.mesh({{"attributes", {{"POSITION", bad.positions(kTriangle)}}}, {"material", bad.diffuse()}});
  const int t = bad.accessor(std::vector<float>{0, 0, 0, 1, 0, 0}, kFloat, "VEC3");
  const int sc = bad.accessor(std::vector<float>{1, 1, 1}, kFloat, "VEC3");
  bad.root({{"mesh", m},
            {"extensions", {{"EXT_mesh_gpu_instancing", {{"attributes", {{"TRANSLATION", t}, {"SCALE", sc}}}}}}}});
  CHECK(loadError(dir.write("bad.gltf", bad.text())).find("different counts") != std::string::npos);
}

TEST_CASE("instancing: autoInstances keeps instances only where flattening multiplies the triangles") {
  TempDir dir;
  const auto scene = [&](int nodes) {
    Gltf g;
    const int mesh = g.mesh({{"attributes", {{"POSITION", g.positions({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0})}}},
                             {"material", g.diffuse()}});
    for (int i = 0; i < nodes; ++i) g.root({{"mesh", mesh}, {"translation", {double(i), 0.0, 0.0}}});
    return dir.write("nodes" + std::to_string(nodes) + ".gltf", g.text());
  };
  caustica::LoadOptions opts;
  opts.keepInstances = opts.autoInstances = true;  // --instances auto (factor 4)
  const Scene four = caustica::loadScene(scene(4), opts);  // 4x the stored triangles: flattened
  CHECK(four.instances.empty());
  CHECK(four.triangles.size() == 8);
  const Scene five = caustica::loadScene(scene(5), opts);  // 5x: kept
  CHECK(five.instances.size() == 5);
  CHECK(five.triangles.size() == 2);
  opts.maxTriangles = 7;  // 8 flattened triangles exceed the limit: kept, whatever the factor
  const Scene limited = caustica::loadScene(scene(4), opts);
  CHECK(limited.instances.size() == 4);
  // The flattened load is the plain one, bit for bit (not flattenInstances' float normals).
  caustica::LoadOptions plain;
  const Scene flat = caustica::loadScene(scene(4), plain);
  REQUIRE(flat.triangles.size() == four.triangles.size());
  for (std::size_t i = 0; i < flat.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      CHECK(flat.triangles[i].p[k] == four.triangles[i].p[k]);
      CHECK(flat.triangles[i].normalWord[k] == four.triangles[i].normalWord[k]);
    }
}

TEST_CASE("nothing dropped in silence: what is not rendered is named in one warning line") {
  TempDir dir;
  Gltf g;
  const int pos = g.positions(kTriangle);
  const int colors = g.accessor(std::vector<float>{1, 1, 1, 1, 1, 1, 1, 1, 1}, kFloat, "VEC3");
  const int uv2 = g.accessor(std::vector<float>{0, 0, 1, 0, 0, 1}, kFloat, "VEC2");
  const int mat = g.add("materials", {{"name", "aged"}, {"occlusionTexture", {{"index", 0}}}});
  const unsigned char png[4] = {255, 255, 255, 255};
  REQUIRE(stbi_write_png((dir.path / "ao.png").string().c_str(), 1, 1, 4, png, 4));
  g.doc["images"] = {{{"uri", "ao.png"}}};
  g.doc["textures"] = {{{"source", 0}}};
  const int mesh = g.mesh({{"attributes", {{"POSITION", pos}, {"COLOR_1", colors}, {"TEXCOORD_2", uv2},
                                           {"_BATCHID", colors}}},
                           {"material", mat}});
  g.root({{"mesh", mesh}});
  g.doc["scenes"].push_back({{"nodes", json::array()}});
  g.doc["extensionsUsed"] = {"KHR_materials_iridescence", "KHR_materials_sheen", "KHR_materials_clearcoat",
                             "KHR_materials_unlit", "KHR_animation_pointer"};
  const Scene s = g.load(dir);
  std::vector<std::string> lines;
  for (const std::string& w : s.warnings)
    if (w.find("not rendered: ") != std::string::npos) lines.push_back(w);
  REQUIRE(lines.size() == 1);
  const std::string& line = lines[0];
  CHECK(line.rfind(s.path + ": not rendered: ", 0) == 0);
  for (const char* rendered : {"clearcoat", "sheen", "unlit", "specular", "transmission"}) {  // the layers are rendered
    CAPTURE(std::string(rendered));
    CHECK(line.find(rendered) == std::string::npos);
  }
  for (const char* named : {"extension(s) KHR_animation_pointer, KHR_materials_iridescence",
                            "vertex attribute(s) COLOR_1, TEXCOORD_2, _BATCHID",
                            "1 scene(s) besides the default one", "'aged': occlusionTexture"}) {
    CAPTURE(std::string(named));
    CHECK(line.find(named) != std::string::npos);
  }
  SUBCASE("a file with nothing unsupported gets no such line") {
    Gltf plain;
    const int m = plain.diffuse();
    plain.root({{"mesh", plain.mesh({{"attributes", {{"POSITION", plain.positions(kTriangle)}}}, {"material", m}})}});
    for (const std::string& w : plain.load(dir, "plain.gltf").warnings) CHECK(w.find("not rendered") == std::string::npos);
  }
}

TEST_CASE("a negative index is named with its value") {
  TempDir dir;
  Gltf g;
  g.root({{"mesh", -1}});
  const std::string error = loadError(dir.write("negative.gltf", g.text()));
  CHECK(error.find("nodes[0].mesh is -1; it must be a non-negative integer") != std::string::npos);
  CHECK(error.find("but it is an integer") == std::string::npos);
}
