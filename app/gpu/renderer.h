// renderer.h — the progressive path tracer on the GPU: uploads a scene, compiles the shader variant
// it needs, dispatches samples into the accumulation image and reads results back. Knows no window.
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "accel/bvh.h"
#include "gpu/gl_objects.h"
#include "accel/gpu_scene.h"
#include "image/image_io.h"
#include "scene/scene.h"
#include "gpu/shader_library.h"
#include "image/tonemap.h"

namespace caustica {

enum class Integrator { Naive, Mis };
enum class DispersionMode { Rgb, Spectral };
Integrator parseIntegrator(const std::string& name);          // "naive" | "mis"
DispersionMode parseDispersionMode(const std::string& name);  // "rgb" | "spectral"
const char* integratorName(Integrator i);
const char* dispersionModeName(DispersionMode d);

struct RenderSettings {
  int width = 512, height = 512;  // pixels
  std::uint32_t seed = 1;
  int maxDepth = 32;              // path segments
  Integrator integrator = Integrator::Mis;
  DispersionMode dispersion = DispersionMode::Rgb;
  // mis only: probability that a diffuse bounce aims at a caustic caster (a glass or mirror object)
  // instead of cosine sampling; 0 turns it off. At most kMaxCasterProbability, so every direction
  // keeps a non-zero pdf.
  float casterProbability = 0.5f;
};
constexpr float kMaxCasterProbability = 0.9f;

// Totals over everything rendered since the last reset.
struct RenderStats {
  std::uint64_t primaryRays = 0, secondaryRays = 0, shadowRays = 0, nonFinite = 0;
  std::uint64_t rays() const { return primaryRays + secondaryRays + shadowRays; }
};

// Limits of the current GL implementation that matter to caustica.
struct GlLimits {
  std::int64_t maxStorageBlockSize = 0;  // bytes per SSBO
  int maxComputeStorageBlocks = 0;
  int maxWorkGroupInvocations = 0;
  int maxTextureSize = 0;
  int maxWorkGroupCount[2] = {0, 0};
};
GlLimits queryGlLimits();

class Renderer {
 public:
  // Needs a current GL 4.3 context. Throws Error if the scene exceeds the GL limits.
  Renderer(const ShaderLibrary& library, const Scene& scene, const Camera& camera, const RenderSettings& settings);

  void setCamera(const Camera& camera);          // restarts accumulation
  void setIntegrator(Integrator integrator);     // restarts accumulation
  void setDispersionMode(DispersionMode mode);   // restarts accumulation
  void setMaxDepth(int maxDepth);                // restarts accumulation
  void setCasterProbability(float p);            // restarts accumulation
  void resize(int width, int height);            // restarts accumulation
  void reset();

  // Adds `spp` samples per pixel to rows [y0, y1). Cover every row, then call endPass(spp) once.
  void renderRows(int y0, int y1, int spp);
  void endPass(int spp);
  void renderPass(int spp) { renderRows(0, settings_.height, spp); endPass(spp); }

  int samplesPerPixel() const { return spp_; }
  Image image() const;                           // mean radiance per pixel (linear)
  // Tone-maps the accumulation into the rgba8 display texture (viewer).
  const GlTexture& updateDisplay(const ToneMapSettings& tone);
  const RenderStats& stats() const { return stats_; }
  const RenderSettings& settings() const { return settings_; }
  const Camera& camera() const { return camera_; }
  const GpuScene& gpuScene() const { return gpuScene_; }
  const Bvh& bvh() const { return bvh_; }
  double bvhBuildSeconds() const { return bvhSeconds_; }
  std::vector<std::string> shaderDefines() const;  // the variant the current settings need

 private:
  const GlProgram& program();
  void readCounters();
  void uploadCasters();

  const ShaderLibrary& library_;
  RenderSettings settings_;
  Camera camera_;
  Bvh bvh_;
  double bvhSeconds_ = 0.0;
  GpuScene gpuScene_;
  GlLimits limits_;
  std::vector<GlBuffer> buffers_;  // indexed by CAUSTICA_BINDING_*
  GlBuffer frameUbo_;
  GlBuffer casterUbo_;
  GlTexture accum_, comp_, display_;
  std::map<std::string, GlProgram> programs_;
  GlProgram tonemapProgram_;
  int spp_ = 0;
  std::uint32_t sampleBase_ = 0;
  RenderStats stats_;
};

}  // namespace caustica
