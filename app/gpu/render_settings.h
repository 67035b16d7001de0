// render_settings.h — the one value that says how to render (size, seed, depth, estimator, dispersion,
// caster aiming): parsed once by every command, validated here, applied by Renderer::apply; its fields
// listed once (visitFields) for comparison, the checkpoint identity and printing. No GL.
#pragma once
#include <cstdint>
#include <string>
#include <type_traits>

#include "gpu/render_mode.h"  // RenderMode: one row per mode
#include "util/field_count.h"

namespace caustica {

enum class Integrator { Naive, Mis };
enum class DispersionMode { Rgb, Spectral };
// Manifold NEE: Auto joins light only through the casters where it pays (manifoldAutoEligible,
// scene/caustic_casters.h), On through every caster, Off never.
enum class ManifoldMode { Auto, On, Off };
Integrator parseIntegrator(const std::string& name);          // "naive" | "mis"; throws Error otherwise
DispersionMode parseDispersionMode(const std::string& name);  // "rgb" | "spectral"; throws Error otherwise
ManifoldMode parseManifoldMode(const std::string& name);      // "auto" | "on" | "off"; throws Error otherwise
const char* integratorName(Integrator i);
const char* dispersionModeName(DispersionMode d);
const char* manifoldModeName(ManifoldMode m);

constexpr int kMinMaxDepth = 1;                   // bounds of RenderSettings::maxDepth (path segments)
constexpr int kMaxMaxDepth = 1024;
constexpr float kMaxCasterProbability = 0.9f;     // every direction keeps a non-zero cosine pdf
constexpr int kMaxImageSide = 16384;              // pixels; the GPU's texture limit may be lower
constexpr int kMaxSamplesPerDispatch = 64;        // bound of RenderSettings::samplesPerDispatch
constexpr float kMinLightPaths = 1.0f / 64.0f;    // bounds of RenderSettings::lightPaths
constexpr float kMaxLightPaths = 64.0f;

struct RenderSettings {
  int width = 512, height = 512;  // pixels
  std::uint32_t seed = 1;
  // Path segments, kMinMaxDepth..kMaxMaxDepth: a safety cap; Russian roulette ends paths long
  // before it in ordinary scenes (docs/stability.md), so it biases only paths trapped for hundreds
  // of bounces (total internal reflection, white furnaces).
  int maxDepth = 256;
  Integrator integrator = Integrator::Mis;
  DispersionMode dispersion = DispersionMode::Rgb;
  // mis only: probability that a diffuse bounce aims at a caustic caster (a glass or mirror object)
  // instead of cosine sampling; 0 turns it off; at most kMaxCasterProbability.
  float casterProbability = 0.5f;
  // mis only: probability that a bounce aimed at a caster follows the caster's guide lobe (a direction
  // lobe fitted to caustic photons that landed near the vertex, docs/path-tracer.md) rather than its
  // whole cone, where the vertex's cell has one; 0 turns caster guiding off. 0 to 1.
  float guideProbability = 0.5f;
  // mis only: manifold next-event estimation, which joins the light sample at a path's first diffuse
  // vertex to it through a glass or mirror caster (docs/path-tracer.md); scenes without casters or
  // emitters never use it. Auto (the default) leaves it off where light tracing compiles; otherwise it uses
  // it only through the casters whose emitters look small from them, and compiles it only where there is
  // one (resolveManifold, shader_features.h).
  ManifoldMode manifold = ManifoldMode::Auto;
  // mis only: light tracing of caustics: light subpaths from the emitters through glass and mirror objects
  // splat the Lambertian points the camera sees, and take those paths over from the eye paths
  // (docs/path-tracer.md, "Light tracing"). Compiled where the scene has a caster and an emissive
  // triangle and manifold NEE is not on (the light-tracing row, shader_features.cpp).
  bool lightTracing = true;
  // Light subpaths per pixel and sample under light tracing (kMinLightPaths..kMaxLightPaths): each sample
  // index gets width x height x lightPaths of them (at least one). More puts more of the time into the
  // caustics the light tracer adds (docs/path-tracer.md, "Light tracing").
  float lightPaths = 0.125f;
  RenderMode mode = RenderMode::Path;
  // Compile every material feature into the path tracer, whatever the scene uses (the shader is
  // otherwise specialised to the scene's features): measures what specialisation saves
  // (docs/benchmarks.md, "Specialisation"). The expected image does not change.
  bool allFeatures = false;
  // Samples per pixel one path-tracing dispatch traces (path regeneration, pathtrace.comp): 0 chooses
  // automatically; any value is lowered to what keeps llvmpipe's loop cap out of reach for the depth
  // cap (Renderer::samplesPerDispatch). The image does not depend on it, only the speed.
  int samplesPerDispatch = 0;

  // Throws Error naming the first setting out of range.
  void validate() const;
  bool operator==(const RenderSettings& o) const;
  bool operator!=(const RenderSettings& o) const { return !(*this == o); }
};

// What a setting changes, for visitFields' users (docs/long-renders.md, "Resuming": what must match):
enum class SettingRole {
  // The samples themselves (their expectation or their random streams): part of the accumulation
  // identity, which two renders must share to add their samples (resume, shards, merge).
  Accumulation,
  // Only how fast the same samples are made: left out of the identity. Each such field says whether
  // the samples stay the same bit for bit or to float rounding.
  Speed,
  // Only how the accumulated sums are written out (tone curve, exposure): left out of the identity.
  Output,
};
const char* settingRoleName(SettingRole r);  // "accumulation" | "speed" | "output"

// Calls visit(name, role, field) for every field of `s` (a RenderSettings, const or not), in one fixed
// order. `name` is the field's key in the checkpoint identity and in printed settings (the option
// without "--", or "width"/"height" for --size). operator==, the checkpoint identity
// (cli/image_settings.h) and printing all go through it, so a field is either everywhere or nowhere;
// the static_assert below fails the build when a field is added without a line here, and
// tests/cli/image_settings_test.cpp checks that every visited field changes what its role says.
template <class Settings, class Visit,
          std::enable_if_t<std::is_same_v<std::remove_const_t<Settings>, RenderSettings>, int> = 0>
void visitFields(Settings& s, Visit&& visit) {
  visit("width", SettingRole::Accumulation, s.width);
  visit("height", SettingRole::Accumulation, s.height);
  visit("seed", SettingRole::Accumulation, s.seed);
  visit("max-depth", SettingRole::Accumulation, s.maxDepth);
  visit("integrator", SettingRole::Accumulation, s.integrator);
  visit("dispersion", SettingRole::Accumulation, s.dispersion);
  visit("caster-probability", SettingRole::Accumulation, s.casterProbability);
  visit("guide-probability", SettingRole::Accumulation, s.guideProbability);
  visit("manifold", SettingRole::Accumulation, s.manifold);
  visit("light-tracing", SettingRole::Accumulation, s.lightTracing);
  visit("light-paths", SettingRole::Accumulation, s.lightPaths);
  visit("mode", SettingRole::Accumulation, s.mode);
  // The same expected image; the same bits on llvmpipe (tests/gpu/error_estimate_test.cpp), to float
  // rounding elsewhere.
  visit("all-features", SettingRole::Speed, s.allFeatures);
  // The same bits for every K (tests/gpu/regen_test.cpp).
  visit("samples-per-dispatch", SettingRole::Speed, s.samplesPerDispatch);
}
// Added a field to RenderSettings? Add it to visitFields above (with its role), then count it here.
static_assert(fieldCount<RenderSettings>() == 14, "RenderSettings has a field that visitFields does not list");

// A setting's value as one word of text, the same in the checkpoint identity and printed settings
// (a float as the shortest text that reads back as the same float: 0.05f is "0.05").
std::string settingText(int v);
std::string settingText(std::uint32_t v);
std::string settingText(float v);
std::string settingText(double v);
std::string settingText(bool v);  // "on" | "off"
std::string settingText(const std::string& v);
std::string settingText(Integrator v);
std::string settingText(DispersionMode v);
std::string settingText(ManifoldMode v);
std::string settingText(RenderMode v);

// What changing the settings from `from` to `to` asks of a renderer. Every change restarts
// accumulation; some also need new images, another shader variant or new caster parameters.
struct SettingsChange {
  bool restart = false;  // anything differs: the accumulated samples no longer belong to the image
  bool resize = false;   // width or height: new accumulation images
  bool shader = false;   // integrator, dispersion mode, caster aiming, manifold NEE or light tracing on/off, render mode: maybe another variant
  bool casters = false;  // caster probability: the caster UBO
};
SettingsChange compareSettings(const RenderSettings& from, const RenderSettings& to);

}  // namespace caustica
