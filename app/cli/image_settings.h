// image_settings.h — everything that decides a command's image, in one value: the RenderSettings, the
// options that change the loaded scene (--env, --env-strength, --env-rotation, --background,
// --light-radius), the camera and the output's tone mapping. Read from the command line once
// (imageSettingsFrom), applied to the scene in one place (applySceneSettings), and listed field by
// field once (visitFields), from which the accumulation identity of checkpoints is derived.
#pragma once
#include <string>
#include <type_traits>

#include "accel/gpu_scene.h"
#include "gpu/render_settings.h"
#include "image/tonemap.h"
#include "scene/scene.h"

namespace caustica {
std::string settingText(ToneCurve v);  // beside the settingText overloads of gpu/render_settings.h
}

namespace caustica::cli {

class Options;

// The options that change the Scene after it is loaded, as the user gave them (docs/lighting.md).
struct SceneSettings {
  // --env: FILE (.hdr/.exr or a bundled map's name), a radiance ("0.8" or "R,G,B") or "none"; "auto"
  // (the default): none if the scene has emitters, else a uniform sky of radiance 1.
  std::string env = "auto";
  float envStrength = 1.0f;          // --env-strength: multiplies the environment's radiance
  float envRotation = 0.0f;          // --env-rotation: degrees about +Y, right-handed
  std::string background = "env";    // --background: "env", "transparent" or a colour ("0.2", "R,G,B")
  float lightRadius = 0.0f;          // --light-radius in scene units; 0: point and spot lights stay points
  // The glTF animation pose (docs/animation.md): --animation ("first", "all", a name or an index) and
  // the time in seconds (--anim-time, or --frame N / --fps F). Loading applies them (scenePoseFrom);
  // for a file without animations they stay at "first" and 0 (nothing moves).
  std::string animation = "first";
  double animTime = 0.0;
};

struct ImageSettings {
  RenderSettings render;   // how the renderer renders (app/gpu, no command line there)
  SceneSettings scene;     // what is changed in the scene before it is uploaded
  int camera = 0;          // --camera: the scene's N-th perspective camera
  ToneMapSettings tone;    // --exposure, --tonemap: how the sums become a PNG (output only)
};

// The fields of each part, as visitFields(RenderSettings) does (gpu/render_settings.h): visit(name,
// role, field) for every field, in one fixed order; a static_assert fails the build when a field is
// added without a line. Adding an option that changes the image: a field here (or in RenderSettings),
// its line with its role, its parsing in imageSettingsFrom and, if it changes the scene, its effect in
// applySceneSettings. The identity, the resume check and printing then follow by themselves.
template <class S, class Visit>
void visitSceneFields(S& s, Visit&& visit) {
  visit("env", SettingRole::Accumulation, s.env);
  visit("env-strength", SettingRole::Accumulation, s.envStrength);
  visit("env-rotation", SettingRole::Accumulation, s.envRotation);
  visit("background", SettingRole::Accumulation, s.background);
  visit("light-radius", SettingRole::Accumulation, s.lightRadius);
  visit("animation", SettingRole::Accumulation, s.animation);
  visit("anim-time", SettingRole::Accumulation, s.animTime);
}
static_assert(fieldCount<SceneSettings>() == 7, "SceneSettings has a field that visitSceneFields does not list");

template <class S, class Visit>
void visitToneFields(S& s, Visit&& visit) {
  visit("exposure", SettingRole::Output, s.exposureStops);
  visit("tonemap", SettingRole::Output, s.curve);
}
static_assert(fieldCount<ToneMapSettings>() == 2, "ToneMapSettings has a field that visitToneFields does not list");

template <class S, class Visit, std::enable_if_t<std::is_same_v<std::remove_const_t<S>, ImageSettings>, int> = 0>
void visitFields(S& s, Visit&& visit) {  // S: ImageSettings or const ImageSettings
  caustica::visitFields(s.render, visit);
  visitSceneFields(s.scene, visit);
  visit("camera", SettingRole::Accumulation, s.camera);
  visitToneFields(s.tone, visit);
}
static_assert(fieldCount<ImageSettings>() == 4, "ImageSettings has a part that visitFields does not list");

// Reads every image setting from the command line, each checked with an error naming its option: the
// RenderSettings (--size, default `defaultWidth` wide with the height from the camera's aspect,
// --seed, --max-depth, --integrator, --dispersion, --mode, --caster-probability, --all-features,
// --samples-per-dispatch), --env, --env-strength, --env-rotation, --background, --light-radius,
// --camera, --exposure, --tonemap. An option the command does not declare keeps its default; one it
// declares as a LIST (bench) too: the command sets it per run.
ImageSettings imageSettingsFrom(const Options& opts, const Camera& camera, int defaultWidth);

// The one place the scene side of the settings reaches the Scene: --light-radius turns point and spot
// lights into emissive spheres, then the environment and background are set (a scene with no light
// and env "auto" gets the uniform default, said in a line unless !verbose). Throws Error naming a bad
// environment file.
void applySceneSettings(const ImageSettings& settings, Scene& scene, bool verbose);

// "key value" lines, one per field of `role` (visitFields order).
std::string settingsLines(const ImageSettings& settings, SettingRole role);
// Every field on one line, "width 512, height 512, ..., tonemap aces" (render prints it).
std::string settingsSummary(const ImageSettings& settings);

// The accumulation identity: settingsLines(settings, Accumulation), then "camera-view" with the camera
// `settings.camera` picked (position, forward, up, yfov, aspect). Two renders of the same scene files
// (hashSceneFiles) may add their samples together — resume a checkpoint, merge shards — only if their
// identities are equal; Speed and Output fields may differ. It is the text stored in a checkpoint
// (cli/checkpoint.h); compare two with identityDifference.
std::string accumulationIdentity(const ImageSettings& settings, const Camera& camera);
// The accumulation identity of a render of the scene packed as `gpu` (Renderer::gpuScene): as above,
// with the manifold and guide-probability lines as the image sees them (imageManifoldMode,
// imageGuideProbability). What checkpoints and shard partials
// record and resuming compares, so that `--manifold auto` on a scene where auto finds no caster
// continues a `--manifold off` render and the other way round.
std::string accumulationIdentity(const ImageSettings& settings, const Camera& camera, const GpuScene& gpu);
// The manifold mode that decides the image of the scene packed as `gpu` under `settings`: Auto becomes
// Off where light tracing compiles or where it sends photons to no caster (resolveManifold: the off
// variant), On where it takes every caster On takes (the same variant and photon cells), and stays Auto
// where it takes some casters only (an image neither On nor Off renders). On and Off stay as given.
ManifoldMode imageManifoldMode(const RenderSettings& settings, const GpuScene& gpu);
// --guide-probability as the image sees it: 0 where caster guiding is not compiled (naive, no caster
// aiming, no caster the emitters look small from: guideCasterMask), so that such renders continue and
// merge whatever it says.
float imageGuideProbability(const RenderSettings& settings, const GpuScene& gpu);
// --light-tracing as the image sees it: on only where the light-tracing row compiles (the path tracer,
// mis, a caster, an emissive triangle, --manifold off or auto), so that renders of other scenes
// continue and merge whatever it says (and --light-paths with it).
bool imageLightTracing(const RenderSettings& settings, const GpuScene& gpu);
// An identity text with its manifold line replaced by imageManifoldMode for `gpu` and the identity's own
// light-tracing, integrator and mode lines (a text without one, or with a line this build cannot read, is
// returned as it is). Resuming compares both sides through it: a checkpoint that recorded "manifold auto"
// literally reads as what auto gives for the scene.
std::string resolveIdentityManifold(const std::string& identity, const GpuScene& gpu);
// resolveIdentityManifold, the guide-probability line as 0 where guiding is not compiled for the scene
// (no caster it applies to, imageGuideProbability), and the light-tracing line as off (light-paths as the
// default) where light tracing is not (imageLightTracing): what resuming compares once the scene is packed.
std::string resolveIdentityScene(const std::string& identity, const GpuScene& gpu);
// The identity text without its manifold, guide-probability, light-tracing and light-paths lines (what they
// mean depends on the scene): what can be compared before the scene is packed.
std::string identityWithoutSceneLines(const std::string& identity);

// What differs between two identity texts, "key: LABEL-A a, LABEL-B b; ..." (a key missing on one
// side shows "(none)", except a setting added later, which its absence gives the value it had before:
// guide-probability 0); "" when they are equal. E.g. labels "checkpoint" and "this render".
std::string identityDifference(const std::string& a, const std::string& b, const std::string& labelA,
                               const std::string& labelB);

}  // namespace caustica::cli
