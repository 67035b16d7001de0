// shader_features.h — the shader-feature table: one row per #define that specialises the compute
// shaders (CAUSTICA_MIRROR, CAUSTICA_MIS, ...), with its name in `caustica info`, what turns it on
// (the scene, the settings, or both), what it compiles in and what --all-features does with it.
// Feature detection, the Renderer's defines, `info`, --all-features and the shader tests read the
// rows; nothing else lists features. Adding a lobe or an estimator: its GLSL under #ifdef, one row in
// shader_features.cpp, a line in docs/shader-features.md, its tests (docs/architecture.md).
#pragma once
#include <bitset>
#include <string>
#include <vector>

#include "accel/gpu_scene.h"
#include "gpu/render_settings.h"
#include "scene/scene.h"

namespace caustica {

// Who decides a feature.
enum class FeatureKind {
  Scene,       // the scene alone (its materials and lights): `info` lists it
  Image,       // what the image holds beside colour (alpha coverage): the scene and the render mode
  Integrator,  // the path tracer's estimators, from the settings: only in modes whose RenderModeSpec
               // has pathTracer
  Output,      // what the path tracer records beside the image (the denoiser's feature buffers): on when
               // the Renderer keeps them (Renderer::setFeatureBuffers), whatever the scene; path tracer only
};
const char* featureKindName(FeatureKind k);  // "scene" | "image" | "integrator" | "output"

// What --all-features (the unspecialised path tracer, RenderSettings::allFeatures) does with a row.
enum class AllFeatures {
  Force,  // compiled in whatever the scene needs
  Keep,   // as without --all-features
  Drop,   // left out (a specialisation that removes code)
};

// What a row's scene test sees: the loaded scene, what packing made of it (emitters, casters, the
// environment map, punctual lights), and which materials some triangle uses.
struct SceneView {
  const Scene& scene;
  const GpuScene& gpu;
  const std::vector<bool>& usedMaterials;
};

struct ShaderFeature {
  const char* name;     // as `caustica info` prints it ("mirror"); unique
  const char* define;   // what the GLSL tests with #ifdef ("CAUSTICA_MIRROR"); unique
  FeatureKind kind;
  const char* summary;  // one line: what it compiles in
  const char* when;     // one line: what turns it on, in words (what the tests below check)
  // On for a scene where a material some triangle uses passes `material`, or where `scene` holds
  // (either may be null; with both null the row is on for every scene) ...
  bool (*material)(const Material&);
  bool (*scene)(const SceneView&);
  // ... and, where given, only under these settings.
  bool (*settings)(const RenderSettings&);
  const char* needs;     // an earlier row's define that must be on too, or nullptr
  AllFeatures allFeatures;
};

constexpr std::size_t kMaxShaderFeatures = 64;  // FeatureSet's capacity

// The table, in the order defines are written (and `info` lists features).
const std::vector<ShaderFeature>& shaderFeatureTable();
std::size_t shaderFeatureIndex(const std::string& define);  // throws Error for a define not in the table

// A set of rows of the table.
class FeatureSet {
 public:
  bool has(const std::string& define) const { return rows_.test(shaderFeatureIndex(define)); }
  bool test(std::size_t row) const { return rows_.test(row); }
  void set(std::size_t row, bool on) { rows_.set(row, on); }
  bool operator==(const FeatureSet& o) const { return rows_ == o.rows_; }
  FeatureSet only(FeatureKind kind) const;    // the rows of one kind
  std::vector<std::string> defines() const;  // in table order
  std::string describe() const;              // names of its Scene rows: "mirror glass ggx", or "diffuse only"

 private:
  std::bitset<kMaxShaderFeatures> rows_;
};

// The loader's feature detection: every row whose material and scene tests hold (its settings test
// is not asked). `gpu` is `scene` packed (packScene, packInstancedScene).
FeatureSet detectFeatures(const Scene& scene, const GpuScene& gpu);
// The rows one compute variant compiles: those of `scene` whose settings test holds and whose kind
// the mode compiles (none without an entry shader; integrator and output rows only in the path
// tracer), the output rows when `featureBuffers`, with --all-features applied (path tracer only) and
// each row's `needs` checked.
FeatureSet variantFeatures(const FeatureSet& scene, const RenderSettings& settings, bool featureBuffers = false);
// The casters the caustic photon pass sends photons to under manifold mode m (bit i: caster i; the
// cell table holds no other caster's cells, so manifold NEE and its MIS weight skip them alike): every
// caster under On, those with CausticCaster::manifoldAuto under Auto, none under Off or without emitters.
std::uint32_t manifoldCasterMask(ManifoldMode m, const GpuScene& g);
// The settings with --manifold auto decided for the scene: Off where light tracing compiles (it takes the
// caustics of emissive triangles), else On where manifoldCasterMask(Auto) holds a caster (the manifold
// row's settings test reads On; a scene where auto finds no caster compiles the same variant as off), else
// Off. And caster aiming off (casterProbability 0) where light tracing compiles, unless a caster's emitters
// look small from it (guideCasterMask) or the scene has an environment map or a punctual light: beside light
// tracing aiming serves only the caustics it does not take. What the Renderer asks variantFeatures with.
RenderSettings resolveManifold(RenderSettings s, const GpuScene& g);
// Whether the light-tracing row compiles for settings `s` (--manifold auto resolved or not: auto leaves
// it on) on `g`: the path tracer, mis, --light-tracing on, --manifold not on, a caster and an emissive
// triangle. The one test resolveManifold and the accumulation identity (imageLightTracing) share.
bool lightTracingCompiled(const RenderSettings& s, const GpuScene& g);
// The casters caster guiding sends its photons to: those --manifold auto chooses (smooth, the emitters
// subtending less than kManifoldAutoSolidAngle from them), where guiding measured a gain; under larger
// lamps it measured a loss (docs/path-tracer.md). 0: guiding is not compiled.
std::uint32_t guideCasterMask(const GpuScene& g);
// The casters whose cone a diffuse bounce may aim at (caster aiming, --caster-probability): every glass
// caster (on its shadow side, casterFacesLights), and every mirror but one whose emissive triangles subtend
// kManifoldAutoSolidAngle or more from its centre. Under such lamps a mirror's reflection of them is found
// by cosine sampling about as often as by aiming at its whole cone, which measured a loss
// (docs/path-tracer.md); mirrors lit by small lamps, the sun, the environment or punctual lights keep it.
// A caster outside the mask may still get guide lobes (caster guiding). 0: caster aiming is not compiled.
std::uint32_t aimCasterMask(const GpuScene& g);
// Every row the mode's entry shader can read (what the shader tests compile combinations of).
FeatureSet modeFeatureRows(RenderMode mode);

}  // namespace caustica
