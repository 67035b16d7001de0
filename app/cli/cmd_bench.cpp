// cmd_bench.cpp — `caustica bench`: run time against error for each estimator. Renders each scene
// progressively, measures relMSE against a (cached) high-spp reference at log-spaced times, and
// writes a CSV, a gnuplot log-log plot per scene and a summary table.
#include <sys/wait.h>

#include <spawn.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli/cli_common.h"
#include "cli/commands.h"
#include "scene/assets.h"
#include "cli/bench/bench_metrics.h"
#include "util/error.h"
#include "util/file_io.h"
#include "image/image_io.h"
#include "platform/context.h"

extern char** environ;

namespace caustica::cli {

namespace {

namespace fs = std::filesystem;

constexpr const char* kCacheVersion = "caustica-bench-reference-v1";
constexpr double kFirstCheckpoint = 0.25;  // seconds
constexpr int kCheckpointsPerOctave = 2;
constexpr int kDefaultReferenceSpp = 1024;
// Seed of rendered references: above the largest --seed (2^31 - 1), so never a measured run's seed,
// and fixed, so runs with other seeds reuse the cached reference.
constexpr std::uint32_t kReferenceSeed = 0x9E3779BAu;
constexpr double kMaxDispatchSeconds = 0.1;  // longest single dispatch we aim for (GPU watchdogs, progress)

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}
std::string sci(double v) { return std::isfinite(v) ? fmt("%.3g", v) : "n/a"; }

// "vendor | renderer | version" -> "renderer".
std::string rendererOf(const std::string& glInfo) {
  size_t a = glInfo.find(" | ");
  if (a == std::string::npos) return glInfo;
  size_t b = glInfo.find(" | ", a + 3);
  return glInfo.substr(a + 3, b == std::string::npos ? std::string::npos : b - a - 3);
}

// Where bench/scenes.json is: --scenes-json, else next to the bundled scenes, else the source tree.
std::string findScenesJson(const Options& opts) {
  if (opts.has("--scenes-json")) return opts.get("--scenes-json", "");
  std::vector<fs::path> candidates = {fs::path(assetSceneDir()) / ".." / ".." / "bench" / "scenes.json",
                                      fs::path(assetSceneDir()) / ".." / "bench" / "scenes.json",
                                      fs::path(CAUSTICA_SOURCE_DIR) / "bench" / "scenes.json"};
  for (const auto& c : candidates) {
    std::error_code ec;
    if (fs::is_regular_file(c, ec)) return fs::weakly_canonical(c, ec).string();
  }
  return "";
}

std::string defaultCacheDir() {
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return (fs::path(x) / "caustica" / "references").string();
  if (const char* h = std::getenv("HOME"); h && *h) return (fs::path(h) / ".cache" / "caustica" / "references").string();
  return "bench-out/cache";
}

// Hash of the scene file and of the files it names (external glTF buffers and images).
std::uint64_t hashSceneFiles(const std::string& path) {
  std::string bytes = readFileText(path);
  std::uint64_t h = fnv1a64(bytes);
  if (fileExtension(path) != ".gltf") return h;
  try {
    nlohmann::json j = nlohmann::json::parse(bytes);
    for (const char* key : {"buffers", "images"}) {
      if (!j.contains(key) || !j[key].is_array()) continue;
      for (const auto& item : j[key]) {
        if (!item.is_object() || !item.contains("uri") || !item["uri"].is_string()) continue;
        std::string uri = item["uri"].get<std::string>();
        if (uri.rfind("data:", 0) == 0) continue;
        fs::path p = fs::path(path).parent_path() / uri;
        std::error_code ec;
        if (fs::is_regular_file(p, ec)) h = fnv1a64(readFileText(p.string()), fnv1a64(uri, h));
      }
    }
  } catch (const nlohmann::json::exception&) {
    // The loader accepted the file; anything it could not name is covered by the file's own bytes.
  }
  return h;
}

// Writes to a temporary name and renames, so that an interrupted run leaves no half file behind.
void writeImageAtomic(const std::string& path, const Image& image) {
  std::string tmp = path + ".tmp.exr";
  writeImage(tmp, image);
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) throw Error(path + ": cannot rename the temporary file (" + ec.message() + ")");
}

// Runs a program with arguments, no shell; returns its exit status (127 if it could not start).
int runProgram(const std::vector<std::string>& argv) {
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawnp(&pid, args[0], nullptr, nullptr, args.data(), environ) != 0) return 127;
  int status = 0;
  if (waitpid(pid, &status, 0) < 0) return 127;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

std::string gnuplotQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

// Draws a one-pixel outline of `r` into a copy of `img` (for the reference preview).
Image outlined(Image img, const PixelRect& r, float value) {
  auto put = [&](int x, int y) {
    if (x < 0 || y < 0 || x >= img.width || y >= img.height) return;
    img.at(x, y, 0) = 0.0f;
    img.at(x, y, 1) = value;
    img.at(x, y, 2) = value;
  };
  for (int x = r.x0 - 1; x <= r.x1; ++x) put(x, r.y0 - 1), put(x, r.y1);
  for (int y = r.y0 - 1; y <= r.y1; ++y) put(r.x0 - 1, y), put(r.x1, y);
  return img;
}

struct Reference {
  Image image;                      // the mean of the two halves, or the user's file
  std::optional<Image> halfA, halfB;  // independent halves, for the noise estimate
  std::string source;               // file or cache entry it came from
  int spp = 0;                      // samples per pixel of a rendered reference; 0 if given as a file
  double noise = std::nan(""), noiseCaustic = std::nan("");
};

struct RunResult {
  std::string scene, integrator, dispersion;
  std::vector<BenchRow> rows;
  double noise = std::nan(""), noiseCaustic = std::nan("");
  int referenceSpp = 0;
  bool hasCaustic = false;
};

class Bench {
 public:
  explicit Bench(const Options& opts) : opts_(opts) {
    quiet_ = opts.has("--quiet");
    maxSeconds_ = opts.getDouble("--max-seconds", 20.0);
    if (!(maxSeconds_ > 0.0)) throw Error("option --max-seconds needs a positive number of seconds");
    referenceSpp_ = opts.getInt("--reference-spp", kDefaultReferenceSpp, 2, 1 << 24);
    referenceSpp_ += referenceSpp_ % 2;  // two equal halves
    outDir_ = opts.get("--out", "bench-out");
    cacheDir_ = opts.get("--cache", defaultCacheDir());
    for (const auto& name : splitList(opts.get("--integrators", "naive,mis"))) integrators_.push_back(parseIntegrator(name));
    if (integrators_.empty()) throw Error("option --integrators needs at least one of naive, mis");
    for (const auto& name : splitList(opts.get("--dispersion", "rgb,spectral"))) dispersions_.push_back(parseDispersionMode(name));
    if (dispersions_.empty()) throw Error("option --dispersion needs at least one of rgb, spectral");
    std::string scenesJson = findScenesJson(opts);
    if (!scenesJson.empty()) sceneInfo_ = parseBenchScenes(readFileText(scenesJson), scenesJson);
    else note(quiet_, "warning: bench/scenes.json not found: no caustic regions (use --scenes-json FILE)");
    std::error_code ec;
    fs::create_directories(outDir_, ec);
    if (ec) throw Error(outDir_ + ": cannot create the output folder (" + ec.message() + ")");
  }

  int run() {
    std::vector<std::string> scenes = opts_.positional();
    if (scenes.empty()) scenes = assetSceneNames();
    if (scenes.empty()) throw Error(assetSceneDir() + ": no bundled scenes found");
    if (opts_.has("--reference") && scenes.size() != 1)
      throw Error("--reference gives one image: name exactly one scene (got " + std::to_string(scenes.size()) + ")");
    // Resolve every scene first so that a typo fails before minutes of rendering.
    std::vector<std::string> paths;
    for (const auto& s : scenes) paths.push_back(resolveScenePath(s));

    std::string glInfo;
    auto context = createHeadlessContext(parseBackend(opts_.get("--backend", "auto")), &glInfo);
    backend_ = context->backendName();
    glRenderer_ = rendererOf(glInfo);
    note(quiet_, "OpenGL (" + backend_ + "): " + glInfo);
    ShaderLibrary library = shaderLibraryFrom(opts_);
    auto start = Clock::now();
    for (const auto& path : paths) benchScene(library, path);
    writeSummary(secondsSince(start));
    return 0;
  }

 private:
  void benchScene(const ShaderLibrary& library, const std::string& path) {
    const std::string name = fs::path(path).stem().string();
    LoadedScene ls = loadSceneForCli(path, opts_, !quiet_);
    const Scene& scene = ls.scene;
    const Camera& camera = ls.camera;
    const int cameraIndex = cameraIndexFrom(opts_);
    const RenderSettings settings = renderSettingsFrom(opts_, camera, 256);

    std::optional<PixelRect> caustic;
    auto info = sceneInfo_.find(name);
    int referenceSpp = referenceSpp_;  // --reference-spp, else scenes.json, else the default
    if (!opts_.has("--reference-spp") && info != sceneInfo_.end() && info->second.referenceSpp > 0)
      referenceSpp = info->second.referenceSpp;
    if (info != sceneInfo_.end() && info->second.caustic)
      caustic = cropToPixels(*info->second.caustic, settings.width, settings.height);
    else if (info == sceneInfo_.end() && !sceneInfo_.empty())
      note(quiet_, "warning: " + name + " is not in bench/scenes.json: no caustic region");

    Renderer renderer(library, scene, camera, settings);
    std::vector<DispersionMode> modes;
    if (renderer.gpuScene().features.dispersion) modes = dispersions_;
    else modes = {DispersionMode::Rgb};  // the mode changes nothing without dispersive glass
    if (opts_.has("--reference") && modes.size() != 1)
      throw Error("--reference gives one image but " + name + " is benchmarked in " + std::to_string(modes.size()) +
                  " dispersion modes: pick one with --dispersion");
    note(quiet_, name + ": " + std::to_string(scene.triangles.size()) + " triangles, features: " +
                     renderer.gpuScene().features.describe() + "; " + std::to_string(settings.width) + "x" +
                     std::to_string(settings.height) +
                     (caustic ? ", caustic region " + std::to_string(caustic->width()) + "x" +
                                    std::to_string(caustic->height()) + " px at (" + std::to_string(caustic->x0) +
                                    ", " + std::to_string(caustic->y0) + ")"
                              : ", no caustic region"));

    std::vector<RunResult> results;
    for (DispersionMode mode : modes) {
      Reference ref =
          reference(library, scene, camera, settings, renderer, path, name, cameraIndex, mode, caustic, referenceSpp);
      std::string preview = (fs::path(outDir_) / (name + "-" + dispersionModeName(mode) + "-reference.png")).string();
      writeImage(preview, caustic ? outlined(ref.image, *caustic, 4.0f) : ref.image);
      for (Integrator integrator : integrators_) {  // reference() left the renderer in its own settings
        RenderSettings run = settings;
        run.dispersion = mode;
        run.integrator = integrator;
        renderer.apply(run);
        results.push_back(measure(renderer, name, ref, caustic));
      }
    }
    std::vector<BenchRow> rows;
    for (const auto& r : results) rows.insert(rows.end(), r.rows.begin(), r.rows.end());
    std::string csv = (fs::path(outDir_) / ("bench-" + name + ".csv")).string();
    writeBenchCsv(csv, rows);
    note(quiet_, "wrote " + csv);
    plot(name, settings, results);
    for (auto& r : results) all_.push_back(std::move(r));
  }

  // The reference: --reference FILE, else the cache, else rendered now with mis and another seed.
  Reference reference(const ShaderLibrary& library, const Scene& scene, const Camera& camera,
                      const RenderSettings& settings, Renderer& renderer, const std::string& path,
                      const std::string& name, int cameraIndex, DispersionMode mode,
                      const std::optional<PixelRect>& caustic, int referenceSpp) {
    Reference ref;
    if (opts_.has("--reference")) {
      ref.source = opts_.get("--reference", "");
      ref.image = readImage(ref.source);
      if (ref.image.width != settings.width || ref.image.height != settings.height)
        throw Error(ref.source + ": the reference is " + std::to_string(ref.image.width) + "x" +
                    std::to_string(ref.image.height) + " but the bench renders " + std::to_string(settings.width) +
                    "x" + std::to_string(settings.height) + " (use --size " + std::to_string(ref.image.width) + "x" +
                    std::to_string(ref.image.height) + ")");
      note(quiet_, "reference " + ref.source + " (given; its own noise is unknown)");
      return ref;
    }
    RenderSettings rs = settings;
    rs.seed = kReferenceSeed;  // independent of the measured runs, whatever their --seed
    rs.integrator = Integrator::Mis;
    rs.dispersion = mode;
    // The reference is one estimate of the image whatever the measured runs use: always mis with the
    // default caster probability, so --caster-probability runs (ablations) share the cached reference.
    rs.casterProbability = RenderSettings{}.casterProbability;
    renderer.apply(rs);  // for its shader variant, which is part of the cache key
    std::ostringstream key;
    key << kCacheVersion << '\n' << hex64(hashSceneFiles(path)) << '\n' << rs.width << 'x' << rs.height << '\n'
        << referenceSpp << " spp\nseed " << rs.seed << "\ndepth " << rs.maxDepth << '\n'
        << dispersionModeName(mode) << "\nmis\ncasters " << rs.casterProbability << "\ncamera " << cameraIndex << ' ' << camera.position.x << ' '
        << camera.position.y << ' ' << camera.position.z << ' ' << camera.forward.x << ' ' << camera.forward.y << ' '
        << camera.forward.z << ' ' << camera.up.x << ' ' << camera.up.y << ' ' << camera.up.z << ' ' << camera.yfov
        << '\n'
        << hex64(fnv1a64(library.expand("pathtrace.comp", renderer.shaderDefines()).source)) << '\n';
    std::string stem = name + "-" + dispersionModeName(mode) + "-" + hex64(fnv1a64(key.str()));
    fs::path a = fs::path(cacheDir_) / (stem + "-a.exr"), b = fs::path(cacheDir_) / (stem + "-b.exr");
    std::error_code ec;
    if (!opts_.has("--refresh-reference") && fs::is_regular_file(a, ec) && fs::is_regular_file(b, ec)) {
      ref.halfA = readImage(a.string());
      ref.halfB = readImage(b.string());
      ref.source = "cached " + (fs::path(cacheDir_) / stem).string() + "-{a,b}.exr";
    } else {
      fs::create_directories(cacheDir_, ec);
      if (ec) throw Error(cacheDir_ + ": cannot create the reference cache folder (" + ec.message() + ")");
      renderReference(library, scene, camera, rs, name, referenceSpp, ref);
      writeImageAtomic(a.string(), *ref.halfA);
      writeImageAtomic(b.string(), *ref.halfB);
      std::ofstream meta(fs::path(cacheDir_) / (stem + ".txt"));
      meta << key.str() << "scene " << path << "\nGL " << glRenderer_ << '\n';
      ref.source = "rendered, cached as " + (fs::path(cacheDir_) / stem).string() + "-{a,b}.exr";
    }
    ref.spp = referenceSpp;
    ref.image = averageImages(*ref.halfA, *ref.halfB);
    ref.noise = referenceNoise(*ref.halfA, *ref.halfB);
    if (caustic) ref.noiseCaustic = referenceNoise(*ref.halfA, *ref.halfB, *caustic);
    note(quiet_, "reference " + std::string(dispersionModeName(mode)) + ", " + std::to_string(referenceSpp) +
                     " spp mis: " + ref.source + "; its own relMSE ~" + sci(ref.noise) +
                     (caustic ? ", caustic region ~" + sci(ref.noiseCaustic) : std::string()));
    return ref;
  }

  void renderReference(const ShaderLibrary& library, const Scene& scene, const Camera& camera,
                       const RenderSettings& rs, const std::string& name, int referenceSpp, Reference& ref) {
    Renderer r(library, scene, camera, rs);
    const int half = referenceSpp / 2;
    const std::string label = "reference " + name + " " + dispersionModeName(rs.dispersion) + ":";
    // The first half, then the second: the sample indices differ, so the halves are independent.
    renderWithProgress(r, half, label, quiet_);
    ref.halfA = r.image();
    renderWithProgress(r, referenceSpp, label, quiet_);
    // mean = (A + B) / 2, so B = 2 mean - A.
    Image mean = r.image();
    Image b = mean;
    for (size_t i = 0; i < b.rgb.size(); ++i) b.rgb[i] = 2.0f * mean.rgb[i] - ref.halfA->rgb[i];
    ref.halfB = std::move(b);
  }

  // One progressive run: renders in batches sized to land just past each checkpoint; the clock
  // counts rendering only (the read-back and error at each checkpoint are excluded).
  RunResult measure(Renderer& renderer, const std::string& name, const Reference& ref,
                    const std::optional<PixelRect>& caustic) {
    const RenderSettings& s = renderer.settings();
    RunResult out;
    out.scene = name;
    out.integrator = integratorName(s.integrator);
    // A non-default caster probability is part of the estimator's name (CSV, plot, summary).
    if (s.integrator == Integrator::Mis && !renderer.gpuScene().casters.empty() &&
        s.casterProbability != RenderSettings{}.casterProbability)
      out.integrator += fmt(" casters=%g", s.casterProbability);
    out.dispersion = dispersionModeName(s.dispersion);
    out.noise = ref.noise;
    out.noiseCaustic = ref.noiseCaustic;
    out.referenceSpp = ref.spp;
    out.hasCaustic = caustic.has_value();
    renderer.renderPass(1);  // compiles this shader variant outside the clock
    renderer.reset();
    const std::vector<double> schedule = checkpointSchedule(kFirstCheckpoint, maxSeconds_, kCheckpointsPerOctave);
    const double pixels = double(s.width) * s.height;
    double elapsed = 0.0;
    size_t next = 0;
    while (next < schedule.size()) {
      int n = 1;
      if (renderer.samplesPerPixel() > 0) {
        double sppPerSecond = renderer.samplesPerPixel() / elapsed;
        double wanted = std::ceil((schedule[next] - elapsed) * sppPerSecond);
        double cap = std::max(1.0, std::floor(sppPerSecond * kMaxDispatchSeconds));
        n = static_cast<int>(std::clamp(wanted, 1.0, cap));
      }
      auto t0 = Clock::now();
      renderer.renderPass(n);
      elapsed += secondsSince(t0);
      if (elapsed < schedule[next]) continue;
      while (next < schedule.size() && schedule[next] <= elapsed) ++next;

      const RenderStats& st = renderer.stats();
      Image img = renderer.image();
      BenchRow row;
      row.scene = name;
      row.integrator = out.integrator;
      row.dispersion = out.dispersion;
      row.glRenderer = glRenderer_;
      row.width = s.width;
      row.height = s.height;
      row.checkpoint = static_cast<int>(out.rows.size());
      row.seconds = elapsed;
      row.spp = renderer.samplesPerPixel();
      row.samplesPerSecond = row.spp * pixels / elapsed;
      row.raysPerSecond = double(st.rays()) / elapsed;
      row.primaryRays = st.primaryRays;
      row.secondaryRays = st.secondaryRays;
      row.shadowRays = st.shadowRays;
      row.nonFinite = st.nonFinite;
      row.relMse = relMse(img, ref.image);
      row.relMseCaustic = caustic ? relMse(img, ref.image, *caustic) : std::nan("");
      row.referenceNoise = ref.noise;
      row.referenceNoiseCaustic = ref.noiseCaustic;
      out.rows.push_back(row);
      if (!quiet_) {
        std::fprintf(stderr, "\rcaustica: %s %s/%s: %6.2f s %6d spp  relMSE %.3g%s   ", name.c_str(),
                     out.integrator.c_str(), out.dispersion.c_str(), elapsed, row.spp, row.relMse,
                     caustic ? (", caustic " + sci(row.relMseCaustic)).c_str() : "");
        std::fflush(stderr);
      }
    }
    if (!quiet_) std::fprintf(stderr, "\n");
    if (out.rows.back().nonFinite > 0)
      note(quiet_, "warning: " + name + " " + out.integrator + ": " + std::to_string(out.rows.back().nonFinite) +
                       " non-finite samples were rejected");
    return out;
  }

  // A gnuplot script with the data inline, run to make the PNG; the script stays next to it.
  void plot(const std::string& name, const RenderSettings& settings, const std::vector<RunResult>& results) {
    fs::path gp = fs::path(outDir_) / ("bench-" + name + ".gp");
    fs::path png = fs::path(outDir_) / ("bench-" + name + ".png");
    std::ofstream f(gp);
    if (!f) throw Error(gp.string() + ": cannot open for writing");
    f << "# " << gp.filename().string() << " - written by caustica bench; run: gnuplot " << gp.filename().string()
      << "\n";
    f << "set terminal pngcairo size 900,600 font 'sans,10'\n";
    f << "set output " << gnuplotQuote(png.filename().string()) << "\n";
    f << "set title " << gnuplotQuote(name + ", " + std::to_string(settings.width) + "x" + std::to_string(settings.height) +
                                       ", " + glRenderer_ + " (" + backend_ + ")")
      << " noenhanced\n";
    f << "set logscale xy\nset format y '10^{%L}'\nset grid xtics ytics mxtics mytics lc rgb '#dddddd'\n";
    double tMin = 1e30, tMax = 0.0;
    for (const auto& r : results)
      for (const auto& row : r.rows) tMin = std::min(tMin, row.seconds), tMax = std::max(tMax, row.seconds);
    if (tMax > 0.0) f << "set xrange [" << fmt("%.6g", tMin / 1.25) << ":" << fmt("%.6g", tMax * 1.25) << "]\n";
    f << "set xlabel 'render time (s)'\nset ylabel 'relMSE'\nset key inside right top noenhanced opaque box\n";
    for (size_t i = 0; i < results.size(); ++i) {
      f << "$run" << i << " << EOD\n# seconds spp relmse relmse_caustic\n";
      for (const auto& r : results[i].rows)
        f << fmt("%.6g", r.seconds) << ' ' << r.spp << ' ' << fmt("%.6g", r.relMse) << ' '
          << (std::isfinite(r.relMseCaustic) ? fmt("%.6g", r.relMseCaustic) : "NaN") << "\n";
      f << "EOD\n";
    }
    const char* colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b"};
    std::vector<std::string> terms;
    for (size_t i = 0; i < results.size(); ++i) {
      const RunResult& r = results[i];
      std::string color = colors[i % 6];
      bool multiMode = std::any_of(results.begin(), results.end(),
                                   [&](const RunResult& o) { return o.dispersion != results[0].dispersion; });
      std::string label = r.integrator + (multiMode ? " " + r.dispersion : "");
      terms.push_back("$run" + std::to_string(i) + " using 1:3 with linespoints lw 2 pt 7 ps 0.6 lc rgb '" + color +
                      "' dt 1 title " + gnuplotQuote(label));
      if (r.hasCaustic)
        terms.push_back("$run" + std::to_string(i) + " using 1:4 with linespoints lw 2 pt 6 ps 0.6 lc rgb '" + color +
                        "' dt 2 title " + gnuplotQuote(label + ", caustic region"));
    }
    // The reference's own error: measured curves cannot drop far below it.
    std::vector<std::string> seen;
    for (const auto& r : results) {
      if (std::find(seen.begin(), seen.end(), r.dispersion) != seen.end() || !std::isfinite(r.noise)) continue;
      seen.push_back(r.dispersion);
      std::string suffix = results.back().dispersion != results.front().dispersion ? " " + r.dispersion : "";
      terms.push_back(fmt("%.6g", r.noise) + " with lines lc rgb '#888888' dt 3 title " +
                      gnuplotQuote("reference noise" + suffix));
      if (r.hasCaustic && std::isfinite(r.noiseCaustic))
        terms.push_back(fmt("%.6g", r.noiseCaustic) + " with lines lc rgb '#888888' dt 4 title " +
                        gnuplotQuote("reference noise" + suffix + ", caustic"));
    }
    f << "plot ";
    for (size_t i = 0; i < terms.size(); ++i) f << (i ? ", \\\n     " : "") << terms[i];
    f << "\n";
    f.close();
    // gnuplot runs in the output folder so the script's relative output name works when rerun by hand.
    std::string gnuplot = opts_.get("--gnuplot", "gnuplot");
    fs::path absGp = fs::absolute(gp);
    fs::path cwd = fs::current_path();
    std::error_code ec;
    fs::current_path(fs::absolute(outDir_), ec);
    int rc = ec ? 127 : runProgram({gnuplot, absGp.filename().string()});
    fs::current_path(cwd, ec);
    if (rc == 0) note(quiet_, "wrote " + png.string());
    else
      note(quiet_, "warning: '" + gnuplot + "' failed or is missing (exit " + std::to_string(rc) + "): no " +
                       png.string() + "; install gnuplot-nox and run 'gnuplot " + gp.filename().string() + "' in " +
                       outDir_);
  }

  void writeSummary(double totalSeconds) {
    std::ostringstream md;
    md << "GL renderer: " << glRenderer_ << " (" << backend_ << "); time limit " << fmt("%g", maxSeconds_)
       << " s per run; references: mis, another seed; total " << fmt("%.0f", totalSeconds) << " s\n\n";
    md << "| scene | estimator | size | spp | samples/s | rays/s | relMSE | t(0.01) | t(0.001) | efficiency | "
          "caustic relMSE | caustic t(0.01) | caustic t(0.001) | caustic eff. | ref. spp | ref. noise (caustic) |\n";
    md << "|---|---|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n";
    auto col = [](const RunResult& r, bool causticRegion) {
      std::vector<double> t, e;
      for (const auto& row : r.rows) {
        t.push_back(row.seconds);
        e.push_back(causticRegion ? row.relMseCaustic : row.relMse);
      }
      return std::make_pair(t, e);
    };
    for (const auto& r : all_) {
      const BenchRow& last = r.rows.back();
      auto [t, e] = col(r, false);
      md << "| " << r.scene << " | " << r.integrator << (r.dispersion == "rgb" ? "" : " " + r.dispersion) << " | "
         << last.width << "x" << last.height << " | " << last.spp << " | " << sci(last.samplesPerSecond) << " | "
         << sci(last.raysPerSecond) << " | " << sci(last.relMse) << " | "
         << formatThresholdTime(timeToThreshold(t, e, 0.01)) << " | "
         << formatThresholdTime(timeToThreshold(t, e, 0.001)) << " | " << sci(efficiency(last.relMse, last.seconds))
         << " | ";
      if (r.hasCaustic) {
        auto [tc, ec] = col(r, true);
        md << sci(last.relMseCaustic) << " | " << formatThresholdTime(timeToThreshold(tc, ec, 0.01)) << " | "
           << formatThresholdTime(timeToThreshold(tc, ec, 0.001)) << " | "
           << sci(efficiency(last.relMseCaustic, last.seconds)) << " | ";
      } else {
        md << "- | - | - | - | ";
      }
      md << (r.referenceSpp > 0 ? std::to_string(r.referenceSpp) : "file") << " | " << sci(r.noise) << (r.hasCaustic ? " (" + sci(r.noiseCaustic) + ")" : "") << " |\n";
    }
    // mis against naive at the same scene and dispersion mode: the ratio of efficiencies.
    std::ostringstream cmp;
    for (const auto& m : all_) {
      if (m.integrator.rfind("mis", 0) != 0) continue;
      for (const auto& n : all_) {
        if (n.integrator != "naive" || n.scene != m.scene || n.dispersion != m.dispersion) continue;
        const BenchRow &a = m.rows.back(), &b = n.rows.back();
        double whole = efficiency(a.relMse, a.seconds) / efficiency(b.relMse, b.seconds);
        cmp << "- " << m.scene << (m.dispersion == "rgb" ? "" : " (" + m.dispersion + ")") << ": " << m.integrator
            << "/naive efficiency "
            << fmt("%.2fx", whole) << " whole image";
        if (m.hasCaustic)
          cmp << ", " << fmt("%.2fx", efficiency(a.relMseCaustic, a.seconds) / efficiency(b.relMseCaustic, b.seconds))
              << " caustic region";
        cmp << "\n";
      }
    }
    if (!cmp.str().empty()) md << "\n" << cmp.str();
    md << "\nt(x): render time to reach relMSE x, interpolated on log-log axes; '~' extrapolated as 1/time past the "
          "last checkpoint, '<=' already reached at the first. efficiency = 1 / (relMSE x seconds) at the last "
          "checkpoint.\n";
    std::cout << md.str();
    std::string path = (fs::path(outDir_) / "summary.md").string();
    std::ofstream f(path);
    f << md.str();
    if (!f) throw Error(path + ": cannot write");
    note(quiet_, "wrote " + path);
  }

  const Options& opts_;
  bool quiet_ = false;
  double maxSeconds_ = 20.0;
  int referenceSpp_ = 1024;
  std::string outDir_, cacheDir_, glRenderer_, backend_;
  std::vector<Integrator> integrators_;
  std::vector<DispersionMode> dispersions_;
  std::map<std::string, BenchSceneInfo> sceneInfo_;
  std::vector<RunResult> all_;
};

}  // namespace

int cmdBench(const std::vector<std::string>& args) {
  std::vector<OptionSpec> specs = {
      {"--size", "", "W[xH]", "image size in pixels (default 256; H follows the camera's aspect)"},
      {"--max-seconds", "", "S", "render time per estimator run in seconds (default 20)"},
      {"--integrators", "", "LIST", "estimators to compare, comma-separated (default naive,mis)"},
      {"--dispersion", "", "LIST", "dispersion modes for scenes with dispersive glass (default rgb,spectral)"},
      {"--reference", "", "FILE", "linear .exr/.pfm reference (one scene, one mode) instead of rendering one"},
      {"--reference-spp", "", "N", "samples per pixel of rendered references (default: bench/scenes.json, else 1024)"},
      {"--refresh-reference", "", "", "render the reference again even if the cache has it"},
      {"--cache", "", "DIR", "reference cache folder (default ~/.cache/caustica/references)"},
      {"--out", "", "DIR", "output folder for CSVs, plots and summary.md (default bench-out)"},
      {"--scenes-json", "", "FILE", "caustic regions per scene (default: the bundled bench/scenes.json)"},
      {"--gnuplot", "", "PROG", "gnuplot program that draws the plots (default gnuplot)"},
      {"--seed", "", "S", "random seed of the measured runs (default 1); the reference uses another"},
      sceneOptionSpec("--max-depth"),
      sceneOptionSpec("--caster-probability"),
      sceneOptionSpec("--camera"),
      sceneOptionSpec("--backend"),
      sceneOptionSpec("--shader-dir"),
      {"--quiet", "-q", "", "print nothing but errors and the summary table"},
  };
  Options opts("caustica bench [SCENE...] [options]",
               "Measures run time against error: for each SCENE (default: every bundled scene), each estimator\n"
               "and each dispersion mode the scene uses, renders progressively and records relMSE against a\n"
               "reference (whole image and the scene's caustic region) at log-spaced times. Writes\n"
               "OUT/bench-SCENE.csv, OUT/bench-SCENE.png (log-log plot by gnuplot) and OUT/summary.md.",
               specs);
  if (!opts.parse(args)) return 0;
  Bench bench(opts);
  return bench.run();
}

}  // namespace caustica::cli
