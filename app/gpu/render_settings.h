// render_settings.h — the one value that says how to render (size, seed, depth, estimator, dispersion,
// caster aiming): parsed once by every command, validated here, applied by Renderer::apply. No GL.
#pragma once
#include <cstdint>
#include <string>

namespace caustica {

enum class Integrator { Naive, Mis };
enum class DispersionMode { Rgb, Spectral };
// How the image is made (docs/render-modes.md): the path tracer, a Whitted ray tracer (compute
// shader, point lights, mirrors and glass, no global illumination) or the OpenGL raster pipeline.
enum class RenderMode { Path, Whitted, Raster };
RenderMode parseRenderMode(const std::string& name);          // "path" | "whitted" | "raster"; throws Error otherwise
const char* renderModeName(RenderMode m);
Integrator parseIntegrator(const std::string& name);          // "naive" | "mis"; throws Error otherwise
DispersionMode parseDispersionMode(const std::string& name);  // "rgb" | "spectral"; throws Error otherwise
const char* integratorName(Integrator i);
const char* dispersionModeName(DispersionMode d);

constexpr int kMinMaxDepth = 1;                   // bounds of RenderSettings::maxDepth (path segments)
constexpr int kMaxMaxDepth = 1024;
constexpr float kMaxCasterProbability = 0.9f;     // every direction keeps a non-zero cosine pdf
constexpr int kMaxImageSide = 16384;              // pixels; the GPU's texture limit may be lower
constexpr int kMaxSamplesPerDispatch = 64;        // bound of RenderSettings::samplesPerDispatch

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
  RenderMode mode = RenderMode::Path;
  // Compile every material feature into the path tracer, whatever the scene uses (the shader is
  // otherwise specialised to the scene's features): measures what specialisation saves
  // (docs/benchmarks.md). The expected image does not change.
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

// What changing the settings from `from` to `to` asks of a renderer. Every change restarts
// accumulation; some also need new images, another shader variant or new caster parameters.
struct SettingsChange {
  bool restart = false;  // anything differs: the accumulated samples no longer belong to the image
  bool resize = false;   // width or height: new accumulation images
  bool shader = false;   // integrator, dispersion mode, caster aiming on/off or render mode: maybe another variant
  bool casters = false;  // caster probability: the caster UBO
};
SettingsChange compareSettings(const RenderSettings& from, const RenderSettings& to);

}  // namespace caustica
