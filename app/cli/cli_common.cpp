// cli_common.cpp — option parsing and shared subcommand steps.
#include "cli/cli_common.h"

#include <fcntl.h>
#include <unistd.h>

#include <csignal>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>

#include "cli/environment_options.h"
#include "scene/assets.h"
#include "util/error.h"
#include "util/memory_stats.h"

namespace caustica::cli {

Options::Options(std::string usage, std::string summary, std::vector<OptionSpec> specs)
    : usage_(std::move(usage)), summary_(std::move(summary)), specs_(std::move(specs)) {
  specs_.push_back({"--help", "-h", "", "show this help and exit"});
}

std::string Options::help() const {
  std::ostringstream out;
  out << "usage: " << usage_ << "\n\n" << summary_ << "\n\noptions:\n";
  for (const auto& s : specs_) {
    std::string left = "  " + (s.alias.empty() ? "" : s.alias + ", ") + s.name + (s.metavar.empty() ? "" : " " + s.metavar);
    out << left;
    if (left.size() < 30) out << std::string(30 - left.size(), ' ');
    else out << "\n" << std::string(30, ' ');
    out << s.help << "\n";
  }
  return out.str();
}

bool Options::parse(const std::vector<std::string>& args) {
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a.size() < 2 || a[0] != '-') {
      positional_.push_back(a);
      continue;
    }
    std::string name = a, value;
    bool inlineValue = false;
    size_t eq = a.find('=');
    if (a.rfind("--", 0) == 0 && eq != std::string::npos) {
      name = a.substr(0, eq);
      value = a.substr(eq + 1);
      inlineValue = true;
    }
    const OptionSpec* spec = nullptr;
    for (const auto& s : specs_)
      if (s.name == name || (!s.alias.empty() && s.alias == name)) spec = &s;
    if (!spec) throw Error("unknown option '" + a + "' (see --help)");
    if (spec->name == "--help") {
      std::cout << help();
      return false;
    }
    if (spec->metavar.empty()) {
      if (inlineValue) throw Error("option " + spec->name + " takes no value");
      values_[spec->name] = "1";
    } else {
      if (!inlineValue) {
        if (i + 1 >= args.size()) throw Error("option " + spec->name + " needs a value (" + spec->metavar + ")");
        value = args[++i];
      }
      values_[spec->name] = value;
    }
  }
  return true;
}

bool Options::isList(const std::string& name) const {
  for (const auto& s : specs_)
    if (s.name == name) return s.metavar == "LIST";
  return false;
}

std::string Options::get(const std::string& name, const std::string& fallback) const {
  auto it = values_.find(name);
  return it == values_.end() ? fallback : it->second;
}

int Options::getInt(const std::string& name, int fallback, int lo, int hi) const {
  auto it = values_.find(name);
  if (it == values_.end()) return fallback;
  const std::string& v = it->second;
  char* end = nullptr;
  long n = std::strtol(v.c_str(), &end, 10);
  if (v.empty() || *end != '\0' || n < lo || n > hi)
    throw Error("option " + name + " needs an integer from " + std::to_string(lo) + " to " + std::to_string(hi) +
                ", got '" + v + "'");
  return static_cast<int>(n);
}

double Options::getDouble(const std::string& name, double fallback) const {
  auto it = values_.find(name);
  if (it == values_.end()) return fallback;
  char* end = nullptr;
  double d = std::strtod(it->second.c_str(), &end);
  if (it->second.empty() || *end != '\0' || !std::isfinite(d))
    throw Error("option " + name + " needs a number, got '" + it->second + "'");
  return d;
}

std::vector<OptionSpec> sceneOptionSpecs() {
  std::vector<OptionSpec> specs = {
      {"--size", "", "W[xH]", "image size in pixels (default 512; H follows the camera's aspect)"},
      {"--mode", "", "MODE", renderModeHelp()},
      {"--seed", "", "S", "random seed (default 1); the same seed gives the same image"},
      {"--integrator", "", "NAME", "naive (BSDF sampling only) or mis (light sampling + MIS; default)"},
      {"--dispersion", "", "MODE", "rgb (one channel per path; default) or spectral (hero wavelength)"},
      {"--max-depth", "", "N", "maximum path length in bounces, a safety cap: Russian roulette ends paths (default 256)"},
      {"--caster-probability", "", "P",
       "mis: chance that a diffuse bounce aims at a glass or mirror object (0 to 0.9, default 0.5; 0 = off)"},
      {"--guide-probability", "", "P",
       "mis: chance that a bounce aimed at a glass or mirror object follows the direction its caustic photons "
       "came from near the vertex (caster guiding, for the objects the lights look small from, as --manifold auto "
       "picks them; 0 to 1, default 0.5; 0 = off)"},
      {"--manifold", "", "auto|on|off",
       "mis: manifold next-event estimation, light joined to diffuse points through glass and mirror objects "
       "(caustics of small lights); auto (default) uses it only under --light-tracing off, through the objects "
       "the lights look small from (caustica info lists them); on through all, instead of light tracing"},
      {"--light-tracing", "", "on|off",
       "mis: light subpaths from the emitters through glass and mirror objects add the caustics the camera "
       "sees on diffuse surfaces (default on; not beside manifold NEE: --manifold on takes precedence, auto "
       "leaves manifold NEE off)"},
      {"--light-paths", "", "R", "light tracing: light subpaths per pixel and sample (1/64 to 64, default 0.125)"},
      {"--camera", "", "N", "use the scene's N-th perspective camera (default 0)"},
      {"--light-radius", "", "R",
       "turn point and spot lights into emissive spheres of radius R (scene units), same power: bounces find "
       "them, so their caustics appear (more noise)"},
      {"--backend", "", "NAME", "auto (EGL, then OSMesa; default), egl or osmesa"},
      {"--shader-dir", "", "DIR", "load shaders from DIR instead of the embedded copies"},
      {"--all-features", "", "",
       "compile every material feature into the path tracer instead of the scene's (measures specialisation; "
       "same image)"},
      {"--samples-per-dispatch", "", "K",
       "path tracer: samples per pixel per GPU dispatch (0 = automatic, the default; lowered where the depth cap "
       "needs it); changes the speed, never the image"},
      {"--quiet", "-q", "", "print nothing but errors"},
  };
  for (OptionSpec& s : environmentOptionSpecs()) specs.push_back(std::move(s));
  for (OptionSpec& s : animationOptionSpecs()) specs.push_back(std::move(s));
  for (OptionSpec& s : sceneInputOptionSpecs()) specs.push_back(std::move(s));
  return specs;
}

std::vector<OptionSpec> animationOptionSpecs() {
  return {
      {"--anim-time", "", "SECONDS", "pose the scene's glTF animation at this time (default 0; docs/animation.md)"},
      {"--frame", "", "N", "pose it at frame N of --fps frames a second (time N / F)"},
      {"--fps", "", "F", "frames a second for --frame and --frames (default 24)"},
      {"--animation", "", "NAME|INDEX",
       "which of the file's animations plays: its name or index, or all (default: all when no two animate the "
       "same node property, else the first)"},
  };
}

bool animationTimeGiven(const Options& opts) {
  return opts.has("--anim-time") || opts.has("--frame") || opts.has("--frames");
}

ScenePose scenePoseFrom(const Options& opts) {
  ScenePose pose;
  pose.animation = opts.get("--animation", "");
  if (opts.has("--animation") && pose.animation.empty()) throw Error("option --animation needs a name, an index or all");
  if (pose.animation == "first") pose.animation.clear();
  const double fps = opts.getDouble("--fps", 24.0);
  if (!(fps > 0.0 && fps <= 1e6)) throw Error("option --fps needs a number of frames a second above 0");
  if (opts.has("--fps") && !opts.has("--frame") && !opts.has("--frames"))
    throw Error("option --fps needs --frame N (or render's --frames A..B)");
  if (opts.has("--anim-time") && (opts.has("--frame") || opts.has("--frames")))
    throw Error("give the time with --anim-time or with --frame/--frames, not both");
  if (opts.has("--anim-time")) {
    pose.time = opts.getDouble("--anim-time", 0.0);
    if (!(std::abs(pose.time) < 1e9)) throw Error("option --anim-time needs a finite number of seconds");
  } else if (opts.has("--frame")) {
    pose.time = double(opts.getInt("--frame", 0, 0, 1 << 30)) / fps;
  }
  return pose;
}

std::string animationsSummary(const Scene& s) {
  if (s.animations.empty()) return "none";
  auto seconds = [](double t) {
    char b[32];
    std::snprintf(b, sizeof b, "%.4g", t);
    return std::string(b);
  };
  std::string out = std::to_string(s.animations.size()) + (s.animations.size() == 1 ? " animation: " : " animations: ");
  constexpr std::size_t kListed = 4;  // files with one animation per node have dozens
  for (std::size_t i = 0; i < s.animations.size(); ++i) {
    if (i == kListed) {
      out += ", ... (" + std::to_string(s.animations.size() - kListed) + " more)";
      break;
    }
    const AnimationInfo& a = s.animations[i];
    out += (i ? ", " : "") + std::to_string(i) + (a.name.empty() ? "" : " '" + a.name + "'") + " " + seconds(a.start) +
           "-" + seconds(a.end) + " s (" + std::to_string(a.channels) + (a.channels == 1 ? " channel" : " channels") +
           (a.weights ? ", morph weights" : "") + (a.skins ? ", skin joints" : "") + ")";
  }
  std::string played;
  if (s.animationsPlayed.size() > 1 && s.animationsPlayed.size() == s.animations.size()) played = "all";
  else
    for (int i : s.animationsPlayed)
      played += (played.empty() ? "" : " and ") + std::to_string(i) +
                (s.animations[std::size_t(i)].name.empty() ? "" : " '" + s.animations[std::size_t(i)].name + "'");
  return out + "; showing " + (played.empty() ? "none" : played) + " at t = " + seconds(s.animationTime) + " s";
}

std::vector<OptionSpec> sceneInputOptionSpecs() {
  const LoadOptions defaults;
  return {
      {"--allow-outside-paths", "", "",
       "let the scene's buffer and image files lie outside its folder (absolute paths, '..', symlinks)"},
      {"--max-texture-mib", "", "N",
       "refuse scenes whose images decode to more than N MiB in all (default " +
           std::to_string(defaults.maxTextureBytes >> 20) + ")"},
      {"--max-buffer-mib", "", "N",
       "refuse scenes whose buffers declare more than N MiB in all (default " +
           std::to_string(defaults.maxBufferBytes >> 20) + ")"},
      {"--max-triangles", "", "N",
       "refuse scenes with more than N triangles (default " + std::to_string(defaults.maxTriangles) + ")"},
      {"--instances", "", "auto|on|off",
       "keep meshes placed several times once on the GPU (two-level BVH): on, off (flatten them), or auto "
       "(default): on when the placed triangles exceed --max-triangles or 4x the stored ones"},
  };
}

LoadOptions loadOptionsFrom(const Options& opts) {
  LoadOptions o;
  o.allowOutsidePaths = opts.has("--allow-outside-paths");
  o.maxTextureBytes = std::uint64_t(opts.getInt("--max-texture-mib", int(o.maxTextureBytes >> 20), 1, 1 << 20)) << 20;
  o.maxBufferBytes = std::uint64_t(opts.getInt("--max-buffer-mib", int(o.maxBufferBytes >> 20), 1, 1 << 20)) << 20;
  o.maxTriangles = std::uint64_t(opts.getInt("--max-triangles", int(o.maxTriangles), 1, 1 << 30));
  const std::string instances = opts.get("--instances", "auto");
  if (instances != "auto" && instances != "on" && instances != "off")
    throw Error("option --instances expects auto, on or off, got '" + instances + "'");
  o.keepInstances = instances != "off";
  o.autoInstances = instances == "auto";
  return o;
}

OptionSpec sceneOptionSpec(const std::string& name) {
  for (const OptionSpec& s : sceneOptionSpecs())
    if (s.name == name) return s;
  throw Error("internal: no scene option " + name);
}

void parseSize(const std::string& text, float cameraAspect, int& width, int& height) {
  size_t x = text.find('x');
  auto num = [&](const std::string& s) {
    char* end = nullptr;
    long n = std::strtol(s.c_str(), &end, 10);
    if (s.empty() || *end != '\0' || n < 1 || n > kMaxImageSide)
      throw Error("bad --size '" + text + "' (expected W or WxH, 1 to " + std::to_string(kMaxImageSide) + ")");
    return static_cast<int>(n);
  };
  if (x == std::string::npos) {
    width = num(text);
    height = cameraAspect > 0.0f ? std::max(1, static_cast<int>(std::lround(width / cameraAspect))) : width;
  } else {
    width = num(text.substr(0, x));
    height = num(text.substr(x + 1));
  }
}

namespace {
volatile std::sig_atomic_t gInterrupt = 0;

extern "C" void onInterrupt(int sig) {
  gInterrupt = sig;
  // The first signal asks for a clean stop; the next one ends the program at once.
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
}
}  // namespace

void installInterruptHandlers() {
  struct sigaction sa {};
  sa.sa_handler = onInterrupt;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART needed: the loop only polls the flag
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

bool interruptRequested() { return gInterrupt != 0; }
int interruptSignal() { return static_cast<int>(gInterrupt); }

void checkWritableFile(const std::string& path, const std::string& what) {
  namespace fs = std::filesystem;
  fs::path p(path);
  fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  std::error_code ec;
  if (!fs::exists(dir, ec)) throw Error(path + ": cannot write the " + what + ": folder '" + dir.string() + "' does not exist");
  if (!fs::is_directory(dir, ec)) throw Error(path + ": cannot write the " + what + ": '" + dir.string() + "' is not a folder");
  if (fs::is_directory(p, ec)) throw Error(path + ": cannot write the " + what + ": it is a folder");
  if (fs::exists(p, ec) && ::access(path.c_str(), W_OK) != 0)
    throw Error(path + ": cannot write the " + what + ": " + std::strerror(errno));
  // Create and remove a file next to it: the only test that covers permissions, read-only mounts
  // and full quotas alike.
  std::string probe = (dir / (".caustica-write-test-" + std::to_string(::getpid()))).string();
  int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0)
    throw Error(path + ": cannot write the " + what + " in folder '" + dir.string() + "': " + std::strerror(errno));
  ::close(fd);
  ::unlink(probe.c_str());
}

void renderWithProgress(Renderer& renderer, int targetSpp, const std::string& label, bool quiet) {
  renderWithProgress(renderer, targetSpp, label, quiet, ProgressHooks{});
}

bool renderWithProgress(Renderer& renderer, int targetSpp, const std::string& label, bool quiet,
                        const ProgressHooks& hooks) {
  const auto start = std::chrono::steady_clock::now();
  auto seconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  const bool tty = isatty(STDERR_FILENO) != 0;
  const int first = renderer.samplesPerPixel();
  int batch = 1;
  double lastPrint = -1.0, lastCheckpoint = 0.0;
  bool stopped = false;
  while (renderer.samplesPerPixel() < targetSpp) {
    double t0 = seconds();
    // At least the samples one dispatch traces (path regeneration, Renderer::samplesPerDispatch).
    renderer.renderPass(std::min(std::max(batch, renderer.samplesPerDispatch()), targetSpp - renderer.samplesPerPixel()));
    double dt = seconds() - t0;
    if (dt < 0.05 && batch < 256) batch *= 2;
    else if (dt > 0.5 && batch > 1) batch /= 2;
    double now = seconds();
    int done = renderer.samplesPerPixel();
    if (!quiet && (now - lastPrint > (tty ? 0.5 : 10.0) || done == targetSpp)) {
      lastPrint = now;
      double eta = now / (done - first) * (targetSpp - done);
      std::fprintf(stderr, "%scaustica: %s%s%d/%d spp  %.1f s  eta %.1f s%s", tty ? "\r" : "", label.c_str(),
                   label.empty() ? "" : " ", done, targetSpp, now, eta, tty ? "   " : "\n");
      std::fflush(stderr);
    }
    if (hooks.stopOnInterrupt && interruptRequested()) {
      stopped = true;
      break;
    }
    if (hooks.checkpointSeconds > 0.0 && hooks.checkpoint && now - lastCheckpoint >= hooks.checkpointSeconds &&
        done < targetSpp) {
      hooks.checkpoint();
      lastCheckpoint = seconds();
    }
  }
  if (!quiet && tty && renderer.samplesPerPixel() > first) std::fprintf(stderr, "\n");
  return !stopped;
}

void note(bool quiet, const std::string& line) {
  if (!quiet) std::cerr << "caustica: " << line << "\n";
}

int cameraIndexFrom(const Options& opts) { return opts.getInt("--camera", 0, 0, 1 << 20); }

LoadedScene loadSceneForCli(const std::string& nameOrPath, const Options& opts, bool verbose, int defaultWidth) {
  const LoadOptions loadOptions = loadOptionsFrom(opts);  // option errors before any file is read
  const ScenePose pose = scenePoseFrom(opts);
  std::string path = resolveScenePath(nameOrPath);
  Scene scene = loadScene(path, loadOptions, pose);
  releaseFreedMemory();  // the parser's arrays and the file's bytes: freed heap back to the kernel (memory_stats.h)
  for (const auto& w : scene.warnings) note(!verbose, "warning: " + w);
  if (!scene.animations.empty() && !animationTimeGiven(opts))
    note(!verbose, path + " has " + animationsSummary(scene) +
                       " (choose the time with --anim-time SECONDS or --frame N --fps F, the animation with --animation)");
  else if (scene.animations.empty() && animationTimeGiven(opts))
    note(!verbose, "warning: " + path + " has no animations: the time given changes nothing");
  return prepareLoadedScene(std::move(scene), opts, pose, verbose, defaultWidth);
}

LoadedScene prepareLoadedScene(Scene scene, const Options& opts, const ScenePose& pose, bool verbose, int defaultWidth) {
  LoadedScene ls;
  ls.scene = std::move(scene);
  const std::string& path = ls.scene.path;
  int index = cameraIndexFrom(opts);
  if (ls.scene.cameras.empty()) {
    if (opts.has("--camera")) throw Error(path + ": the scene has no camera, --camera cannot pick one");
    ls.camera = autoCamera(ls.scene.bounds);
  } else {
    if (index >= static_cast<int>(ls.scene.cameras.size()))
      throw Error(path + ": --camera " + std::to_string(index) + " but the scene has " +
                  std::to_string(ls.scene.cameras.size()) + " camera(s)");
    ls.camera = ls.scene.cameras[static_cast<size_t>(index)];
  }
  ls.settings = imageSettingsFrom(opts, ls.camera, defaultWidth);
  // The pose the scene was built with is part of the image (accumulation identity); a file without
  // animations looks the same at any time, so its identity keeps the defaults.
  const SceneSettings unposed;
  ls.settings.scene.animation = ls.scene.animations.empty() ? unposed.animation : pose.animation.empty() ? "first" : pose.animation;
  ls.settings.scene.animTime = ls.scene.animations.empty() ? unposed.animTime : pose.time;
  applySceneSettings(ls.settings, ls.scene, verbose);
  return ls;
}

void flattenForMode(Scene& scene, RenderMode mode, const Options& opts, bool quiet) {
  const RenderModeSpec& spec = renderModeSpec(mode);
  if (scene.instances.empty() || spec.instancedScenes) return;
  const std::uint64_t placed = instancedTriangleCount(scene);
  const std::uint64_t limit = loadOptionsFrom(opts).maxTriangles;
  if (placed > limit)
    throw Error(scene.path + ": the " + spec.name + " mode draws flattened scenes, and flattening its " +
                std::to_string(scene.instances.size()) + " instances makes " + std::to_string(placed) +
                " triangles, more than the limit of " + std::to_string(limit) + " (use --max-triangles to raise it)");
  note(quiet, std::string(spec.name) + " mode: " + std::to_string(scene.instances.size()) + " instances flattened into " +
                  std::to_string(placed) + " triangles");
  flattenInstances(scene);
}

LoadedScene loadSceneForCli(const Options& opts, bool verbose, int defaultWidth) {
  if (opts.positional().size() > 1) throw Error("expected one scene, got " + std::to_string(opts.positional().size()));
  return loadSceneForCli(opts.positional().empty() ? kDefaultScene : opts.positional()[0], opts, verbose, defaultWidth);
}

ShaderLibrary shaderLibraryFrom(const Options& opts) { return ShaderLibrary(opts.get("--shader-dir", "")); }

}  // namespace caustica::cli
