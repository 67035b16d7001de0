// cmd_render.cpp — `caustica render`: headless progressive render of a scene to an image file.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <optional>

#include "cli/aov_output.h"
#include "cli/bench/reference_cache.h"
#include "cli/budget_render.h"
#include "cli/checkpoint.h"
#include "cli/cli_common.h"
#include "cli/load_report.h"
#include "cli/commands.h"
#include "cli/shard.h"
#include "util/error.h"
#include "util/file_io.h"
#include "util/memory_stats.h"
#include "image/image_io.h"
#include "platform/context.h"
#include "scene/assets.h"

namespace caustica::cli {

namespace {

// --frames A..B: the first and last frame (A <= B, both >= 0).
std::pair<int, int> parseFrames(const std::string& text) {
  const auto bad = [&] { return Error("option --frames needs A..B with 0 <= A <= B (frame numbers), got '" + text + "'"); };
  const size_t dots = text.find("..");
  if (dots == std::string::npos) throw bad();
  const auto number = [&](const std::string& t) {
    char* end = nullptr;
    const long v = std::strtol(t.c_str(), &end, 10);
    if (t.empty() || *end != '\0' || v < 0 || v > (1 << 30)) throw bad();
    return int(v);
  };
  const int a = number(text.substr(0, dots)), b = number(text.substr(dots + 2));
  if (a > b) throw bad();
  return {a, b};
}

// The output of frame `n`: the last run of '#' in `pattern` replaced by n, zero-padded to the run's
// length ("out_####.png", 7 -> "out_0007.png").
std::string frameFileName(const std::string& pattern, int n) {
  const size_t last = pattern.find_last_of('#');
  size_t first = last;
  while (first > 0 && pattern[first - 1] == '#') --first;
  std::string number = std::to_string(n);
  if (number.size() < last - first + 1) number.insert(0, last - first + 1 - number.size(), '0');
  return pattern.substr(0, first) + number + pattern.substr(last + 1);
}

// Writes `renderer`'s sums to `file` as the checkpoint of this render (or shard).
std::function<void()> checkpointWriter(const Renderer& renderer, const std::string& file, std::uint64_t sceneHash,
                                       const std::string& identity, const std::optional<SampleShare>& shard) {
  return [&renderer, file, sceneHash, identity, shard] {
    Checkpoint ck;
    ck.state = renderer.saveAccumulation();
    ck.seed = renderer.settings().seed;
    ck.sceneHash = sceneHash;
    ck.identity = identity;
    ck.shard = shard;
    writeCheckpoint(file, ck);
  };
}

// Writes the render's image to `out`: the denoised image with `denoise`, else the raw mean, with the
// AOVs (aov_output.h).
void writeOutput(Renderer& renderer, const std::string& out, const ToneMapSettings& tone, bool denoise,
                 const std::vector<Aov>& aovs, bool quiet) {
  const Image raw = renderer.image();
  const AccumulationState sums = aovsNeedFeatures(aovs) ? renderer.saveAccumulation() : AccumulationState{};
  if (!denoise) return writeImageWithAovs(out, raw, tone, aovs, raw, sums);
  const Image denoised = renderer.denoisedImage();
  char ms[64];
  std::snprintf(ms, sizeof ms, "denoised in %.1f ms", renderer.denoiseMs());
  note(quiet, ms);
  writeImageWithAovs(out, denoised, tone, aovs, raw, sums);
}

// What render does besides rendering: stop between passes on Ctrl-C / SIGTERM, and call `checkpoint`
// every `checkpointSeconds` (0: never) while it renders.
ProgressHooks renderHooks(double checkpointSeconds, std::function<void()> checkpoint) {
  ProgressHooks hooks;
  hooks.stopOnInterrupt = true;
  hooks.checkpointSeconds = checkpointSeconds;
  hooks.checkpoint = std::move(checkpoint);
  return hooks;
}

// `render --frames A..B`: an animation's frames in one process, one image each. What does not change
// from frame to frame is made once: the parsed file and its decoded images (SceneFile), the GL context
// and the compiled shader variants (Renderer::setScene), and for a rigid animation of an instanced
// scene the meshes' BVHs (only the instances are placed again; docs/animation.md).
int renderFrames(const Options& opts, const std::string& pattern, const RenderBudget& budget, Backend backend,
                 double checkpointSeconds, bool denoise, const std::vector<Aov>& aovs, bool quiet) {
  for (const char* option : {"--shard", "--resume", "--checkpoint-file", "--stats", "--frame"})
    if (opts.has(option))
      throw Error(std::string(option) + " with --frames: render one frame with --frame N for that (a render farm runs a "
                                        "frame per job: docs/render-farm.md)");
  const auto [first, last] = parseFrames(opts.get("--frames", ""));
  if (pattern.find('#') == std::string::npos)
    throw Error(pattern + ": --frames needs the frame number's place in the output name, as #### (e.g. -o out_####.png)");
  checkImageExtension(frameFileName(pattern, first));
  checkWritableFile(frameFileName(pattern, first), "output");
  for (const std::string& f : aovFiles(frameFileName(pattern, first), aovs)) checkWritableFile(f, "--aov");
  const double fps = opts.getDouble("--fps", 24.0);
  ScenePose pose = scenePoseFrom(opts);  // the animation chosen; the time is each frame's
  if (opts.positional().size() > 1) throw Error("expected one scene, got " + std::to_string(opts.positional().size()));
  const std::string path = resolveScenePath(opts.positional().empty() ? kDefaultScene : opts.positional()[0]);
  const auto commandStart = std::chrono::steady_clock::now();
  const SceneFile file(path, loadOptionsFrom(opts));
  const std::uint64_t sceneHash = hashSceneFiles(path);
  std::string glInfo;
  auto context = createHeadlessContext(backend, &glInfo);
  note(quiet, "OpenGL (" + context->backendName() + "): " + glInfo);
  ShaderLibrary library = shaderLibraryFrom(opts);
  std::unique_ptr<Renderer> renderer;
  installInterruptHandlers();
  const auto seconds = [](std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  };
  double sceneTotal = 0.0, uploadTotal = 0.0, renderTotal = 0.0;
  for (int n = first; n <= last; ++n) {
    const auto frameStart = std::chrono::steady_clock::now();
    pose.time = double(n) / fps;
    Scene posed = file.sceneAt(pose);
    if (n == first) {
      for (const auto& w : posed.warnings) note(quiet, "warning: " + w);
      note(quiet, posed.animations.empty() ? "warning: " + path + " has no animations: every frame is the same image"
                                           : path + " has " + animationsSummary(posed));
    }
    LoadedScene ls = prepareLoadedScene(std::move(posed), opts, pose, !quiet && n == first);
    flattenForMode(ls.scene, ls.settings.render.mode, opts, true);  // raster draws flat scenes
    const double sceneSeconds = seconds(frameStart);
    const RenderSettings& settings = ls.settings.render;
    if (!renderer) {
      note(quiet, "settings: " + settingsSummary(ls.settings));
      RendererOptions ro;
      ro.sceneUpdates = true;
      renderer = std::make_unique<Renderer>(library, ls.scene, ls.camera, settings, ro);
      if (denoise || aovsNeedFeatures(aovs)) {
        if (!renderModeSpec(settings.mode).pathTracer)
          throw Error(std::string(denoise ? "--denoise" : "--aov") + " needs the path tracer (--mode path), not --mode " +
                      renderModeName(settings.mode));
        renderer->setFeatureBuffers(true);
      }
    } else {
      if (renderer->settings() != settings) renderer->apply(settings);
      renderer->setScene(ls.scene, ls.camera);
    }
    const double uploadSeconds = renderer->loadTimes().ready;
    const std::string out = frameFileName(pattern, n);
    const std::string checkpointFile = out + ".ckpt";
    const auto saveCheckpoint = checkpointWriter(*renderer, checkpointFile, sceneHash,
                                                 accumulationIdentity(ls.settings, ls.camera, renderer->gpuScene()), std::nullopt);
    const BudgetResult result = renderWithBudget(*renderer, budget, "frame " + std::to_string(n), quiet,
                                                 renderHooks(checkpointSeconds, saveCheckpoint));
    writeOutput(*renderer, out, ls.settings.tone, denoise, aovs, quiet || n != first);
    if (result.reason == StopReason::Interrupted) {
      std::string saved;
      try {
        saveCheckpoint();
        saved = " and checkpoint " + checkpointFile;
      } catch (const Error& e) {
        saved = "; no checkpoint: " + std::string(e.what());
      }
      // Always said, even with --quiet: it explains the exit status.
      std::fprintf(stderr,
                   "caustica: interrupted at frame %d, %d spp; wrote %s (partial)%s (continue it with --frame %d --resume "
                   "%s, then --frames %d..%d)\n",
                   n, renderer->samplesPerPixel(), out.c_str(), saved.c_str(), n, checkpointFile.c_str(), n + 1, last);
      return kExitInterrupted;
    }
    if (checkpointSeconds > 0.0) saveCheckpoint();
    sceneTotal += sceneSeconds;
    uploadTotal += uploadSeconds;
    renderTotal += result.seconds;
    char line[256];
    std::snprintf(line, sizeof line, "frame %d (t = %.4g s): %d spp, scene %.3f s, upload %.3f s, render %.2f s: wrote %s", n,
                  pose.time, renderer->samplesPerPixel(), sceneSeconds, uploadSeconds, result.seconds, out.c_str());
    note(quiet, line);
  }
  char line[256];
  const int frames = last - first + 1;
  std::snprintf(line, sizeof line,
                "%d frame(s) in %.2f s; a frame: scene %.3f s, upload %.3f s, render %.2f s (mean); mesh BVH builds: %d",
                frames, seconds(commandStart), sceneTotal / frames, uploadTotal / frames, renderTotal / frames,
                renderer->meshBvhBuilds());
  note(quiet, line);
  return 0;
}

// The options of `caustica render`, the scene options last.
std::vector<OptionSpec> renderOptionSpecs() {
  std::vector<OptionSpec> specs = {
      {"--output", "-o", "FILE", "output image: .png (tone-mapped sRGB), .exr or .pfm (linear) (default caustica.png)"},
      {"--spp", "", "N", "samples per pixel, a cap (default 64; with --time or --target-error: 65536)"},
      {"--time", "", "SECONDS", "stop after about SECONDS (whichever of --spp, --time, --target-error comes first)"},
      {"--target-error", "", "E",
       "stop once the estimated relMSE of the image is at most E; samples go to the tiles whose error falls fastest (adaptive sampling)"},
      {"--uniform", "", "", "with --target-error: keep sampling every pixel (no adaptive sampling)"},
      {"--stats", "", "FILE.json",
       "write seconds, spp_min, spp_mean, spp_max, estimated_relmse, nonfinite_samples, rays, samples"},
      {"--exposure", "", "STOPS", "PNG exposure in stops (default 0)"},
      {"--tonemap", "", "CURVE", "PNG tone curve: aces (default) or clamp"},
      {"--checkpoint", "", "SECONDS", "rewrite a checkpoint every SECONDS (atomically) and at the end"},
      {"--checkpoint-file", "", "FILE", "where checkpoints go (default OUTPUT.ckpt)"},
      {"--resume", "", "CHECKPOINT",
       "continue the render saved in CHECKPOINT (same scene and settings; --spp is the new total); auto: the "
       "checkpoint this render writes (--checkpoint-file, or a shard's -o) if it exists, else start (for job scripts "
       "that may run again)"},
      {"--shard", "", "K/N",
       "render only the K-th of N disjoint shares of the --spp samples and write them, mergeable, to -o PART.ckpt "
       "('caustica merge' adds the parts into the image one machine would render; docs/render-farm.md)"},
      {"--frames", "", "A..B",
       "render frames A to B of the animation (time N / --fps), one image each, named by -o with #### for the "
       "frame number (out_####.png); reuses what does not change between frames (docs/animation.md)"},
      {"--denoise", "", "",
       "write the denoised image instead of the raw mean (docs/denoising.md); with --shard the partial keeps the "
       "feature sums and caustica merge --denoise denoises the merged render"},
      {"--aov", "", "LIST",
       "also write albedo, normal, depth, variance, raw (or all): layers of an .exr output, else files "
       "OUTPUT-STEM.NAME.pfm (raw: the output's format) beside it; with --shard: caustica merge --aov writes them"},
  };
  for (auto& s : sceneOptionSpecs()) specs.push_back(s);
  return specs;
}

// Refuses an output name or an option the render mode (--frames, --shard or one image) cannot take,
// before any work.
void checkOutputForMode(const Options& opts, const std::string& out, bool sharded) {
  if (opts.has("--frames")) {
    // checked by renderFrames
  } else if (sharded) {
    if (fileExtension(out) != ".ckpt")
      throw Error(out + ": --shard writes a mergeable partial, not an image: name the output PART.ckpt (caustica merge "
                        "makes the image from the parts)");
    // A shard renders a fixed share of the samples, which merge checks; the budgets that stop elsewhere
    // are refused rather than given a meaning no shard can keep (docs/render-farm.md).
    if (opts.has("--time"))
      throw Error("--time with --shard: a shard renders a fixed share of --spp, which --time would leave unfinished "
                  "(a shard stopped by SIGTERM, e.g. at a scheduler's time limit, writes its partial: continue it with --resume)");
    if (opts.has("--target-error") || opts.has("--uniform"))
      throw Error("--target-error with --shard: the error to reach is the merged image's, which no shard sees, and "
                  "adaptive sampling would give each shard's pixels their own sample counts; render the shards with --spp "
                  "(caustica merge prints the merged image's estimated relMSE)");
    if (opts.has("--checkpoint-file"))
      throw Error("--checkpoint-file with --shard: a shard's partial (-o) is its checkpoint");
  } else if (fileExtension(out) == ".ckpt") {
    throw Error(out + ": a .ckpt output is a shard's partial: add --shard K/N (checkpoints of a whole render go to "
                      "--checkpoint-file)");
  } else {
    checkImageExtension(out);
  }
}

// --time, --target-error, --uniform and --spp: when the render stops.
RenderBudget parseBudget(const Options& opts) {
  RenderBudget budget;
  budget.seconds = opts.getDouble("--time", 0.0);
  if (opts.has("--time") && !(budget.seconds > 0.0 && budget.seconds < 1e9))
    throw Error("option --time needs a number of seconds above 0");
  budget.targetError = opts.getDouble("--target-error", 0.0);
  if (opts.has("--target-error") && !(budget.targetError > 0.0 && budget.targetError < 1e30))
    throw Error("option --target-error needs a relMSE above 0 (e.g. 0.01)");
  budget.adaptive = !opts.has("--uniform");
  if (opts.has("--uniform") && !opts.has("--target-error")) throw Error("option --uniform needs --target-error");
  const bool openEnded = opts.has("--time") || opts.has("--target-error");
  int spp = opts.getInt("--spp", openEnded ? 65536 : 64, 1, 1 << 24);
  budget.maxSpp = spp;
  return budget;
}

// Refuses, before any work, an output file that could not be written.
void checkOutputsWritable(const std::string& out, const std::string& checkpointFile, const std::vector<Aov>& aovs,
                          bool sharded) {
  checkWritableFile(out, "output");
  checkWritableFile(checkpointFile, "checkpoint");
  if (!sharded)  // a shard writes its partial only; merge writes the AOVs
    for (const std::string& f : aovFiles(out, aovs)) checkWritableFile(f, "--aov");
}

// The checkpoint --resume names (auto: RESUMEPATH, this render's own, if it exists); none without --resume.
// A bad file fails before any work; with auto, a missing one starts the render (a first run).
std::optional<Checkpoint> readResume(const Options& opts, const std::string& resumePath, bool quiet) {
  std::optional<Checkpoint> resumeFrom;
  const bool resumeAuto = opts.get("--resume", "") == "auto";
  if (opts.has("--resume") && (!resumeAuto || std::filesystem::exists(resumePath))) resumeFrom = readCheckpoint(resumePath);
  else if (resumeAuto) note(quiet, "--resume auto: no " + resumePath + " yet, starting the render");
  return resumeFrom;
}

// Refuses what the loaded scene's settings cannot give: alpha in a PFM, features without the path tracer.
void checkSceneForOutput(const LoadedScene& ls, const std::string& out, bool features, bool denoise) {
  if (ls.scene.background.kind == Background::Kind::Transparent && fileExtension(out) == ".pfm")
    throw Error(out + ": PFM has no alpha channel: write .exr or .png with --background transparent");
  if (features && !renderModeSpec(ls.settings.render.mode).pathTracer)
    throw Error(std::string(denoise ? "--denoise" : "--aov") + " needs the path tracer (--mode path), not --mode " +
                renderModeName(ls.settings.render.mode));
}

// Refuses a checkpoint of another scene, other settings or another shard. Called before the scene is
// packed (gpu null: every setting but --manifold and --guide-probability, whose effect depends on the scene) and again after.
void checkResumable(const Checkpoint& from, const std::string& resumePath, std::uint64_t sceneHash,
                    const std::string& identity, const std::optional<SampleShare>& share, const GpuScene* gpu) {
  std::string diff = checkpointMismatch(from, sceneHash, identity, gpu);
  if (!diff.empty()) throw Error(resumePath + ": cannot resume another render: " + diff);
  if (from.shard && !share)
    throw Error(resumePath + ": it is the partial of " + describeShare(*from.shard) + " of " +
                std::to_string(from.shard->total) + " spp: continue it with --shard " +
                std::to_string(from.shard->index) + "/" + std::to_string(from.shard->count) + " --spp " +
                std::to_string(from.shard->total) + " (or merge the shards with caustica merge)");
  if (share && !from.shard)
    throw Error(resumePath + ": it is the checkpoint of a whole render, not of a shard: --shard cannot continue it");
  if (share && *from.shard != *share)
    throw Error(resumePath + ": cannot resume another shard: the file holds " + describeShare(*from.shard) +
                " of " + std::to_string(from.shard->total) + " spp, this render is " + describeShare(*share) +
                " of " + std::to_string(share->total) + " spp");
}

// What is about to be rendered: the scene, its features, the image size, samples and estimator.
std::string renderSummary(const Renderer& renderer, const Scene& scene, const RenderSettings& settings, int spp,
                          const std::optional<SampleShare>& share) {
  return scene.path + ": " + std::to_string(scene.triangles.size()) + " triangles, " +
         std::to_string(renderer.gpuScene().emitterCount) + " emissive, features: " +
         renderer.sceneFeatures().describe() + "; " + std::to_string(settings.width) + "x" +
         std::to_string(settings.height) + ", " + std::to_string(spp) + " spp, " +
         (share ? describeShare(*share) + ", " : std::string()) +
         (renderModeSpec(settings.mode).pathTracer ? integratorName(settings.integrator) : renderModeName(settings.mode));
}

// The render's time, sample and ray rates, and non-finite sample count, as one line.
std::string speedLine(const RenderStats& st, double total) {
  char line[256];
  std::snprintf(line, sizeof line, "%.2f s, %.3g samples/s, %.3g rays/s, non-finite samples: %llu", total,
                double(st.primaryRays) / total, double(st.rays()) / total, static_cast<unsigned long long>(st.nonFinite));
  return line;
}

// Prints the render statistics as JSON and writes them to --stats FILE (atomically) when asked.
void writeStats(Renderer& renderer, const BudgetResult& result, const RenderBudget& budget, const std::string& statsFile,
                bool quiet) {
  const std::string json = renderStatsJson(renderer, renderer.errorEstimate(), result, budget.targetError > 0.0 && budget.adaptive);
  note(quiet, "stats " + json);
  if (!statsFile.empty())
    writeFileAtomically(statsFile, ".tmp", [&](const std::string& tmp) {
      std::ofstream f(tmp, std::ios::trunc);
      f << json << "\n";
      f.close();
      if (!f) throw Error(tmp + ": cannot write the statistics");
    });
}

// Saves what an interrupted render has and says so on stderr.
void reportInterrupted(const std::function<void()>& saveCheckpoint, const std::string& checkpointFile,
                       const std::optional<SampleShare>& share, int samples, int maxSpp, int spp, double total,
                       const std::string& out) {
  // Always said, even with --quiet: it explains the exit status.
  std::string saved;
  try {
    saveCheckpoint();
    saved = (share ? " " : " and checkpoint ") + checkpointFile + " (continue with --resume " + checkpointFile + ")";
  } catch (const Error& e) {
    saved = "; no checkpoint: " + std::string(e.what());
  }
  if (share)
    std::fprintf(stderr, "caustica: interrupted at %d/%d samples of %s after %.0f s; wrote the partial%s\n",
                 samples, maxSpp, describeShare(*share).c_str(), total, saved.c_str());
  else
    std::fprintf(stderr, "caustica: interrupted at %d/%d spp after %.0f s; wrote %s (partial)%s\n",
                 samples, spp, total, out.c_str(), saved.c_str());
}

}  // namespace

int cmdRender(const std::vector<std::string>& args) {
  const std::vector<OptionSpec> specs = renderOptionSpecs();
  Options opts("caustica render [SCENE] [options]",
               "Renders SCENE (a .gltf/.glb file or a bundled scene name; default cornell-glass) headless and\n"
               "writes the mean radiance of each pixel. Linear outputs are not tone-mapped or clamped.\n"
               "Ctrl-C (SIGINT) or SIGTERM finishes the current pass, writes the image so far and a\n"
               "checkpoint, and exits with status 4; a second Ctrl-C aborts at once.",
               specs);
  if (!opts.parse(args)) return 0;
  bool quiet = opts.has("--quiet");
  std::string out = opts.get("--output", "caustica.png");
  const bool sharded = opts.has("--shard");
  checkOutputForMode(opts, out, sharded);  // fail before any work
  RenderBudget budget = parseBudget(opts);
  int spp = budget.maxSpp;
  const std::string statsFile = opts.get("--stats", "");
  if (opts.has("--stats")) checkWritableFile(statsFile, "stats");
  Backend backend = parseBackend(opts.get("--backend", "auto"));
  const double checkpointSeconds = opts.getDouble("--checkpoint", 0.0);
  if (opts.has("--checkpoint") && !(checkpointSeconds > 0.0))
    throw Error("option --checkpoint needs a number of seconds above 0");
  const bool denoise = opts.has("--denoise");
  const std::vector<Aov> aovs = opts.has("--aov") ? parseAovList(opts.get("--aov", "")) : std::vector<Aov>{};
  if (opts.has("--frames")) return renderFrames(opts, out, budget, backend, checkpointSeconds, denoise, aovs, quiet);
  const std::string checkpointFile = sharded ? out : opts.get("--checkpoint-file", out + ".ckpt");
  std::optional<SampleShare> share;
  if (sharded) {
    const auto [k, n] = parseShardOption(opts.get("--shard", ""));
    share = shareOf(k, n, spp);
    budget.maxSpp = int(share->end - share->first);
  }
  checkOutputsWritable(out, checkpointFile, aovs, share.has_value());
  const std::string resumePath = opts.get("--resume", "") == "auto" ? checkpointFile : opts.get("--resume", "");
  const std::optional<Checkpoint> resumeFrom = readResume(opts, resumePath, quiet);
  // The feature buffers: for the denoiser and --aov, and kept going when the checkpoint has them.
  const bool features = denoise || aovsNeedFeatures(aovs) || (resumeFrom && resumeFrom->state.hasFeatures());
  if (resumeFrom && features && !resumeFrom->state.hasFeatures())
    throw Error(resumePath + ": has no feature sums (it was rendered without --denoise or --aov): resume it without "
                "--denoise and --aov, or render again with them");

  memTrace("command start");
  const auto commandStart = std::chrono::steady_clock::now();
  LoadedScene ls = loadSceneForCli(opts, !quiet, 512);  // the scene with every image setting applied
  memTrace("scene loaded");
  const double parseSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - commandStart).count();
  checkSceneForOutput(ls, out, features, denoise);
  const RenderSettings& settings = ls.settings.render;
  const ToneMapSettings& tone = ls.settings.tone;
  flattenForMode(ls.scene, settings.mode, opts, quiet);  // raster draws flat scenes (cli_common.h)
  const std::uint64_t sceneHash = hashSceneFiles(ls.scene.path);
  const std::string givenIdentity = accumulationIdentity(ls.settings, ls.camera);  // image_settings.h
  note(quiet, "settings: " + settingsSummary(ls.settings));
  if (share && renderModeSpec(settings.mode).samples == SampleRule::OneFrame)
    throw Error(std::string("--mode ") + renderModeName(settings.mode) +
                " with --shard: it draws one deterministic frame, there are no samples to share");
  if (resumeFrom) checkResumable(*resumeFrom, resumePath, sceneHash, givenIdentity, share, nullptr);
  std::string glInfo;
  auto context = createHeadlessContext(backend, &glInfo);
  memTrace("context");
  note(quiet, "OpenGL (" + context->backendName() + "): " + glInfo);
  ShaderLibrary library = shaderLibraryFrom(opts);
  const double startToRenderer = std::chrono::duration<double>(std::chrono::steady_clock::now() - commandStart).count();
  Renderer renderer(library, ls.scene, ls.camera, settings);
  renderer.setFeatureBuffers(features);
  // What this render records: --manifold as the image of this scene sees it (auto resolved).
  const std::string identity = accumulationIdentity(ls.settings, ls.camera, renderer.gpuScene());
  if (resumeFrom) checkResumable(*resumeFrom, resumePath, sceneHash, identity, share, &renderer.gpuScene());
  note(quiet, renderSummary(renderer, ls.scene, settings, spp, share));
  if (resumeFrom) {
    renderer.restoreAccumulation(resumeFrom->state);
    note(quiet, "resumed " + resumePath + " at " + std::to_string(renderer.samplesPerPixel()) + " spp");
  } else if (share) {
    renderer.startAtSample(share->first);  // the share's samples, with the whole render's random streams
  }

  const auto saveCheckpoint = checkpointWriter(renderer, checkpointFile, sceneHash, identity, share);
  const ProgressHooks hooks = renderHooks(checkpointSeconds, saveCheckpoint);
  installInterruptHandlers();
  auto start = std::chrono::steady_clock::now();
  const BudgetResult result =
      renderWithBudget(renderer, budget, share ? "shard " + opts.get("--shard", "") : std::string(), quiet, hooks);
  memTrace("rendered");
  const bool complete = result.reason != StopReason::Interrupted;
  double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  note(quiet, speedLine(renderer.stats(), total));
  note(quiet, loadSummary(renderer, parseSeconds, startToRenderer, ls.scene.triangles.size()));  // load_report.h
  if (!share) writeOutput(renderer, out, tone, denoise, aovs, quiet);
  writeStats(renderer, result, budget, statsFile, quiet);
  if (!complete) {
    reportInterrupted(saveCheckpoint, checkpointFile, share, renderer.samplesPerPixel(), budget.maxSpp, spp, total, out);
    return kExitInterrupted;
  }
  if (share) {
    saveCheckpoint();
    note(quiet, "wrote " + describeShare(*share) + " of " + std::to_string(spp) + " spp to " +
                    std::filesystem::absolute(out).string() +
                    (features ? " with the feature sums (add the parts with caustica merge; --denoise, --aov there)"
                              : " (add the parts with caustica merge)"));
    return 0;
  }
  if (checkpointSeconds > 0.0) saveCheckpoint();  // so that the render can be extended later
  note(quiet, "wrote " + std::filesystem::absolute(out).string());
  return 0;
}

}  // namespace caustica::cli
