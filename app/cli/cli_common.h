// cli_common.h — the small option parser every subcommand uses, and the steps they share
// (scene loading, camera choice, image size, context creation).
#pragma once
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "cli/image_settings.h"
#include "platform/gl_context.h"
#include "gpu/renderer.h"
#include "scene/scene.h"
#include "gpu/shader_library.h"

namespace caustica::cli {

struct OptionSpec {
  std::string name;      // "--spp"
  std::string alias;     // "-o" or ""
  std::string metavar;   // "N"; empty for a flag
  std::string help;
};

class Options {
 public:
  Options(std::string usage, std::string summary, std::vector<OptionSpec> specs);
  // Parses args (after the subcommand). Returns false if --help was given (help already printed).
  // Throws Error on unknown options or missing values.
  bool parse(const std::vector<std::string>& args);
  bool has(const std::string& name) const { return values_.count(name) > 0; }
  std::string get(const std::string& name, const std::string& fallback) const;
  int getInt(const std::string& name, int fallback, int lo, int hi) const;
  double getDouble(const std::string& name, double fallback) const;
  const std::vector<std::string>& positional() const { return positional_; }
  // Whether this command declares `name` with metavar LIST (comma-separated values, e.g. bench's
  // --dispersion rgb,spectral) rather than a single value.
  bool isList(const std::string& name) const;
  std::string help() const;

 private:
  std::string usage_, summary_;
  std::vector<OptionSpec> specs_;
  std::map<std::string, std::string> values_;
  std::vector<std::string> positional_;
};

// Options shared by render, view and bench.
std::vector<OptionSpec> sceneOptionSpecs();
// The entry of sceneOptionSpecs() named `name` (for commands that take only some of them).
OptionSpec sceneOptionSpec(const std::string& name);

// Options of every command that loads a scene (render, view, bench, info): how far an untrusted
// scene file is trusted (docs/untrusted-input.md). Part of sceneOptionSpecs().
std::vector<OptionSpec> sceneInputOptionSpecs();
// --allow-outside-paths, --max-texture-mib, --max-buffer-mib, --max-triangles and --instances as LoadOptions
// (defaults: LoadOptions{}); each bad value is an error naming the option.
LoadOptions loadOptionsFrom(const Options& opts);

// The glTF animation options (docs/animation.md): --anim-time SECONDS, --frame N, --fps F,
// --animation NAME|INDEX|all. Part of sceneOptionSpecs().
std::vector<OptionSpec> animationOptionSpecs();
// The pose they ask for: the time is --anim-time, or --frame N / --fps F (default 24), else 0; each bad
// value or combination is an error naming the option. "first" stands for ScenePose's "" (the first).
ScenePose scenePoseFrom(const Options& opts);
// Whether the command line chose a time (--anim-time, --frame or, for render, --frames).
bool animationTimeGiven(const Options& opts);
// "2 animations: 0 'move' 0-2 s (5 channels), 1 'spin' 0-0.5 s (1 channel); showing 0 'move' at t = 0 s",
// or "none".
std::string animationsSummary(const Scene& scene);

// Parses "W" or "WxH". With only W, H follows the camera's aspect ratio (or is W).
void parseSize(const std::string& text, float cameraAspect, int& width, int& height);

struct LoadedScene {
  Scene scene;              // with the settings' scene side applied (applySceneSettings)
  Camera camera;            // the camera settings.camera picked
  ImageSettings settings;   // everything that decides the image (cli/image_settings.h)
};
// The one path from the command line to a scene ready to render (render, view, bench, compare,
// info): loads `nameOrPath` (a bundled scene name or a file), prints its warnings when verbose, picks
// --camera N (default 0; a camera framing the scene if it has none), reads every image setting
// (imageSettingsFrom; --size defaults to `defaultWidth` pixels wide) and applies their scene side
// (applySceneSettings: --light-radius, --env..., --background).
LoadedScene loadSceneForCli(const std::string& nameOrPath, const Options& opts, bool verbose, int defaultWidth = 512);
// The steps of loadSceneForCli after loading, for a scene posed elsewhere (render --frames: one file, a
// pose per frame): camera, image settings (with `pose` as the animation settings), scene settings.
LoadedScene prepareLoadedScene(Scene scene, const Options& opts, const ScenePose& pose, bool verbose,
                               int defaultWidth = 512);
// The same for the command's one positional scene argument (default: the bundled default scene).
LoadedScene loadSceneForCli(const Options& opts, bool verbose, int defaultWidth = 512);
int cameraIndexFrom(const Options& opts);  // --camera N, default 0
// For a mode that draws flat scenes only (RenderModeSpec::instancedScenes false: raster), bakes an
// instanced scene's instances on the host (flattenInstances), or refuses (Error) when that would
// exceed --max-triangles. Does nothing otherwise.
void flattenForMode(Scene& scene, RenderMode mode, const Options& opts, bool quiet);

ShaderLibrary shaderLibraryFrom(const Options& opts);

// Renders until `renderer` holds `targetSpp` samples per pixel. Passes grow while they take under
// 50 ms and shrink above 0.5 s, so progress stays live and no pass trips a GPU watchdog. Prints
// "caustica: LABEL N/M spp" with the elapsed time and an estimate of what is left: in place on a
// terminal, a line every 10 s in logs.
void renderWithProgress(Renderer& renderer, int targetSpp, const std::string& label, bool quiet);

// What a long render does besides rendering (render --checkpoint, SIGINT/SIGTERM).
struct ProgressHooks {
  double checkpointSeconds = 0.0;   // > 0: call `checkpoint` whenever this much time passed since the last
  std::function<void()> checkpoint;
  bool stopOnInterrupt = false;     // stop between passes once interruptRequested()
};
// The same, with hooks. Returns false if it stopped early on an interrupt, true once at targetSpp.
bool renderWithProgress(Renderer& renderer, int targetSpp, const std::string& label, bool quiet,
                        const ProgressHooks& hooks);

// Exit status of a render that was interrupted (SIGINT/SIGTERM) and wrote its partial image.
constexpr int kExitInterrupted = 4;
// Installs SIGINT and SIGTERM handlers (sigaction) that only set a flag; the first signal restores
// the default handlers, so a second one ends the program at once.
void installInterruptHandlers();
bool interruptRequested();
int interruptSignal();  // the signal that set the flag (0 if none)

// Throws Error naming `path` unless a file can be created there: its folder exists, is a folder and
// is writable, and `path` itself is not a folder or a read-only file. `what` names it ("output").
void checkWritableFile(const std::string& path, const std::string& what);

// Prints a line to stderr with the "caustica: " prefix unless quiet.
void note(bool quiet, const std::string& line);

}  // namespace caustica::cli
