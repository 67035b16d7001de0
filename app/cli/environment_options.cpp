// environment_options.cpp — --env, --env-strength, --env-rotation, --background and the default
// environment (docs/lighting.md).
#include "cli/environment_options.h"

#include "util/error.h"

namespace caustica::cli {

std::vector<OptionSpec> environmentOptionSpecs() {
  return {
      {"--env", "", "FILE|RGB|none",
       "environment light: an equirectangular .hdr/.exr map, a uniform sky (0.8 or R,G,B) or none "
       "(default auto: none if the scene has emitters, else a uniform sky of radiance 1)"},
      {"--env-strength", "", "S", "multiplies the environment's radiance (default 1)"},
      {"--env-rotation", "", "DEG", "turns the environment map about +Y, right-handed (default 0)"},
      {"--background", "", "WHAT",
       "what camera rays that leave the scene see: env (default), a colour (0.2 or R,G,B) or transparent "
       "(alpha 0 in .png/.exr; the environment still lights the scene)"},
  };
}

namespace {
// Modes that do not see the environment (RenderModeSpec::seesEnvironment: raster, Whitted; docs/render-modes.md)
// light with the emitters only: say so when the environment is all the light there is.
void noteModeWithoutEnvironment(RenderMode mode, const Scene& scene, bool verbose) {
  if (!renderModeSpec(mode).seesEnvironment && scene.environment.emits())
    note(!verbose, std::string("warning: the image will be black: --mode ") + renderModeName(mode) +
                       " does not see the environment yet and " + scene.path + " has no emitters (use --mode " +
                       renderModeNames([](const RenderModeSpec& m) { return m.seesEnvironment; }) + ")");
}
}  // namespace

void applyEnvironmentSettings(const ImageSettings& settings, Scene& scene, bool verbose) {
  const SceneSettings& s = settings.scene;
  const RenderMode mode = settings.render.mode;
  scene.background = parseBackground(s.background);
  if (scene.background.kind == Background::Kind::Transparent && !renderModeSpec(mode).tracksCoverage)
    note(!verbose, std::string("warning: --mode ") + renderModeName(mode) + " draws an opaque image: --background transparent needs --mode " +
                       renderModeNames([](const RenderModeSpec& m) { return m.tracksCoverage; }));
  scene.environment = Environment{};
  const bool emitters = sceneHasLights(scene);  // emissive triangles (the environment is not set yet)
  if (s.env != "auto") {
    scene.environment = parseEnvironment(s.env, s.envStrength, s.envRotation);
    if (!emitters && !scene.environment.emits())
      note(!verbose, "warning: the image will be black: " + scene.path +
                         " has no emitters (emissive triangles or punctual lights) and the environment emits nothing (--env " +
                         s.env + ")");
    else if (!emitters)
      noteModeWithoutEnvironment(mode, scene, verbose);
    return;
  }
  if (emitters) return;
  scene.environment = uniformEnvironment(glm::vec3(kDefaultEnvironmentRadiance), s.envStrength);
  scene.environment.rotationDegrees = s.envRotation;
  scene.environment.isDefault = true;
  note(!verbose, scene.path + " has no emitters (emissive triangles or punctual lights): lit by the default environment, a uniform sky of radiance 1 "
                              "(--env FILE|RGB to choose one, --env none for none)");
  noteModeWithoutEnvironment(mode, scene, verbose);
}

std::string lightingSummary(const Scene& scene, std::size_t emitterTriangles) {
  std::string s = std::to_string(emitterTriangles) + " emitter triangle" + (emitterTriangles == 1 ? "" : "s") + ", " +
                  std::to_string(scene.punctualLights.size()) + " punctual, environment " + scene.environment.describe();
  if (scene.background.kind != Background::Kind::Environment) s += ", background " + scene.background.describe();
  return s;
}

std::string lightingTag(const Scene& scene, std::size_t emitterTriangles) {
  std::string s;
  if (emitterTriangles > 0) s = std::to_string(emitterTriangles) + " emitter tris";
  if (!scene.punctualLights.empty())
    s += (s.empty() ? "" : " + ") + std::to_string(scene.punctualLights.size()) + " punctual";
  const Environment& e = scene.environment;
  if (e.emits()) {
    std::string env = e.isDefault ? "env default (uniform 1)"
                      : e.kind == Environment::Kind::Uniform
                          ? "env uniform"
                          : "env " + e.source.substr(e.source.find_last_of('/') + 1);
    s += (s.empty() ? "" : " + ") + env;
  }
  return s.empty() ? "no lights" : s;
}

}  // namespace caustica::cli
