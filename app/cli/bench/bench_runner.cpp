// bench_runner.cpp — the bench per scene: its settings and caustic region, a reference per dispersion
// mode, and one progressive run per estimator whose error is measured at log-spaced checkpoints.
#include "cli/bench/bench_runner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#include "cli/bench/bench_metrics.h"
#include "cli/bench/denoise_ladder.h"
#include "cli/bench/reference_cache.h"
#include "cli/bench/report.h"
#include "gpu/adaptive_sampler.h"
#include "platform/context.h"
#include "scene/assets.h"
#include "util/error.h"

namespace caustica::cli {

namespace {

namespace fs = std::filesystem;

constexpr double kFirstCheckpoint = 0.25;  // seconds
constexpr int kCheckpointsPerOctave = 2;
constexpr int kDefaultReferenceSpp = 1024;
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

// Where bench/scenes.json is: --scenes-json, else next to the bundled scenes, else the source tree.
std::string findScenesJson(const Options& opts) {
  if (opts.has("--scenes-json")) return opts.get("--scenes-json", "");
  std::vector<fs::path> candidates = {fs::path(assetSceneDir()) / ".." / ".." / "bench" / "scenes.json",
                                      fs::path(assetSceneDir()) / ".." / "bench" / "scenes.json",
                                      fs::path(sourceDir()) / "bench" / "scenes.json"};
  for (const auto& c : candidates) {
    std::error_code ec;
    if (fs::is_regular_file(c, ec)) return fs::weakly_canonical(c, ec).string();
  }
  return "";
}

class BenchRunner {
 public:
  explicit BenchRunner(const Options& opts) : opts_(opts) {
    quiet_ = opts.has("--quiet");
    setup_.maxSeconds = opts.getDouble("--max-seconds", 20.0);
    if (!(setup_.maxSeconds > 0.0)) throw Error("option --max-seconds needs a positive number of seconds");
    referenceSpp_ = opts.getInt("--reference-spp", kDefaultReferenceSpp, 2, 1 << 24);
    referenceSpp_ += referenceSpp_ % 2;  // two equal halves
    outDir_ = opts.get("--out", "bench-out");
    cacheDir_ = opts.get("--cache", defaultReferenceCacheDir());
    for (const auto& name : splitList(opts.get("--integrators", "naive,mis")))
      integrators_.push_back(parseEstimator(name));
    if (integrators_.empty()) throw Error("option --integrators needs at least one of naive, mis, mis-off, manifold, mis-unguided, mis-eye");
    // --adaptive: the integrators that also get an adaptive run (default mis; "none" for none).
    for (const auto& name : splitList(opts.get("--adaptive", "mis")))
      if (name != "none") adaptiveIntegrators_.push_back(parseEstimator(name));
    for (const auto& name : splitList(opts.get("--dispersion", "rgb,spectral")))
      dispersions_.push_back(parseDispersionMode(name));
    if (dispersions_.empty()) throw Error("option --dispersion needs at least one of rgb, spectral");
    std::string scenesJson = findScenesJson(opts);
    if (!scenesJson.empty()) sceneInfo_ = readBenchScenes(scenesJson);
    else note(quiet_, "warning: bench/scenes.json not found: no caustic regions (use --scenes-json FILE)");
    denoise_ = opts.has("--denoise");
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
    setup_.backend = context->backendName();
    setup_.glRenderer = glRendererName(glInfo);
    note(quiet_, "OpenGL (" + setup_.backend + "): " + glInfo);
    ShaderLibrary library = shaderLibraryFrom(opts_);
    ReferenceCache cache(cacheDir_, opts_.has("--refresh-reference"), setup_.glRenderer, quiet_);
    auto start = Clock::now();
    for (const auto& path : paths) benchScene(library, cache, path);
    if (opts_.has("--adaptive-bound")) return 0;
    std::string summary = summaryMarkdown(setup_, secondsSince(start), all_);
    if (denoise_) {
      summary += denoiseSummaryMarkdown(ladders_);
      const std::string csv = outDir_ + "/denoise.csv";
      std::ofstream f(csv, std::ios::binary);
      f << denoiseLadderCsv(ladders_);
      if (!f) throw Error(csv + ": cannot write");
      note(quiet_, "wrote " + csv);
    }
    writeSummary(outDir_, summary, quiet_);
    return 0;
  }

 private:
  void benchScene(const ShaderLibrary& library, const ReferenceCache& cache, const std::string& path) {
    const std::string name = fs::path(path).stem().string();
    LoadedScene ls = loadSceneForCli(path, opts_, !quiet_, 256);
    ReferenceRequest request;
    request.cameraIndex = ls.settings.camera;
    const RenderSettings settings = ls.settings.render;
    request.scenePath = path;
    request.sceneName = name;
    request.measured = settings;
    auto info = sceneInfo_.find(name);
    request.spp = referenceSpp_;  // --reference-spp, else scenes.json, else the default
    if (!opts_.has("--reference-spp") && info != sceneInfo_.end() && info->second.referenceSpp > 0)
      request.spp = info->second.referenceSpp;
    if (info != sceneInfo_.end() && info->second.caustic)
      request.caustic = cropToPixels(*info->second.caustic, settings.width, settings.height);
    else if (info == sceneInfo_.end() && !sceneInfo_.empty())
      note(quiet_, "warning: " + name + " is not in bench/scenes.json: no caustic region");
    const std::optional<PixelRect>& caustic = request.caustic;

    Renderer renderer(library, ls.scene, ls.camera, settings);
    std::vector<DispersionMode> modes;
    if (renderer.sceneFeatures().has("CAUSTICA_DISPERSION")) modes = dispersions_;
    else modes = {DispersionMode::Rgb};  // the mode changes nothing without dispersive glass
    if (opts_.has("--reference") && modes.size() != 1)
      throw Error("--reference gives one image but " + name + " is benchmarked in " + std::to_string(modes.size()) +
                  " dispersion modes: pick one with --dispersion");
    note(quiet_, name + ": " + std::to_string(ls.scene.triangles.size()) + " triangles, features: " +
                     renderer.sceneFeatures().describe() + "; " + std::to_string(settings.width) + "x" +
                     std::to_string(settings.height) +
                     (caustic ? ", caustic region " + std::to_string(caustic->width()) + "x" +
                                    std::to_string(caustic->height()) + " px at (" + std::to_string(caustic->x0) +
                                    ", " + std::to_string(caustic->y0) + ")"
                              : ", no caustic region"));

    std::vector<RunResult> results;
    for (DispersionMode mode : modes) {
      request.mode = mode;
      Reference ref = opts_.has("--reference")
                          ? givenReference(opts_.get("--reference", ""), settings.width, settings.height, quiet_)
                          : cache.get(library, ls, request, renderer);
      writeReferencePreview(outDir_, name, dispersionModeName(mode), ref.image, caustic);
      if (opts_.has("--adaptive-bound")) {
        RenderSettings run = settings;
        run.dispersion = mode;
        run.integrator = Integrator::Mis;
        printAdaptiveBound(renderer, run, name, mode, ref);
        continue;
      }
      for (const Estimator& integrator : integrators_) {  // the cache left the renderer in the reference's settings
        RenderSettings run = settings;
        run.dispersion = mode;
        run.integrator = integrator.integrator;
        run.manifold = integrator.manifold;
        if (integrator.unguided) run.guideProbability = 0.0f;
        if (integrator.eyeOnly) run.lightTracing = false;
        renderer.apply(run);
        results.push_back(measure(renderer, name, ref, caustic, false));
        if (std::find(adaptiveIntegrators_.begin(), adaptiveIntegrators_.end(), integrator) !=
            adaptiveIntegrators_.end())
          results.push_back(measure(renderer, name, ref, caustic, true));
      }
      if (denoise_) {  // mis with the denoiser: over time (its filter on the clock), then at fixed spp
        RenderSettings run = settings;
        run.dispersion = mode;
        run.integrator = Integrator::Mis;
        renderer.apply(run);
        results.push_back(measure(renderer, name, ref, caustic, false, true));
        Renderer plain(library, ls.scene, ls.camera, run);
        DenoiseLadder ladder = runDenoiseLadder(renderer, plain, name, ref, caustic, quiet_);
        const std::string stem = name + (modes.size() > 1 ? "-" + std::string(dispersionModeName(mode)) : "");
        writePlot(outDir_, "denoise-" + stem, denoiseLadderPlot(setup_, ladder, stem), opts_.get("--gnuplot", "gnuplot"), quiet_);
        const Canvas figure = composeDenoiseFigure(ladder, ls.settings.tone);
        writePng(outDir_ + "/bench-denoise-" + stem + "-pictures.png", figure.width, figure.height, figure.rgb);
        ladder.pictures.clear();  // the summary needs the figures only
        ladder.reference = Image{};
        ladders_.push_back(std::move(ladder));
      }
    }
    if (opts_.has("--adaptive-bound")) return;
    std::string csv = writeSceneCsv(outDir_, name, results);
    note(quiet_, "wrote " + csv);
    writePlot(outDir_, name, gnuplotScript(setup_, name, settings.width, settings.height, results),
              opts_.get("--gnuplot", "gnuplot"), quiet_);
    for (auto& r : results) all_.push_back(std::move(r));
  }

  // --adaptive-bound: one markdown table row per scene and mode on stdout (header before the first).
  // Renders the measured settings uniformly to the reference's spp / 2 (--bound-spp) and takes each
  // tile's per-sample variance from its even/odd halves, weighted by the reference (tileRelVariance).
  // "uniform spp to 0.01" is mean(v) / 0.01, at which the guarded bounds are taken.
  void printAdaptiveBound(Renderer& renderer, const RenderSettings& run, const std::string& name,
                          DispersionMode mode, const Reference& ref) {
    if (!boundHeader_)
      std::printf("| scene | size | spp | uniform spp to 0.01 | bound 8x8 | bound 4x4 | 4x4, guards 16 spp & 8x | "
                  "4x4, 16 spp & 32x | bound 2x2 | sampler's allocation at spp |\n"
                  "|---|---|--:|--:|--:|--:|--:|--:|--:|--:|\n");
    boundHeader_ = true;
    renderer.apply(run);
    renderer.reset();
    const int spp = opts_.getInt("--bound-spp", std::max(2, ref.spp / 2), 2, 1 << 24);
    for (int done = 0; done < spp;) {
      const int n = std::min(spp - done, std::max(1, renderer.samplesPerDispatch()));
      renderer.renderPass(n);
      done += n;
    }
    const AccumulationState st = renderer.saveAccumulation();
    auto tiles = [&](int tile) { return tileRelVariance(st.accum, st.comp, st.half, ref.image, tile); };
    const std::vector<double> v4 = tiles(4);
    {  // per pixel (row-major): the per-sample relative variance, reference-weighted, from the halves, for
       // analyses across renders (bench/experiments/adaptive-ceiling; docs/adaptive-sampling.md, "How much it can gain")
      std::ofstream f(outDir_ + "/" + name + "-" + dispersionModeName(mode) + "-pixel-variance.txt");
      f << "# " << ref.image.width << "x" << ref.image.height << " pixels, row-major: per-sample relative variance "
        << "from the halves (uniform render, seed " << run.seed << ", " << spp << " spp)\n";
      const std::vector<double> v1 = tiles(1);
      for (double x : v1) f << formatDouble("%.6g", x) << '\n';
    }
    double meanV = 0.0;
    for (double x : v4) meanV += x / static_cast<double>(v4.size());
    const double spp01 = meanV / 0.01;
    // The allocation adaptive sampling itself makes (AdaptiveSampler, this tile size and guards, another
    // seed: independent of the variances), run to a mean of min(spp01, spp) samples per pixel; its
    // expected relMSE mean(v / n) against uniform sampling's mean(v) / mean(n). Free of a single run's
    // luck, which favours adaptive sampling where noise is heavy-tailed (docs/adaptive-sampling.md, "How much
    // it can gain").
    AdaptiveSampler sampler(0.0, true);
    const std::vector<double> vt = sampler.tileSize() == 4 ? v4 : tiles(sampler.tileSize());  // v4 at the default
    RenderSettings other = run;
    other.seed = run.seed + 1;
    renderer.apply(other);
    renderer.reset();
    const double pixels = double(ref.image.width) * ref.image.height, goal = std::min(spp01, double(spp));
    for (int nextCheck = sampler.checkAtOrAfter(0); double(renderer.stats().primaryRays) < goal * pixels;) {
      renderer.renderPass(std::max(1, std::min(renderer.samplesPerDispatch(), nextCheck - renderer.samplesPerPixel())));
      if (renderer.samplesPerPixel() >= nextCheck) {
        sampler.check(renderer);
        if (sampler.done()) break;  // no live tile left (an image without noise)
        nextCheck = sampler.checkAtOrAfter(renderer.samplesPerPixel() + 1);
      }
    }
    const ErrorEstimate e = renderer.errorEstimate(sampler.tileSize());
    renderer.useAllTiles();
    {  // per tile (row-major): the per-sample variance and the sampler's samples, for other analyses
      std::ofstream f(outDir_ + "/" + name + "-" + dispersionModeName(mode) + "-tile-variance.txt");
      f << "# per tile of " << sampler.tileSize() << "x" << sampler.tileSize() << " pixels, row-major, " << e.tilesX
        << " a row: per-sample relative variance (uniform render), the adaptive render's samples per pixel and its\n"
        << "# own estimate of the per-sample variance (relMSE estimate x samples)\n";
      for (size_t t = 0; t < vt.size(); ++t)
        f << formatDouble("%.6g", vt[t]) << ' ' << e.tileSppMin[t] << ' ' << formatDouble("%.6g", e.tile[t] * e.tileSppMin[t])
          << '\n';
    }
    double expected = 0.0, meanVt = 0.0;
    for (size_t t = 0; t < vt.size(); ++t) {
      expected += vt[t] / std::max(e.tileSppMin[t], 1) / double(vt.size());
      meanVt += vt[t] / double(vt.size());
    }
    std::printf("| %s%s | %dx%d | %d | %.0f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f at %.0f |\n", name.c_str(),
                mode == DispersionMode::Rgb ? "" : " (spectral)", ref.image.width, ref.image.height, spp, spp01,
                adaptiveGainBound(tiles(8)), adaptiveGainBound(v4),
                guardedAdaptiveGainBound(v4, spp01, kMinAdaptiveSpp, kMaxSppRatio),
                guardedAdaptiveGainBound(v4, spp01, kMinAdaptiveSpp, 32), adaptiveGainBound(tiles(2)),
                meanVt / e.sppMean / expected, e.sppMean);
    std::fflush(stdout);
  }

  // One progressive run: renders in batches sized to land just past each checkpoint; the clock
  // counts rendering only (the read-back and error at each checkpoint are excluded). An `adaptive`
  // run samples the live tiles of AdaptiveSampler (docs/adaptive-sampling.md), checked at its fixed
  // schedule; those checks (read-back, estimate, tile list) are part of adaptive sampling's cost and
  // are on the clock. Its target is 0: it never stops early, so its error curve spans the same time.
  // A `denoised` run keeps the feature buffers and measures the denoised image at each checkpoint, the
  // denoiser's time on its clock (each checkpoint's image costs the render so far and one filter).
  RunResult measure(Renderer& renderer, const std::string& name, const Reference& ref,
                    const std::optional<PixelRect>& caustic, bool adaptive, bool denoised = false) {
    const RenderSettings& s = renderer.settings();
    renderer.setFeatureBuffers(denoised);
    RunResult out;
    out.scene = name;
    out.integrator = estimatorName(s, !renderer.gpuScene().casters.empty()) + (adaptive ? " adaptive" : "") +
                     (denoised ? " denoised" : "");
    out.dispersion = dispersionModeName(s.dispersion);
    out.noise = ref.noise;
    out.noiseCaustic = ref.noiseCaustic;
    out.referenceSpp = ref.spp;
    out.hasCaustic = caustic.has_value();
    renderer.renderPass(1);  // compiles this shader variant outside the clock
    renderer.reset();
    const std::vector<double> schedule = checkpointSchedule(kFirstCheckpoint, setup_.maxSeconds, kCheckpointsPerOctave);
    const double pixels = double(s.width) * s.height;
    double elapsed = 0.0;  // seconds of rendering so far
    double cpu = 0.0;      // process CPU seconds over the same spans
    size_t next = 0;       // the next checkpoint in `schedule`
    std::optional<AdaptiveSampler> sampler;
    if (adaptive) sampler.emplace(0.0, true);
    int nextCheck = sampler ? sampler->checkAtOrAfter(0) : 0;
    while (next < schedule.size()) {
      int n = nextBatchSpp(renderer.samplesPerPixel(), elapsed, schedule[next], kMaxDispatchSeconds);
      // Under adaptive sampling a pass covers fewer pixels: the rate so far (spp per second) is
      // then an underestimate of the next pass's, which only makes batches shorter.
      if (sampler) n = std::max(1, std::min(n, nextCheck - renderer.samplesPerPixel()));
      auto t0 = Clock::now();
      const std::clock_t c0 = std::clock();
      renderer.renderPass(n);
      if (sampler && renderer.samplesPerPixel() >= nextCheck) {
        sampler->check(renderer);
        nextCheck = sampler->checkAtOrAfter(renderer.samplesPerPixel() + 1);
      }
      elapsed += secondsSince(t0);
      cpu += double(std::clock() - c0) / CLOCKS_PER_SEC;
      if (elapsed < schedule[next]) continue;
      while (next < schedule.size() && schedule[next] <= elapsed) ++next;

      const RenderStats& st = renderer.stats();
      double filterSeconds = 0.0;
      if (denoised) {
        const auto f0 = Clock::now();
        renderer.denoise();  // waits for the GPU
        filterSeconds = secondsSince(f0);
      }
      Image img = denoised ? renderer.denoisedImage() : renderer.image();  // (the read-back is not timed)
      BenchRow row;
      row.scene = name;
      row.integrator = out.integrator;
      row.dispersion = out.dispersion;
      row.glRenderer = setup_.glRenderer;
      row.width = s.width;
      row.height = s.height;
      row.checkpoint = static_cast<int>(out.rows.size());
      row.seconds = elapsed + filterSeconds;
      row.cpuSeconds = cpu + filterSeconds;
      row.filterSeconds = filterSeconds;
      row.spp = renderer.samplesPerPixel();
      // Adaptive runs sample some pixels only: count the paths traced (GPU counter) instead.
      row.samplesPerSecond = adaptive ? double(st.primaryRays) / elapsed : row.spp * pixels / elapsed;
      row.raysPerSecond = double(st.rays()) / elapsed;
      row.primaryRays = st.primaryRays;
      row.secondaryRays = st.secondaryRays;
      row.shadowRays = st.shadowRays;
      row.nonFinite = st.nonFinite;
      row.relMse = relMse(img, ref.image);
      row.relMseCaustic = caustic ? relMse(img, ref.image, *caustic) : std::nan("");
      row.referenceNoise = ref.noise;
      row.referenceNoiseCaustic = ref.noiseCaustic;
      row.meanRatio = imageMean(img, fullImage(s.width, s.height)) / imageMean(ref.image, fullImage(s.width, s.height));
      row.meanRatioCaustic = caustic ? imageMean(img, *caustic) / imageMean(ref.image, *caustic) : std::nan("");
      out.rows.push_back(row);
      if (!quiet_) {
        std::fprintf(stderr, "\rcaustica: %s %s/%s: %6.2f s %6d spp  relMSE %.3g%s   ", name.c_str(),
                     out.integrator.c_str(), out.dispersion.c_str(), elapsed, row.spp, row.relMse,
                     caustic ? (", caustic " + formatSci(row.relMseCaustic)).c_str() : "");
        std::fflush(stderr);
      }
    }
    if (!quiet_) std::fprintf(stderr, "\n");
    renderer.useAllTiles();
    renderer.setFeatureBuffers(false);
    if (out.rows.back().nonFinite > 0)
      note(quiet_, "warning: " + name + " " + out.integrator + ": " + std::to_string(out.rows.back().nonFinite) +
                       " non-finite samples were rejected");
    return out;
  }

  const Options& opts_;
  bool quiet_ = false;
  BenchSetup setup_;  // GL renderer, backend and --max-seconds
  int referenceSpp_ = kDefaultReferenceSpp;
  std::string outDir_, cacheDir_;
  // An estimator of --integrators: naive, mis (manifold NEE as --manifold says, default auto; caster
  // guiding as --guide-probability says, default on), mis-off (without manifold NEE), manifold (mis with
  // --manifold on), mis-unguided (mis with --guide-probability 0) or mis-eye (mis with --light-tracing off:
  // the eye paths alone).
  struct Estimator {
    Integrator integrator;
    ManifoldMode manifold;
    bool unguided = false;
    bool eyeOnly = false;
    bool operator==(const Estimator& o) const {
      return integrator == o.integrator && manifold == o.manifold && unguided == o.unguided && eyeOnly == o.eyeOnly;
    }
  };
  Estimator parseEstimator(const std::string& name) const {
    const ManifoldMode asAsked = parseManifoldMode(opts_.get("--manifold", manifoldModeName(RenderSettings{}.manifold)));
    if (name == "manifold") return {Integrator::Mis, ManifoldMode::On};
    if (name == "mis-off") return {Integrator::Mis, ManifoldMode::Off};
    if (name == "mis-unguided") return {Integrator::Mis, asAsked, true};
    if (name == "mis-eye") return {Integrator::Mis, asAsked, false, true};
    return {parseIntegrator(name), asAsked};
  }
  std::vector<Estimator> integrators_, adaptiveIntegrators_;
  std::vector<DispersionMode> dispersions_;
  std::map<std::string, BenchSceneInfo> sceneInfo_;
  bool boundHeader_ = false;    // --adaptive-bound: the table's header is printed
  bool denoise_ = false;        // --denoise: denoised runs and the fixed-spp ladder (denoise_ladder.h)
  std::vector<DenoiseLadder> ladders_;
  std::vector<RunResult> all_;  // every run of every scene so far, for the summary
};

}  // namespace

int runBench(const Options& opts) {
  BenchRunner bench(opts);
  return bench.run();
}

}  // namespace caustica::cli
