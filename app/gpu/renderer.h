// renderer.h — the progressive path tracer on the GPU: uploads a scene, compiles the shader variant
// it needs, dispatches samples into the accumulation image and reads results back. Knows no window.
#pragma once
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "accel/bvh.h"
#include "gpu/bvh_textures.h"
#include "gpu/caustic_cells.h"
#include "gpu/shading_textures.h"
#include "gpu/environment_textures.h"
#include "gpu/gl_limits.h"
#include "gpu/gl_objects.h"
#include "accel/gpu_scene.h"
#include "image/image_io.h"
#include "scene/scene.h"
#include "gpu/render_settings.h"
#include "gpu/scene_buffers.h"
#include "gpu/shader_features.h"
#include "gpu/shader_library.h"
#include "image/error_estimate.h"
#include "image/tonemap.h"
#include "scene/light_groups.h"
#include "util/field_count.h"

namespace caustica {

class RasterRenderer;
class Denoiser;
struct MeshBvhs;

// The PointLights UBO of the raster and Whitted modes: the emitter `groups`, then the scene's punctual
// lights (at most CAUSTICA_MAX_POINT_LIGHTS in all), with each light's shadow far distance reaching the
// farthest corner of `bounds`.
gpu::PointLights pointLightParams(const std::vector<LightGroup>& groups, const std::vector<PunctualLight>& punctual,
                                  const Bounds& bounds);

// Totals over everything rendered since the last reset.
struct RenderStats {
  std::uint64_t primaryRays = 0, secondaryRays = 0, shadowRays = 0, nonFinite = 0;
  std::uint64_t rays() const { return primaryRays + secondaryRays + shadowRays; }
};

// The running sums of a progressive render: enough to continue it exactly where it stopped.
struct AccumulationState {
  int width = 0, height = 0;
  int spp = 0;                  // samples per pixel accumulated
  std::uint32_t sampleBase = 0;  // global index of the next sample (the RNG's sample dimension)
  std::vector<float> accum;     // rgba32f running sums (rgb radiance, a = sample count), width*height*4
  std::vector<float> comp;      // rgba32f Kahan compensation terms of those sums, width*height*4
  std::vector<float> half;      // rgba32f sums of each pixel's odd-numbered samples (rgb) and their count (a)
  std::vector<float> coverage;  // r32f samples whose camera ray hit the scene, width*height; empty unless
                                // the background is transparent
  // The denoiser's feature sums over the same samples (feature_buffers.glsl), width*height*4 each; empty
  // unless the renderer keeps feature buffers (Renderer::setFeatureBuffers).
  std::vector<float> albedo;    // rgb: albedo of each sample's first non-specular hit; a: luminance(radiance)^2
  std::vector<float> normal;    // xyz: its shading normal; w: its distance along the path
  bool hasFeatures() const { return !albedo.empty(); }
};

// The per-pixel sums of an AccumulationState that are plain sums of per-sample values (no compensation
// term), each as visit(name, images): what adding two states together (merge of shards, cli/shard.h)
// adds besides accum/comp, which are a Kahan pair. An image empty in a state is absent in it. A field
// added to AccumulationState (e.g. another per-pixel sum: feature buffers) must be listed here (or
// beside accum/comp): the static_assert fails the build until it is, so that merged renders never drop
// a sum; merge then adds it and refuses parts that hold it next to parts that do not.
template <class State, class Visit>
void visitPlainSums(State& s, Visit&& visit) {
  visit("half", s.half);
  visit("coverage", s.coverage);
  visit("albedo", s.albedo);
  visit("normal", s.normal);
}
static_assert(fieldCount<AccumulationState>() == 10,
              "AccumulationState has a field that visitPlainSums (or the accum/comp pair) does not cover");

// The mean radiance of each pixel from its running sums (rgb / count; 0 where a pixel has no sample),
// and with `coverage` (hits per pixel) the alpha. Renderer::image() and merge (cli/shard.h) share it, so a
// merged render's image is computed exactly as one machine's.
Image meanImage(int width, int height, const std::vector<float>& accum, const std::vector<float>* coverage);

// Seconds the Renderer spent getting a scene ready (docs/benchmarks.md, "Big scenes").
struct LoadTimes {
  double bvh = 0.0, pack = 0.0, upload = 0.0, compile = 0.0;
  double ready = 0.0;        // from the start of the constructor to its end: the first sample can start
  double firstPass = 0.0;    // from the start of the constructor to the end of the first pass (0: none yet)
};

// How a Renderer will be used beyond one scene.
struct RendererOptions {
  // setScene will follow (animation sequences, docs/animation.md): keep the bottom-level BVHs of an
  // instanced scene on the host (about the meshes' BVH and triangle records again) so that a scene whose
  // stored meshes did not change only re-places its instances.
  bool sceneUpdates = false;
};

class Renderer {
 public:
  // Needs a current GL 4.3 context. Throws Error if the scene exceeds the GL limits.
  Renderer(const ShaderLibrary& library, const Scene& scene, const Camera& camera, const RenderSettings& settings,
           const RendererOptions& options = {});
  ~Renderer();

  // Another scene with the same settings (the next frame of an animation): uploads it and restarts
  // accumulation, keeping what does not depend on the scene: the GL context's compiled shader variants
  // (the same features reuse theirs), the images (unless the coverage image comes or goes) and, with
  // RendererOptions::sceneUpdates, the bottom-level BVHs of meshes that did not change (a rigid
  // animation of an instanced scene rebuilds only the top level). A flat scene's BVH is built again.
  void setScene(const Scene& scene, const Camera& camera);
  // Bottom-level BVH builds so far (RendererOptions::sceneUpdates; tests check that rigid frames add none).
  int meshBvhBuilds() const { return meshBvhBuilds_; }

  void setCamera(const Camera& camera);          // restarts accumulation
  // Feature buffers (albedo, normal, distance, luminance moment: feature_buffers.glsl) accumulated with
  // the samples, for the denoiser and --aov; off by default, compiled out of the shader then. Turning
  // them on restarts accumulation (the samples so far have none); turning them off keeps the samples.
  // Only the path tracer writes them.
  void setFeatureBuffers(bool on);
  bool featureBuffers() const { return features_; }
  // Whether denoise() filters (feature buffers on, path tracer) rather than copying the raw image.
  bool canDenoise() const { return features_ && renderModeSpec(settings_.mode).pathTracer; }
  // Runs the denoiser (gpu/denoiser.h) over the accumulation so far and returns its output: rgba32f in
  // the accumulation image's convention (rgb = denoised mean x count, a = count). Without canDenoise(),
  // the accumulation image itself.
  const GlTexture& denoise();
  Image denoisedImage();  // denoise(), read back like image()
  // The one place that decides what a settings change needs: new images, another shader variant,
  // new caster parameters; any change restarts accumulation. Throws Error if `settings` is invalid
  // or too large for this GPU, leaving the previous settings in force. Returns what it did, so a
  // caller can warm a new shader variant up.
  SettingsChange apply(const RenderSettings& settings);
  void reset();

  // Adds `spp` samples per pixel to rows [y0, y1). Cover every row, then call endPass(spp) once.
  void renderRows(int y0, int y1, int spp);
  void endPass(int spp);
  // Adds `spp` samples to every pixel, or under adaptive sampling (setLiveTiles) to the live tiles only.
  void renderPass(int spp);

  // Adaptive sampling: from now on renderPass samples only these tiles of tileSize x tileSize pixels
  // (packed x | y << 16 in tiles, as liveTiles() returns them; tileSize 1, 2, 4 or 8: one 8x8 work
  // group samples 64 / tileSize^2 tiles); an empty list samples nothing. useAllTiles() (and any reset) ends it.
  void setLiveTiles(const std::vector<std::uint32_t>& tiles, int tileSize = CAUSTICA_WORKGROUP_X);
  void useAllTiles();
  bool adaptive() const { return tileListActive_; }
  std::size_t liveTileCount() const;  // tiles renderPass samples (of the last setLiveTiles' size, else 8x8)
  // The error estimate of the image so far, per tile of tileSize x tileSize pixels (reads three images
  // back; error_estimate.h).
  ErrorEstimate errorEstimate(int tileSize = CAUSTICA_WORKGROUP_X) const;

  int samplesPerPixel() const { return spp_; }
  // Samples per pixel one dispatch traces: in modes of SampleRule::Regeneration (pathtrace.comp's flat
  // bounce loop) settings().samplesPerDispatch or the default, lowered so that K * (depth cap + alpha
  // pass-throughs) <= kRegenBounceBudget; else 1. A render loop should ask for passes of at least
  // this many samples, or the dispatches trace fewer.
  int samplesPerDispatch() const;
  // Reads back both accumulation images and the sample counters (for checkpoints).
  AccumulationState saveAccumulation() const;
  // Continues from `state` (saved from a renderer with the same scene and settings): the next pass
  // renders exactly the samples an uninterrupted render would. Throws Error unless its size matches.
  void restoreAccumulation(const AccumulationState& state);
  // Makes `index` the global index of the next sample (the RNG's sample dimension) of a render that has
  // no samples yet: a shard of a render starts at the first sample of its share (cli/shard.h).
  // Throws Error if samples were already added.
  void startAtSample(std::uint32_t index);
  Image image() const;  // mean radiance per pixel (linear); with hasAlpha() also the alpha (coverage)
  // --background transparent in a mode that tracks coverage (the CAUSTICA_TRANSPARENT row): image()
  // has alpha = the fraction of a pixel's samples whose camera ray hit the scene (coverage.glsl).
  bool hasAlpha() const { return variantFeatures(sceneFeatures_, resolveManifold(settings_, gpuScene_)).has("CAUSTICA_TRANSPARENT"); }
  // Tone-maps the accumulation (with `denoised`, denoise()'s output) into the rgba8 display texture (viewer).
  const GlTexture& updateDisplay(const ToneMapSettings& tone, bool denoised = false);
  // Milliseconds the last denoise() took on the GPU (it waits for the GPU to finish); 0 before any.
  double denoiseMs() const { return denoiseMs_; }
  // The sum of denoiseMs() over every denoise() so far (a frame may filter more than once).
  double denoiseMsTotal() const { return denoiseMsTotal_; }
  const RenderStats& stats() const { return stats_; }
  const RenderSettings& settings() const { return settings_; }
  const Camera& camera() const { return camera_; }
  const GpuScene& gpuScene() const { return gpuScene_; }
  const Bvh& bvh() const { return bvh_; }
  double bvhBuildSeconds() const { return bvhSeconds_; }
  const LoadTimes& loadTimes() const { return load_; }
  // The scene's storage blocks: bytes by array (measured before the host copies were freed) and split.
  const GpuSceneBytes& gpuBytes() const { return gpuBytes_; }
  const SceneBufferLayout& bufferLayout() const { return bufferLayout_; }
  // The shader-feature rows the scene needs (detectFeatures), and the defines of the variant the
  // current settings need: variantFeatures' rows, then the storage layout's (split blocks, instancing).
  const FeatureSet& sceneFeatures() const { return sceneFeatures_; }
  std::vector<std::string> shaderDefines() const;
  // What a caustic cell table holds (manifold NEE's or caster guiding's) as its photon pass built it
  // (zero before one ran).
  CausticCellStats causticCellStats(CellTable t = CellTable::Manifold) const {
    return (t == CellTable::Guide ? causticGuides_ : causticCells_).stats();
  }
  // The point lights of the raster and Whitted modes (emitters grouped, most powerful first).
  const std::vector<LightGroup>& lightGroups() const { return lightGroups_; }
  // Binds the scene's storage blocks, UBOs and textures as the compute shaders read them (before each
  // dispatch; also for GPU tests that run a library function over the scene in their own entry shader).
  void bindSceneForDispatch();

 private:
  const GlProgram& program();
  void prepareMode();  // compiles the current mode's compute variant, or builds the raster pipeline
  void allocateImages();
  void readCounters();
  void dispatchSamples(int spp, int y0, int y1, bool tiles);
  // The light tracer's pass (light_trace.comp, compiled with the path tracer's `defines`) for the k sample
  // indices from frame.z of the frame UBO:
  // their splats, read by the next path-tracing dispatch on CAUSTICA_TEXUNIT_LIGHT_SPLATS. Leaves the
  // path tracer's program to be used again.
  void traceLight(std::uint32_t first, int k, const std::vector<std::string>& defines);
  std::uint64_t lightSubpaths() const;  // per sample index: width x height x RenderSettings::lightPaths, at least 1
  void uploadCasters();
  Image meansOf(const std::vector<float>& rgba) const;  // meanImage of sums like accum_'s, with coverage alpha
  gpu::CasterParams casterParams() const;  // the caster UBO for the current settings and cells
  // A caustic photon pass (caustic_cells.h) filling `table`: manifold NEE's or caster guiding's.
  void buildCausticCells(CellTable table);
  // The compute program of `entry` with `defines`, compiled once per renderer (programs_).
  const GlProgram& compiledProgram(const char* entry, const std::vector<std::string>& defines);
  // The constructor's steps, in order; setScene repeats loadScene's.
  void checkLimits();                      // the GL context's limits and the settings
  void loadScene(const Scene& scene);      // the next five: everything of the scene on the GPU
  std::vector<gpu::BvhWideNode> buildScene(const Scene& scene);  // BVH and GpuScene; flat: the 4-wide nodes
  void planBuffers(const Scene& scene);    // binary nodes cut to the root (flat), the storage blocks' plan
  void uploadScene(const Scene& scene, std::vector<gpu::BvhWideNode> wideNodes);  // buffers and textures
  void createUniformBuffers();             // frame, casters, punctual lights
  void uploadLights(const Scene& scene, const Bounds& sceneBounds);  // point lights, environment

  const ShaderLibrary& library_;
  RendererOptions options_;
  std::unique_ptr<MeshBvhs> meshBvhs_;  // sceneUpdates: the instanced scene's bottom levels, and
  std::uint64_t meshBvhsKey_ = 0;       // the hash of the stored triangles and meshes they were built from
  int meshBvhBuilds_ = 0;
  RenderSettings settings_;
  Camera camera_;
  Bvh bvh_;
  double bvhSeconds_ = 0.0;
  GpuScene gpuScene_;  // nodes, triGeom and triShade are freed once uploaded (only the GPU holds them)
  FeatureSet sceneFeatures_;
  LoadTimes load_;
  std::chrono::steady_clock::time_point created_;
  GpuSceneBytes gpuBytes_;
  SceneBufferLayout bufferLayout_;
  GlLimits limits_;
  std::vector<GlBuffer> buffers_;  // indexed by CAUSTICA_BINDING_*
  BvhTextures bvhTextures_;  // the traversal's views of the nodes and TriGeom buffers
  ShadingTextures shadingTextures_;  // the shading's views of the materials, light-tree and texture buffers
  GlBuffer frameUbo_;
  GlBuffer casterUbo_;
  std::uint32_t cellTableMask_ = 0;  // CasterParams::count.z: the caustic cell table's bucket mask, once built
  std::uint32_t cellCasters_ = 0;    // the casters (manifoldCasterMask) the cell table was built for
  CausticCells causticCells_;
  std::uint32_t guideTableMask_ = 0;  // CasterParams::guide.x: the caster guide table's bucket mask, once built
  CausticCells causticGuides_{CellTable::Guide};
  std::vector<LightGroup> lightGroups_;
  gpu::PointLights pointLights_{};
  GlBuffer pointLightUbo_;
  std::unique_ptr<RasterRenderer> raster_;  // built the first time the raster mode is used
  EnvironmentTextures environment_;  // environment map, CDFs and UBO
  GlBuffer punctualUbo_;  // PunctualParams (KHR_lights_punctual), uploaded once per scene
  GlTexture accum_, comp_, half_, tileList_, display_;
  bool transparent_ = false;  // the scene's background is transparent: coverage_ exists
  GlTexture coverage_;        // r32f camera-ray hits per pixel (CAUSTICA_IMAGE_COVERAGE), if transparent_
  bool features_ = false;     // feature buffers kept (setFeatureBuffers): albedo_ and normal_ exist
  GlTexture albedo_, normal_; // rgba32f feature sums (CAUSTICA_IMAGE_ALBEDO, CAUSTICA_IMAGE_NORMAL)
  std::unique_ptr<Denoiser> denoiser_;  // made at the first denoise()
  double denoiseMs_ = 0.0;
  double denoiseMsTotal_ = 0.0;
  std::uint32_t liveTiles_ = 0;  // entries of tileList_ in use while tileListActive_
  int liveTileSize_ = CAUSTICA_WORKGROUP_X;  // side of those tiles in pixels
  bool tileListActive_ = false;
  std::map<std::string, GlProgram> programs_;
  // Light tracing (CAUSTICA_LIGHT_TRACE): the splats of the last light pass, for sample indices
  // lightFirst_ .. + lightCount_ - 1 (0: none valid; reset() forgets them), as an SSBO and a buffer texture.
  GlBuffer lightSplats_;
  GlBufferTexture lightSplatTexture_;
  std::uint32_t lightFirst_ = 0;
  int lightCount_ = 0;
  float lightSplatUnit_ = 1.0f;  // CasterParams::params.w: radiance of one fixed-point step (loadScene)
  GlProgram tonemapProgram_;
  int spp_ = 0;
  std::uint32_t sampleBase_ = 0;
  RenderStats stats_;
};

}  // namespace caustica
