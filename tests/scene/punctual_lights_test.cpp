// punctual_lights_test.cpp — KHR_lights_punctual: the loader (node placement, -Z direction, units,
// defaults, clear errors for bad lights), power-proportional packing, the spot falloff and
// --light-radius spheres (same power as the light they replace).
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "scene/punctual_lights.h"
#include "scene/scene.h"
#include "shading/sampling.h"
#include "util/error.h"
#include "util/math_constants.h"

using caustica::PunctualLight;
using caustica::PunctualType;
using caustica::Scene;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

// One triangle (a glTF file needs something to render) plus whatever lights and nodes a test adds.
json baseDocument() {
  const float xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::string bytes(reinterpret_cast<const char*>(xyz), sizeof xyz);
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string b64;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {  // 36 bytes: a multiple of 3, no padding
    const std::uint32_t v = std::uint32_t(std::uint8_t(bytes[i])) << 16 | std::uint32_t(std::uint8_t(bytes[i + 1])) << 8 |
                            std::uint8_t(bytes[i + 2]);
    for (int k = 3; k >= 0; --k) b64 += table[(v >> (6 * k)) & 63];
  }
  return {{"asset", {{"version", "2.0"}}},
          {"extensionsUsed", {"KHR_lights_punctual"}},
          {"scene", 0},
          {"scenes", {{{"nodes", {0}}}}},
          {"nodes", {{{"mesh", 0}}}},
          {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}}},
          {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"},
                          {"min", {0, 0, 0}}, {"max", {1, 1, 0}}}}},
          {"bufferViews", {{{"buffer", 0}, {"byteLength", 36}}}},
          {"buffers", {{{"byteLength", 36}, {"uri", "data:application/octet-stream;base64," + b64}}}},
          {"extensions", {{"KHR_lights_punctual", {{"lights", json::array()}}}}}};
}

// Adds a light and a root node placing it; returns the node's index.
int addLight(json& doc, const json& light, const json& node = json::object()) {
  auto& lights = doc["extensions"]["KHR_lights_punctual"]["lights"];
  lights.push_back(light);
  json n = node;
  n["extensions"]["KHR_lights_punctual"]["light"] = lights.size() - 1;
  doc["nodes"].push_back(n);
  const int index = int(doc["nodes"].size() - 1);
  doc["scenes"][0]["nodes"].push_back(index);
  return index;
}

std::string writeFile(const json& doc) {
  static int counter = 0;
  const fs::path dir = fs::temp_directory_path() / ("caustica_punctual_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path file = dir / ("lights" + std::to_string(counter++) + ".gltf");
  std::ofstream(file) << doc.dump();
  return file.string();
}

std::string loadError(const json& doc) {
  const std::string path = writeFile(doc);
  try {
    caustica::loadScene(path);
  } catch (const caustica::Error& e) {
    const std::string what = e.what();
    CHECK_MESSAGE(what.find(path) != std::string::npos, "the message names the file: ", what);
    return what;
  }
  FAIL("loading did not fail: ", doc.dump());
  return "";
}

bool near(const glm::vec3& a, const glm::vec3& b, float eps = 1e-5f) { return glm::length(a - b) <= eps; }

}  // namespace

TEST_CASE("punctual lights: types, node hierarchy, -Z direction, units and defaults") {
  json doc = baseDocument();
  const double r = std::sqrt(0.5);
  // A point light in a child node: parent translation (0, 2, 0), child translation (1, 0, 0).
  doc["extensions"]["KHR_lights_punctual"]["lights"].push_back(
      {{"name", "bulb"}, {"type", "point"}, {"color", {1.0, 0.5, 0.25}}, {"intensity", 8.0}});
  doc["nodes"].push_back({{"translation", {1, 0, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  doc["nodes"].push_back({{"translation", {0, 2, 0}}, {"children", {1}}});
  doc["scenes"][0]["nodes"].push_back(2);
  // A spot rotated -90 degrees about +x: its -Z turns to -Y (pointing down), scaled (ignored).
  addLight(doc, {{"type", "spot"}, {"intensity", 3.0}, {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.6}}}},
           {{"translation", {0, 3, 0}}, {"rotation", {-r, 0.0, 0.0, r}}, {"scale", {5, 5, 5}}});
  // A spot with the default cone angles and a sun rotated 90 degrees about +y: -Z turns to -X.
  addLight(doc, {{"type", "spot"}, {"spot", json::object()}});
  addLight(doc, {{"type", "directional"}, {"intensity", 2.5}, {"range", 4.0}}, {{"rotation", {0.0, r, 0.0, r}}});
  const Scene s = caustica::loadScene(writeFile(doc));
  REQUIRE(s.punctualLights.size() == 4);
  // Depth-first order: node 0 (mesh), node 2 -> child 1, then 3, 4, 5.
  const PunctualLight& bulb = s.punctualLights[0];
  CHECK(bulb.type == PunctualType::Point);
  CHECK(bulb.name == "bulb");
  CHECK(near(bulb.position, glm::vec3(1, 2, 0)));
  CHECK(near(bulb.intensity, glm::vec3(8.0f, 4.0f, 2.0f)));  // colour x intensity, in cd
  const PunctualLight& spot = s.punctualLights[1];
  CHECK(spot.type == PunctualType::Spot);
  CHECK(near(spot.position, glm::vec3(0, 3, 0)));
  CHECK(near(spot.direction, glm::vec3(0, -1, 0)));
  CHECK(near(spot.intensity, glm::vec3(3.0f)));  // node scale does not change brightness
  CHECK(spot.innerCone == doctest::Approx(0.2));
  CHECK(spot.outerCone == doctest::Approx(0.6));
  const PunctualLight& plain = s.punctualLights[2];
  CHECK(near(plain.intensity, glm::vec3(1.0f)));  // defaults: white, intensity 1
  CHECK(plain.innerCone == 0.0f);
  CHECK(plain.outerCone == doctest::Approx(caustica::kPiD / 4.0));
  CHECK(near(plain.direction, glm::vec3(0, 0, -1)));
  const PunctualLight& sun = s.punctualLights[3];
  CHECK(sun.type == PunctualType::Directional);
  CHECK(near(sun.direction, glm::vec3(-1, 0, 0)));
  CHECK(near(sun.intensity, glm::vec3(2.5f)));  // lux
  bool rangeWarning = false;
  for (const auto& w : s.warnings) rangeWarning |= w.find("range is ignored") != std::string::npos;
  CHECK(rangeWarning);
  CHECK(caustica::sceneHasLights(s));
}

TEST_CASE("punctual lights: bad lights are errors naming the file and the property") {
  struct Case {
    json light;
    const char* expect;
  };
  const std::vector<Case> cases = {
      {{{"type", "point"}, {"intensity", -1.0}}, "intensity is -1; it must not be negative"},
      {{{"type", "area"}}, "type is \"area\"; it must be point, spot or directional"},
      {{{"intensity", 1.0}}, "type is missing"},
      {{{"type", "point"}, {"color", {1.0, -0.5, 1.0}}}, "color[1] is -0.5"},
      {{{"type", "point"}, {"color", {1.0, 1.0}}}, "color must have 3 numbers"},
      {{{"type", "point"}, {"intensity", "bright"}}, "intensity must be a number"},
      {{{"type", "point"}, {"range", 0.0}}, "range is 0; it must be positive"},
      {{{"type", "spot"}}, "spot is missing"},
      {{{"type", "spot"}, {"spot", {{"innerConeAngle", 0.5}, {"outerConeAngle", 0.4}}}}, "0 <= inner < outer <= pi/2"},
      {{{"type", "spot"}, {"spot", {{"outerConeAngle", 2.0}}}}, "0 <= inner < outer <= pi/2"},
      {{{"type", "spot"}, {"spot", {{"innerConeAngle", -0.1}}}}, "0 <= inner < outer <= pi/2"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.light.dump());
    json doc = baseDocument();
    addLight(doc, c.light);
    const std::string what = loadError(doc);
    CHECK_MESSAGE(what.find(c.expect) != std::string::npos, what);
    CHECK(what.find("KHR_lights_punctual.lights[0]") != std::string::npos);
  }
  json doc = baseDocument();
  doc["nodes"].push_back({{"extensions", {{"KHR_lights_punctual", {{"light", 3}}}}}});
  doc["scenes"][0]["nodes"].push_back(1);
  const std::string what = loadError(doc);
  CHECK_MESSAGE(what.find("nodes[1].extensions.KHR_lights_punctual.light is 3, but the file has 0 lights") !=
                    std::string::npos,
                what);
  json required = baseDocument();
  required["extensionsRequired"] = {"KHR_lights_punctual"};
  addLight(required, {{"type", "point"}});
  CHECK(caustica::loadScene(writeFile(required)).punctualLights.size() == 1);  // a supported extension
}

TEST_CASE("punctual lights: the smooth spot falloff of the glTF specification") {
  const float cosOuter = std::cos(0.6f), cosInner = std::cos(0.2f);
  CHECK(caustica::spotFalloff(1.0f, cosOuter, cosInner) == 1.0f);
  CHECK(caustica::spotFalloff(std::cos(0.2f), cosOuter, cosInner) == doctest::Approx(1.0));
  CHECK(caustica::spotFalloff(std::cos(0.6f), cosOuter, cosInner) == doctest::Approx(0.0));
  CHECK(caustica::spotFalloff(std::cos(1.0f), cosOuter, cosInner) == 0.0f);
  const float c = std::cos(0.4f);
  const float t = (c - cosOuter) / (cosInner - cosOuter);
  CHECK(caustica::spotFalloff(c, cosOuter, cosInner) == doctest::Approx(t * t).epsilon(1e-6));
  // inner == outer: a hard edge, as the spec's max(0.001, ...) makes it
  CHECK(caustica::spotFalloff(std::cos(0.3f), std::cos(0.3f), std::cos(0.3f)) == doctest::Approx(0.0));
  CHECK(caustica::spotFalloff(std::cos(0.25f), std::cos(0.3f), std::cos(0.3f)) == 1.0f);
}

TEST_CASE("punctual lights: packed with selection probabilities proportional to power") {
  caustica::Bounds bounds;
  bounds.grow(glm::vec3(-1.0f));
  bounds.grow(glm::vec3(1.0f));  // bounding sphere radius sqrt(3)
  std::vector<PunctualLight> lights(4);
  lights[0].type = PunctualType::Point;
  lights[0].intensity = glm::vec3(2.0f);
  lights[1].type = PunctualType::Spot;
  lights[1].intensity = glm::vec3(0.0f);  // emits nothing: left out
  lights[2].type = PunctualType::Spot;
  lights[2].intensity = glm::vec3(5.0f);
  lights[2].innerCone = 0.1f;
  lights[2].outerCone = 0.5f;
  lights[3].type = PunctualType::Directional;
  lights[3].intensity = glm::vec3(1.0f);
  const double p0 = 4.0 * caustica::kPiD * 2.0;
  const double p2 = 2.0 * caustica::kPiD * 5.0 * (1.0 - 0.5 * (std::cos(0.1) + std::cos(0.5)));
  const double p3 = caustica::kPiD * 3.0;
  CHECK(caustica::punctualPower(lights[0], bounds) == doctest::Approx(p0));
  CHECK(caustica::punctualPower(lights[2], bounds) == doctest::Approx(p2));
  CHECK(caustica::punctualPower(lights[3], bounds) == doctest::Approx(p3));
  const auto packed = caustica::packPunctualLights(lights, bounds, "x.gltf");
  REQUIRE(packed.count.x == 3);
  const double total = p0 + p2 + p3;
  CHECK(packed.light[0].select.x == doctest::Approx(p0 / total));
  CHECK(packed.light[1].select.x == doctest::Approx(p2 / total));
  CHECK(packed.light[2].select.x == doctest::Approx(p3 / total));
  CHECK(packed.light[1].select.y == doctest::Approx((p0 + p2) / total));
  CHECK(packed.light[2].select.y == 1.0f);
  CHECK(packed.light[1].position.w == float(caustica::gpu::kPunctualSpot));
  CHECK(packed.light[1].direction.w == doctest::Approx(std::cos(0.5)));
  CHECK(packed.light[1].intensity.w == doctest::Approx(std::cos(0.1)));
  CHECK(caustica::packPunctualLights({}, bounds, "x.gltf").count.x == 0);
  std::vector<PunctualLight> many(CAUSTICA_MAX_PUNCTUAL + 1);
  CHECK_THROWS_WITH_AS(caustica::packPunctualLights(many, bounds, "x.gltf"),
                       doctest::Contains("x.gltf: the scene has 129 punctual lights"), caustica::Error);
}

TEST_CASE("--light-radius: point and spot lights become emissive spheres of the same power") {
  Scene s;
  s.materials.push_back(caustica::Material{});
  PunctualLight point, spot, sun;
  point.position = glm::vec3(1, 2, 3);
  point.intensity = glm::vec3(3.0f, 2.0f, 1.0f);
  spot.type = PunctualType::Spot;
  spot.direction = glm::vec3(0, -1, 0);
  spot.intensity = glm::vec3(4.0f);
  sun.type = PunctualType::Directional;
  s.punctualLights = {point, spot, sun};
  CHECK_THROWS_AS(caustica::applyLightRadius(s, 0.0f), caustica::Error);
  caustica::applyLightRadius(s, 0.25f);
  REQUIRE(s.punctualLights.size() == 1);  // the directional light stays a delta light
  CHECK(s.punctualLights[0].type == PunctualType::Directional);
  REQUIRE(s.materials.size() == 3);
  REQUIRE(s.triangles.size() == 640);
  double area = 0.0;
  for (std::size_t i = 0; i < 320; ++i) {
    const auto& t = s.triangles[i];
    CHECK(t.material == 1u);
    const glm::vec3 c = glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]);
    area += 0.5 * glm::length(c);
    CHECK(glm::dot(c, (t.p[0] + t.p[1] + t.p[2]) / 3.0f - point.position) > 0.0f);  // fronts face out
    for (const auto& p : t.p) CHECK(glm::length(p - point.position) == doctest::Approx(0.25));
  }
  CHECK(area == doctest::Approx(4.0 * caustica::kPiD * 0.0625).epsilon(0.03));  // close to the sphere's
  // Power: a Lambertian emitter of radiance L and area A emits pi L A; the point light 4 pi I.
  const glm::vec3 L = s.materials[1].emission;
  CHECK(caustica::kPiD * L.x * area == doctest::Approx(4.0 * caustica::kPiD * 3.0).epsilon(1e-5));
  CHECK(caustica::kPiD * L.z * area == doctest::Approx(4.0 * caustica::kPiD * 1.0).epsilon(1e-5));
  CHECK(s.materials[1].baseColor == glm::vec4(0, 0, 0, 1));
  REQUIRE(s.spotEmitters.size() == 1);
  CHECK(s.spotEmitters[0].material == 2u);
  CHECK(near(s.spotEmitters[0].axis, glm::vec3(0, -1, 0)));
  CHECK(caustica::sceneHasLights(s));
}
