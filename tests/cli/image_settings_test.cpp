// image_settings_test.cpp — the one field list of the image settings (visitFields): every field is
// listed, read from the command line, printed, and part of the accumulation identity exactly when its
// role says so; and the settings' scene side reaches the Scene (applySceneSettings). No GL.
#include <doctest/doctest.h>

#include <set>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "cli/cli_common.h"
#include "cli/image_settings.h"
#include "scene/punctual_lights.h"
#include "util/error.h"

using namespace caustica;
using namespace caustica::cli;

namespace {

// A different valid value of each type a setting has. A field of a new type fails to compile here:
// give its type a line.
void perturb(int& v) { v += 1; }
void perturb(std::uint32_t& v) { v += 1; }
void perturb(float& v) { v += 0.125f; }
void perturb(double& v) { v += 0.125; }
void perturb(bool& v) { v = !v; }
void perturb(std::string& v) { v += "x"; }
template <class E, std::enable_if_t<std::is_enum_v<E>, int> = 0>
void perturb(E& v) {
  v = static_cast<E>(static_cast<int>(v) == 0 ? 1 : 0);
}

struct FieldInfo {
  std::string name;
  SettingRole role;
};

std::vector<FieldInfo> fields() {
  std::vector<FieldInfo> out;
  ImageSettings s;
  visitFields(s, [&](const char* name, SettingRole role, auto&) { out.push_back({name, role}); });
  return out;
}

// A copy of the defaults with the field at `index` (visitFields order) changed.
ImageSettings withFieldChanged(std::size_t index) {
  ImageSettings s;
  std::size_t i = 0;
  visitFields(s, [&](const char*, SettingRole, auto& v) {
    if (i++ == index) perturb(v);
  });
  return s;
}

template <class S, class Visit>
std::size_t countVisits(S& s, Visit&& visitor) {
  std::size_t n = 0;
  visitor(s, [&](const char*, SettingRole, auto&) { ++n; });
  return n;
}

}  // namespace

TEST_CASE("image settings: every field is listed once, under its own key") {
  // fieldCount counts the struct's fields; the visitors must visit as many (a field counted by the
  // static_assert but left without a visit line fails here).
  RenderSettings r;
  SceneSettings sc;
  ToneMapSettings t;
  ImageSettings all;
  CHECK(countVisits(r, [](auto& s, auto&& v) { visitFields(s, v); }) == fieldCount<RenderSettings>());
  CHECK(countVisits(sc, [](auto& s, auto&& v) { visitSceneFields(s, v); }) == fieldCount<SceneSettings>());
  CHECK(countVisits(t, [](auto& s, auto&& v) { visitToneFields(s, v); }) == fieldCount<ToneMapSettings>());
  CHECK(countVisits(all, [](auto& s, auto&& v) { visitFields(s, v); }) ==
        fieldCount<RenderSettings>() + fieldCount<SceneSettings>() + 1 + fieldCount<ToneMapSettings>());
  std::set<std::string> names;
  for (const FieldInfo& f : fields()) {
    INFO(f.name);
    CHECK(names.insert(f.name).second);  // the identity is read back as key -> value: keys must be unique
    CHECK(f.name.find(' ') == std::string::npos);
  }
}

TEST_CASE("image settings: changing any field changes the identity exactly when it changes the samples") {
  const ImageSettings defaults;
  const Camera camera;
  const std::string identity = accumulationIdentity(defaults, camera), summary = settingsSummary(defaults);
  const std::vector<FieldInfo> list = fields();
  int accumulation = 0;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const ImageSettings changed = withFieldChanged(i);
    INFO("field ", list[i].name, " (", std::string(settingRoleName(list[i].role)), ")");
    CHECK(settingsSummary(changed) != summary);  // printed, whatever its role
    const std::string other = accumulationIdentity(changed, camera);
    if (list[i].role == SettingRole::Accumulation) {
      ++accumulation;
      CHECK(other != identity);
      CHECK(identityDifference(identity, other, "checkpoint", "this render").find(list[i].name + ": checkpoint ") == 0);
    } else {
      CHECK(other == identity);  // speed and output settings may change between parts of one render
      CHECK(identityDifference(identity, other, "a", "b").empty());
    }
    if (i < fieldCount<RenderSettings>()) CHECK(changed.render != defaults.render);  // operator== sees every field
  }
  CHECK(accumulation >= 16);  // 10 RenderSettings, 5 scene, the camera; the rest speed or output
  // The camera that the index picked is part of it too.
  Camera moved = camera;
  moved.yfov += 0.01f;
  CHECK(identityDifference(identity, accumulationIdentity(defaults, moved), "checkpoint", "this render")
            .find("camera-view: checkpoint ") == 0);
}

TEST_CASE("image settings: the roles of the settings that do not change the samples") {
  std::set<std::string> speed, output;
  for (const FieldInfo& f : fields()) {
    if (f.role == SettingRole::Speed) speed.insert(f.name);
    if (f.role == SettingRole::Output) output.insert(f.name);
  }
  CHECK(speed == std::set<std::string>{"all-features", "samples-per-dispatch"});
  CHECK(output == std::set<std::string>{"exposure", "tonemap"});
}

TEST_CASE("image settings: every field is read from its option") {
  std::vector<OptionSpec> specs = sceneOptionSpecs();
  specs.push_back({"--exposure", "", "STOPS", ""});
  specs.push_back({"--tonemap", "", "CURVE", ""});
  Options opts("test", "", specs);
  REQUIRE(opts.parse({"--size", "64x32", "--seed", "5", "--max-depth", "9", "--integrator", "naive", "--dispersion",
                      "spectral", "--caster-probability", "0.25", "--guide-probability", "0.75", "--manifold", "on", "--light-tracing", "off", "--light-paths", "2", "--mode", "whitted", "--all-features",
                      "--samples-per-dispatch", "2", "--env", "0.5", "--env-strength", "2", "--env-rotation", "30",
                      "--background", "0.2,0.2,0.2", "--light-radius", "0.05", "--animation", "spin", "--anim-time", "1.5",
                      "--camera", "1", "--exposure", "1.5", "--tonemap", "clamp"}));
  const ImageSettings got = imageSettingsFrom(opts, Camera{}, 512), defaults;
  // Every field differs from its default: an option that is listed but not read stays at the default.
  std::vector<std::string> a, b, names;
  visitFields(got, [&](const char* name, SettingRole, const auto& v) {
    a.push_back(settingText(v));
    names.push_back(name);
  });
  visitFields(defaults, [&](const char*, SettingRole, const auto& v) { b.push_back(settingText(v)); });
  REQUIRE(a.size() == b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    INFO(names[i], ": ", a[i]);
    CHECK(a[i] != b[i]);
  }
  CHECK(settingsSummary(got).find("width 64, height 32, seed 5") == 0);
  CHECK(accumulationIdentity(got, Camera{}).find("env 0.5\nenv-strength 2\nenv-rotation 30\nbackground 0.2,0.2,0.2\n"
                                                 "light-radius 0.05\nanimation spin\nanim-time 1.5\ncamera 1\n") !=
        std::string::npos);
  // --frame N with --fps F is the time N / F.
  Options frame("test", "", sceneOptionSpecs());
  REQUIRE(frame.parse({"--frame", "12", "--fps", "8"}));
  CHECK(imageSettingsFrom(frame, Camera{}, 512).scene.animTime == 1.5);

  Options bad("test", "", sceneOptionSpecs());
  REQUIRE(bad.parse({"--light-radius", "-1"}));
  CHECK_THROWS_WITH_AS(imageSettingsFrom(bad, Camera{}, 512), "option --light-radius needs a positive number of scene units", Error);
  Options badBackground("test", "", sceneOptionSpecs());
  REQUIRE(badBackground.parse({"--background", "blue"}));
  CHECK_THROWS_WITH_AS(imageSettingsFrom(badBackground, Camera{}, 512), doctest::Contains("option --background needs"), Error);
}

TEST_CASE("image settings: the scene side reaches the scene in applySceneSettings") {
  Scene scene;
  scene.path = "test.gltf";
  PunctualLight point;
  point.type = PunctualType::Point;
  point.intensity = glm::vec3(10.0f);
  scene.punctualLights.push_back(point);
  scene.materials.push_back(Material{});
  ImageSettings s;
  s.scene.lightRadius = 0.1f;
  s.scene.env = "0.25,0.5,1";
  s.scene.envStrength = 2.0f;
  s.scene.background = "transparent";
  applySceneSettings(s, scene, false);
  CHECK(scene.punctualLights.empty());  // the point light became an emissive sphere
  CHECK_FALSE(scene.triangles.empty());
  CHECK(scene.environment.kind == Environment::Kind::Uniform);
  CHECK(scene.environment.uniform == glm::vec3(0.5f, 1.0f, 2.0f));
  CHECK(scene.background.kind == Background::Kind::Transparent);

  Scene dark;  // no light at all: env auto gives the default sky
  dark.path = "dark.gltf";
  applySceneSettings(ImageSettings{}, dark, false);
  CHECK(dark.environment.isDefault);
  CHECK(dark.environment.emits());
  CHECK(dark.background.kind == Background::Kind::Environment);
}

TEST_CASE("image settings: an identity from before caster guiding reads as guide-probability 0") {
  const ImageSettings defaults;
  ImageSettings off = defaults;
  off.render.guideProbability = 0.0f;
  const std::string withZero = accumulationIdentity(off, Camera{}), withDefault = accumulationIdentity(defaults, Camera{});
  // The old text: the same lines without guide-probability.
  std::string old;
  std::istringstream in(withZero);
  for (std::string line; std::getline(in, line);)
    if (line.rfind("guide-probability ", 0) != 0) old += line + '\n';
  REQUIRE(old != withZero);
  CHECK(identityDifference(old, withZero, "checkpoint", "this render").empty());
  CHECK(identityDifference(withZero, old, "checkpoint", "this render").empty());
  CHECK(identityDifference(old, withDefault, "checkpoint", "this render") ==
        "guide-probability: checkpoint 0, this render 0.5");
}
