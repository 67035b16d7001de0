// cmd_render.cpp — `caustica render`: headless progressive render of a scene to an image file.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>

#include "cli/bench/reference_cache.h"
#include "cli/budget_render.h"
#include "cli/checkpoint.h"
#include "cli/cli_common.h"
#include "cli/load_report.h"
#include "cli/commands.h"
#include "util/error.h"
#include "util/file_io.h"
#include "util/memory_stats.h"
#include "image/image_io.h"
#include "platform/context.h"

namespace caustica::cli {

int cmdRender(const std::vector<std::string>& args) {
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
       "continue the render saved in CHECKPOINT (same scene and settings; --spp is the new total)"},
  };
  for (auto& s : sceneOptionSpecs()) specs.push_back(s);
  Options opts("caustica render [SCENE] [options]",
               "Renders SCENE (a .gltf/.glb file or a bundled scene name; default cornell-glass) headless and\n"
               "writes the mean radiance of each pixel. Linear outputs are not tone-mapped or clamped.\n"
               "Ctrl-C (SIGINT) or SIGTERM finishes the current pass, writes the image so far and a\n"
               "checkpoint, and exits with status 4; a second Ctrl-C aborts at once.",
               specs);
  if (!opts.parse(args)) return 0;
  bool quiet = opts.has("--quiet");
  std::string out = opts.get("--output", "caustica.png");
  checkImageExtension(out);  // fail before any work
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
  const std::string statsFile = opts.get("--stats", "");
  if (opts.has("--stats")) checkWritableFile(statsFile, "stats");
  Backend backend = parseBackend(opts.get("--backend", "auto"));
  const double checkpointSeconds = opts.getDouble("--checkpoint", 0.0);
  if (opts.has("--checkpoint") && !(checkpointSeconds > 0.0))
    throw Error("option --checkpoint needs a number of seconds above 0");
  const std::string checkpointFile = opts.get("--checkpoint-file", out + ".ckpt");
  checkWritableFile(out, "output");
  checkWritableFile(checkpointFile, "checkpoint");
  std::optional<Checkpoint> resumeFrom;
  const std::string resumePath = opts.get("--resume", "");
  if (opts.has("--resume")) resumeFrom = readCheckpoint(resumePath);  // a bad file fails before any work

  memTrace("command start");
  const auto commandStart = std::chrono::steady_clock::now();
  LoadedScene ls = loadSceneForCli(opts, !quiet, 512);  // the scene with every image setting applied
  memTrace("scene loaded");
  const double parseSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - commandStart).count();
  if (ls.scene.background.kind == Background::Kind::Transparent && fileExtension(out) == ".pfm")
    throw Error(out + ": PFM has no alpha channel: write .exr or .png with --background transparent");
  const RenderSettings& settings = ls.settings.render;
  const ToneMapSettings& tone = ls.settings.tone;
  flattenForMode(ls.scene, settings.mode, opts, quiet);  // raster draws flat scenes (cli_common.h)
  const std::uint64_t sceneHash = hashSceneFiles(ls.scene.path);
  const std::string identity = accumulationIdentity(ls.settings, ls.camera);  // image_settings.h
  note(quiet, "settings: " + settingsSummary(ls.settings));
  if (resumeFrom) {
    std::string diff = checkpointMismatch(*resumeFrom, sceneHash, identity);
    if (!diff.empty()) throw Error(resumePath + ": cannot resume another render: " + diff);
  }
  std::string glInfo;
  auto context = createHeadlessContext(backend, &glInfo);
  memTrace("context");
  note(quiet, "OpenGL (" + context->backendName() + "): " + glInfo);
  ShaderLibrary library = shaderLibraryFrom(opts);
  const double startToRenderer = std::chrono::duration<double>(std::chrono::steady_clock::now() - commandStart).count();
  Renderer renderer(library, ls.scene, ls.camera, settings);
  note(quiet, ls.scene.path + ": " + std::to_string(ls.scene.triangles.size()) + " triangles, " +
                  std::to_string(renderer.gpuScene().emitterCount) + " emissive, features: " +
                  renderer.sceneFeatures().describe() + "; " + std::to_string(settings.width) + "x" +
                  std::to_string(settings.height) + ", " + std::to_string(spp) + " spp, " +
                  (renderModeSpec(settings.mode).pathTracer ? integratorName(settings.integrator) : renderModeName(settings.mode)));
  if (resumeFrom) {
    renderer.restoreAccumulation(resumeFrom->state);
    note(quiet, "resumed " + resumePath + " at " + std::to_string(renderer.samplesPerPixel()) + " spp");
  }

  auto saveCheckpoint = [&] {
    Checkpoint ck;
    ck.state = renderer.saveAccumulation();
    ck.seed = settings.seed;
    ck.sceneHash = sceneHash;
    ck.identity = identity;
    writeCheckpoint(checkpointFile, ck);
  };
  ProgressHooks hooks;
  hooks.stopOnInterrupt = true;
  hooks.checkpointSeconds = checkpointSeconds;
  hooks.checkpoint = saveCheckpoint;
  installInterruptHandlers();
  auto start = std::chrono::steady_clock::now();
  const BudgetResult result = renderWithBudget(renderer, budget, "", quiet, hooks);
  memTrace("rendered");
  const bool complete = result.reason != StopReason::Interrupted;
  double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const RenderStats& st = renderer.stats();
  char line[256];
  std::snprintf(line, sizeof line, "%.2f s, %.3g samples/s, %.3g rays/s, non-finite samples: %llu", total,
                double(st.primaryRays) / total, double(st.rays()) / total, static_cast<unsigned long long>(st.nonFinite));
  note(quiet, line);
  note(quiet, loadSummary(renderer, parseSeconds, startToRenderer, ls.scene.triangles.size()));  // load_report.h
  writeImage(out, renderer.image(), tone);
  {
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
  if (!complete) {
    // Always said, even with --quiet: it explains the exit status.
    std::string saved;
    try {
      saveCheckpoint();
      saved = " and checkpoint " + checkpointFile + " (continue with --resume " + checkpointFile + ")";
    } catch (const Error& e) {
      saved = "; no checkpoint: " + std::string(e.what());
    }
    std::fprintf(stderr, "caustica: interrupted at %d/%d spp after %.0f s; wrote %s (partial)%s\n",
                 renderer.samplesPerPixel(), spp, total, out.c_str(), saved.c_str());
    return kExitInterrupted;
  }
  if (checkpointSeconds > 0.0) saveCheckpoint();  // so that the render can be extended later
  note(quiet, "wrote " + std::filesystem::absolute(out).string());
  return 0;
}

}  // namespace caustica::cli
