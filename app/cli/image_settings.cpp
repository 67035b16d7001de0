// image_settings.cpp — the command line read into ImageSettings, their scene side applied to the
// Scene, and their text: printed settings and the accumulation identity of checkpoints.
#include "cli/image_settings.h"

#include <cmath>
#include <map>
#include <sstream>
#include <vector>

#include "cli/cli_common.h"
#include "cli/environment_options.h"
#include "gpu/shader_features.h"
#include "scene/punctual_lights.h"
#include "util/error.h"

namespace caustica {
std::string settingText(ToneCurve v) { return toneCurveName(v); }
}  // namespace caustica

namespace caustica::cli {

namespace {

RenderSettings renderSettingsFrom(const Options& opts, const Camera& camera, int defaultWidth) {
  const RenderSettings defaults;
  RenderSettings s;
  parseSize(opts.get("--size", std::to_string(defaultWidth)), camera.aspect, s.width, s.height);
  s.seed = static_cast<std::uint32_t>(opts.getInt("--seed", static_cast<int>(defaults.seed), 0, 2147483647));
  s.maxDepth = opts.getInt("--max-depth", defaults.maxDepth, kMinMaxDepth, kMaxMaxDepth);
  if (!opts.isList("--integrator")) s.integrator = parseIntegrator(opts.get("--integrator", integratorName(defaults.integrator)));
  if (!opts.isList("--dispersion"))
    s.dispersion = parseDispersionMode(opts.get("--dispersion", dispersionModeName(defaults.dispersion)));
  if (!opts.isList("--mode")) s.mode = parseRenderMode(opts.get("--mode", renderModeName(defaults.mode)));
  s.casterProbability = static_cast<float>(opts.getDouble("--caster-probability", defaults.casterProbability));
  if (!(s.casterProbability >= 0.0f && s.casterProbability <= kMaxCasterProbability)) {
    std::ostringstream m;
    m << "option --caster-probability needs a number from 0 to " << kMaxCasterProbability;
    throw Error(m.str());
  }
  s.guideProbability = static_cast<float>(opts.getDouble("--guide-probability", defaults.guideProbability));
  if (!(s.guideProbability >= 0.0f && s.guideProbability <= 1.0f))
    throw Error("option --guide-probability needs a number from 0 to 1");
  s.manifold = parseManifoldMode(opts.get("--manifold", settingText(defaults.manifold)));
  const std::string lightTracing = opts.get("--light-tracing", settingText(defaults.lightTracing));
  if (lightTracing != "on" && lightTracing != "off") throw Error("option --light-tracing needs on or off");
  s.lightTracing = lightTracing == "on";
  s.lightPaths = static_cast<float>(opts.getDouble("--light-paths", defaults.lightPaths));
  s.allFeatures = opts.has("--all-features");
  s.samplesPerDispatch = opts.getInt("--samples-per-dispatch", defaults.samplesPerDispatch, 0, kMaxSamplesPerDispatch);
  s.validate();
  return s;
}

SceneSettings sceneSettingsFrom(const Options& opts) {
  const SceneSettings defaults;
  SceneSettings s;
  s.env = opts.get("--env", defaults.env);
  s.envStrength = static_cast<float>(opts.getDouble("--env-strength", defaults.envStrength));
  if (!(s.envStrength >= 0.0f)) throw Error("option --env-strength needs a non-negative number");
  s.envRotation = static_cast<float>(opts.getDouble("--env-rotation", defaults.envRotation));
  if (!std::isfinite(s.envRotation)) throw Error("option --env-rotation needs a finite number of degrees");
  s.background = opts.get("--background", defaults.background);
  parseBackground(s.background);  // a bad colour fails here, before any work
  if (opts.has("--light-radius")) {
    const double r = opts.getDouble("--light-radius", 0.0);
    if (!(r > 0.0) || r > 3.0e38) throw Error("option --light-radius needs a positive number of scene units");
    s.lightRadius = static_cast<float>(r);
  }
  return s;
}

template <class Each>
void eachField(const ImageSettings& s, Each&& each) {
  visitFields(s, [&](const char* name, SettingRole role, const auto& v) { each(name, role, settingText(v)); });
}

std::map<std::string, std::string> parseLines(const std::string& text) {
  std::map<std::string, std::string> m;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    size_t sp = line.find(' ');
    m[line.substr(0, sp)] = sp == std::string::npos ? "" : line.substr(sp + 1);
  }
  return m;
}

}  // namespace

ImageSettings imageSettingsFrom(const Options& opts, const Camera& camera, int defaultWidth) {
  ImageSettings s;
  s.render = renderSettingsFrom(opts, camera, defaultWidth);
  s.scene = sceneSettingsFrom(opts);
  s.camera = cameraIndexFrom(opts);
  const ScenePose pose = scenePoseFrom(opts);  // --animation, --anim-time or --frame / --fps
  s.scene.animation = pose.animation.empty() ? "first" : pose.animation;
  s.scene.animTime = pose.time;
  s.tone.exposureStops = static_cast<float>(opts.getDouble("--exposure", s.tone.exposureStops));
  s.tone.curve = parseToneCurve(opts.get("--tonemap", toneCurveName(s.tone.curve)));
  return s;
}

void applySceneSettings(const ImageSettings& settings, Scene& scene, bool verbose) {
  const SceneSettings& s = settings.scene;
  if (s.lightRadius > 0.0f) {
    const std::size_t before = scene.punctualLights.size();
    applyLightRadius(scene, s.lightRadius);
    note(!verbose, "--light-radius: " + std::to_string(before - scene.punctualLights.size()) +
                       " point/spot light(s) made emissive spheres of radius " + settingText(s.lightRadius));
  }
  applyEnvironmentSettings(settings, scene, verbose);  // environment_options.cpp
}

std::string settingsLines(const ImageSettings& settings, SettingRole role) {
  std::string out;
  eachField(settings, [&](const char* name, SettingRole r, const std::string& text) {
    if (r == role) out += std::string(name) + ' ' + text + '\n';
  });
  return out;
}

std::string settingsSummary(const ImageSettings& settings) {
  std::string out;
  eachField(settings, [&](const char* name, SettingRole, const std::string& text) {
    out += (out.empty() ? "" : ", ") + std::string(name) + ' ' + text;
  });
  return out;
}

std::string accumulationIdentity(const ImageSettings& settings, const Camera& c) {
  std::string t = settingsLines(settings, SettingRole::Accumulation);
  t += "camera-view";
  for (float v : {c.position.x, c.position.y, c.position.z, c.forward.x, c.forward.y, c.forward.z, c.up.x, c.up.y,
                  c.up.z, c.yfov, c.aspect})
    t += ' ' + settingText(v);
  if (c.orthographic()) t += " orthographic " + settingText(c.orthoHeight);  // (pinhole identities as before)
  return t + '\n';
}

ManifoldMode imageManifoldMode(const RenderSettings& settings, const GpuScene& gpu) {
  if (settings.manifold != ManifoldMode::Auto) return settings.manifold;
  if (lightTracingCompiled(settings, gpu)) return ManifoldMode::Off;  // resolveManifold: light tracing first
  const std::uint32_t casters = manifoldCasterMask(ManifoldMode::Auto, gpu);
  if (casters == 0) return ManifoldMode::Off;
  return casters == manifoldCasterMask(ManifoldMode::On, gpu) ? ManifoldMode::On : ManifoldMode::Auto;
}

namespace {

// `identity` with each line whose key is `key` given to `edit` (with the value after "KEY "), which
// returns the line's replacement without its newline, or "" to drop it; other lines unchanged.
template <class Edit>
std::string editIdentityLines(const std::string& identity, const std::string& key, Edit&& edit) {
  const std::string prefix = key + ' ';
  std::string out;
  std::istringstream in(identity);
  for (std::string line; std::getline(in, line);) {
    if (line.compare(0, prefix.size(), prefix) == 0) {
      line = edit(line.substr(prefix.size()));
      if (line.empty()) continue;
    }
    out += line + '\n';
  }
  return out;
}

}  // namespace

namespace {

// The settings an identity's light-tracing, integrator, mode and manifold lines give (a missing light-tracing
// line: off, kAddedLater's meaning); false where a line is not one this build can read.
bool identityLightSettings(const std::string& identity, RenderSettings& s) {
  const std::map<std::string, std::string> lines = parseLines(identity);
  s.lightTracing = lines.count("light-tracing") && lines.at("light-tracing") == "on";
  try {
    if (lines.count("integrator")) s.integrator = parseIntegrator(lines.at("integrator"));
    if (lines.count("mode")) s.mode = parseRenderMode(lines.at("mode"));
    if (lines.count("manifold")) s.manifold = parseManifoldMode(lines.at("manifold"));
  } catch (const Error&) {
    return false;
  }
  return true;
}

}  // namespace

std::string resolveIdentityManifold(const std::string& identity, const GpuScene& gpu) {
  RenderSettings s;
  if (!identityLightSettings(identity, s)) return identity;  // compared as it is (and differs)
  return editIdentityLines(identity, "manifold", [&](const std::string&) {
    return std::string("manifold ") + manifoldModeName(imageManifoldMode(s, gpu));
  });
}

std::string resolveIdentityScene(const std::string& identity, const GpuScene& gpu) {
  // Light tracing as imageLightTracing decides it from the identity's own lines, before the manifold line
  // is resolved (a line this build cannot read leaves the text as it is: compared as it is).
  RenderSettings s;
  const bool readable = identityLightSettings(identity, s);
  // Guiding is not compiled without a caster it applies to: any guide probability renders as 0.
  std::string t = editIdentityLines(resolveIdentityManifold(identity, gpu), "guide-probability", [&](const std::string& p) {
    return "guide-probability " + (guideCasterMask(gpu) == 0u ? std::string("0") : p);
  });
  if (!readable || !parseLines(t).count("light-tracing") || imageLightTracing(s, gpu)) return t;
  t = editIdentityLines(t, "light-tracing", [](const std::string&) { return std::string("light-tracing off"); });
  return editIdentityLines(t, "light-paths", [](const std::string&) {
    return "light-paths " + settingText(RenderSettings{}.lightPaths);
  });
}

std::string identityWithoutSceneLines(const std::string& identity) {
  const auto drop = [](const std::string&) { return std::string(); };
  std::string t = editIdentityLines(editIdentityLines(identity, "manifold", drop), "guide-probability", drop);
  return editIdentityLines(editIdentityLines(t, "light-tracing", drop), "light-paths", drop);
}

float imageGuideProbability(const RenderSettings& s, const GpuScene& gpu) {
  const bool guides = s.integrator == Integrator::Mis && s.casterProbability > 0.0f && guideCasterMask(gpu) != 0u;
  return guides ? s.guideProbability : 0.0f;
}

bool imageLightTracing(const RenderSettings& s, const GpuScene& gpu) { return lightTracingCompiled(s, gpu); }

std::string accumulationIdentity(const ImageSettings& settings, const Camera& camera, const GpuScene& gpu) {
  ImageSettings s = settings;
  s.render.manifold = imageManifoldMode(settings.render, gpu);
  if (!imageLightTracing(settings.render, gpu)) {  // as the settings were given (auto unresolved)
    s.render.lightTracing = false;
    s.render.lightPaths = RenderSettings{}.lightPaths;
  }
  s.render.guideProbability = imageGuideProbability(s.render, gpu);
  return accumulationIdentity(s, camera);
}

std::string identityDifference(const std::string& a, const std::string& b, const std::string& labelA,
                               const std::string& labelB) {
  std::vector<std::string> diffs;
  std::map<std::string, std::string> ma = parseLines(a), mb = parseLines(b);
  // Settings added after identities were first written, with the value their absence means: an
  // identity from before caster guiding rendered without it.
  static const std::map<std::string, std::string> kAddedLater = {
      {"guide-probability", "0"}, {"light-tracing", "off"}, {"light-paths", settingText(RenderSettings{}.lightPaths)}};
  for (const auto& [key, value] : kAddedLater) {
    if (!ma.count(key) && mb.count(key)) ma[key] = value;
    if (!mb.count(key) && ma.count(key)) mb[key] = value;
  }
  for (const auto& [key, value] : mb) {
    auto it = ma.find(key);
    const std::string other = it == ma.end() ? "(none)" : it->second;
    if (other != value) diffs.push_back(key + ": " + labelA + ' ' + other + ", " + labelB + ' ' + value);
  }
  for (const auto& [key, value] : ma)
    if (!mb.count(key)) diffs.push_back(key + ": " + labelA + ' ' + value + ", " + labelB + " (none)");
  std::string out;
  for (const auto& d : diffs) out += (out.empty() ? "" : "; ") + d;
  return out;
}

}  // namespace caustica::cli
