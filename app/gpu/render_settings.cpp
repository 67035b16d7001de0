// render_settings.cpp — parsing, validation and comparison of RenderSettings.
#include "gpu/render_settings.h"

#include <charconv>
#include <sstream>
#include <vector>

#include "util/error.h"

namespace caustica {

Integrator parseIntegrator(const std::string& name) {
  if (name == "naive") return Integrator::Naive;
  if (name == "mis") return Integrator::Mis;
  throw Error("unknown integrator '" + name + "' (expected naive or mis)");
}

DispersionMode parseDispersionMode(const std::string& name) {
  if (name == "rgb") return DispersionMode::Rgb;
  if (name == "spectral") return DispersionMode::Spectral;
  throw Error("unknown dispersion mode '" + name + "' (expected rgb or spectral)");
}

ManifoldMode parseManifoldMode(const std::string& name) {
  if (name == "auto") return ManifoldMode::Auto;
  if (name == "on") return ManifoldMode::On;
  if (name == "off") return ManifoldMode::Off;
  throw Error("option --manifold needs auto, on or off (got '" + name + "')");
}

const char* integratorName(Integrator i) { return i == Integrator::Naive ? "naive" : "mis"; }
const char* dispersionModeName(DispersionMode d) { return d == DispersionMode::Rgb ? "rgb" : "spectral"; }
const char* manifoldModeName(ManifoldMode m) {
  return m == ManifoldMode::Auto ? "auto" : m == ManifoldMode::On ? "on" : "off";
}

void RenderSettings::validate() const {
  if (width < 1 || height < 1 || width > kMaxImageSide || height > kMaxImageSide)
    throw Error("image size " + std::to_string(width) + "x" + std::to_string(height) + " is outside 1 to " +
                std::to_string(kMaxImageSide) + " pixels per side");
  if (maxDepth < kMinMaxDepth || maxDepth > kMaxMaxDepth)
    throw Error("max depth must be between " + std::to_string(kMinMaxDepth) + " and " + std::to_string(kMaxMaxDepth));
  if (samplesPerDispatch < 0 || samplesPerDispatch > kMaxSamplesPerDispatch)
    throw Error("samples per dispatch must be between 0 (automatic) and " + std::to_string(kMaxSamplesPerDispatch));
  if (!(casterProbability >= 0.0f && casterProbability <= kMaxCasterProbability)) {
    std::ostringstream m;
    m << "caster probability must be between 0 and " << kMaxCasterProbability;
    throw Error(m.str());
  }
  if (!(guideProbability >= 0.0f && guideProbability <= 1.0f)) throw Error("guide probability must be between 0 and 1");
  if (!(lightPaths >= kMinLightPaths && lightPaths <= kMaxLightPaths))
    throw Error("option --light-paths needs a number from 1/64 to 64 (light subpaths per pixel and sample)");
}

bool RenderSettings::operator==(const RenderSettings& o) const {
  // Field by field through the one list (visitFields), in the same order for both sides.
  std::vector<std::string> mine, theirs;
  visitFields(*this, [&](const char*, SettingRole, const auto& v) { mine.push_back(settingText(v)); });
  visitFields(o, [&](const char*, SettingRole, const auto& v) { theirs.push_back(settingText(v)); });
  return mine == theirs;
}

const char* settingRoleName(SettingRole r) {
  return r == SettingRole::Accumulation ? "accumulation" : r == SettingRole::Speed ? "speed" : "output";
}

std::string settingText(int v) { return std::to_string(v); }
std::string settingText(std::uint32_t v) { return std::to_string(v); }
std::string settingText(float v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);  // the shortest text that reads back as v
  return std::string(buf, r.ptr);
}
std::string settingText(double v) {
  char buf[40];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);  // the shortest text that reads back as v
  return std::string(buf, r.ptr);
}
std::string settingText(bool v) { return v ? "on" : "off"; }
std::string settingText(const std::string& v) { return v; }
std::string settingText(Integrator v) { return integratorName(v); }
std::string settingText(DispersionMode v) { return dispersionModeName(v); }
std::string settingText(ManifoldMode v) { return manifoldModeName(v); }
std::string settingText(RenderMode v) { return renderModeName(v); }

SettingsChange compareSettings(const RenderSettings& from, const RenderSettings& to) {
  SettingsChange c;
  c.restart = from != to;
  c.resize = from.width != to.width || from.height != to.height;
  c.shader = from.integrator != to.integrator || from.dispersion != to.dispersion ||
             (from.casterProbability > 0.0f) != (to.casterProbability > 0.0f) || from.manifold != to.manifold || from.lightTracing != to.lightTracing ||
             (from.guideProbability > 0.0f) != (to.guideProbability > 0.0f) ||
             from.mode != to.mode ||
             from.allFeatures != to.allFeatures;
  c.casters = from.casterProbability != to.casterProbability || from.guideProbability != to.guideProbability;
  return c;
}

}  // namespace caustica
