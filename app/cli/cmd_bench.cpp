// cmd_bench.cpp — `caustica bench`: run time against error for each estimator. Its options and help;
// the work is in cli/bench/: bench_runner (scenes and measured runs), reference_cache (the reference
// each run is measured against), report (CSV, gnuplot plots, summary.md), bench_metrics (arithmetic).
#include <string>
#include <vector>

#include "cli/bench/bench_runner.h"
#include "cli/cli_common.h"
#include "cli/commands.h"

namespace caustica::cli {

int cmdBench(const std::vector<std::string>& args) {
  std::vector<OptionSpec> specs = {
      {"--size", "", "W[xH]", "image size in pixels (default 256; H follows the camera's aspect)"},
      {"--max-seconds", "", "S", "render time per estimator run in seconds (default 20)"},
      {"--integrators", "", "LIST", "estimators to compare, comma-separated: naive, mis (manifold NEE as --manifold says, default auto), "
       "mis-off (without manifold NEE), manifold (mis with --manifold on), mis-unguided (mis with --guide-probability 0), "
       "mis-eye (mis with --light-tracing off) (default naive,mis)"},
      {"--adaptive", "", "LIST",
       "estimators that also get an adaptive-sampling run, comma-separated (default mis; none for none)"},
      {"--dispersion", "", "LIST", "dispersion modes for scenes with dispersive glass (default rgb,spectral)"},
      {"--adaptive-bound", "", "",
       "no measured runs: print the gain over uniform sampling that the best allocation of samples over tiles "
       "can reach, from a uniform mis render's even/odd halves (docs/adaptive-sampling.md)"},
      {"--bound-spp", "", "N", "samples per pixel of --adaptive-bound's render (default: half the reference's)"},
      {"--reference", "", "FILE", "linear .exr/.pfm reference (one scene, one mode) instead of rendering one"},
      {"--reference-spp", "", "N", "samples per pixel of rendered references (default: bench/scenes.json, else 1024)"},
      {"--refresh-reference", "", "", "render the reference again even if the cache has it"},
      {"--cache", "", "DIR", "reference cache folder (default ~/.cache/caustica/references)"},
      {"--out", "", "DIR", "output folder for CSVs, plots and summary.md (default bench-out)"},
      {"--scenes-json", "", "FILE", "caustic regions per scene (default: the bundled bench/scenes.json)"},
      {"--gnuplot", "", "PROG", "gnuplot program that draws the plots (default gnuplot)"},
      {"--seed", "", "S", "random seed of the measured runs (default 1); the reference uses another"},
      {"--denoise", "", "",
       "also measure the denoiser: a denoised mis run (its filter on the clock), and raw against denoised at 4, 16, 64, "
       "256 spp (OUT/denoise.csv, bench-denoise-SCENE.png plots and -pictures.png figures, a summary table; docs/denoising.md)"},
      sceneOptionSpec("--max-depth"),
      sceneOptionSpec("--caster-probability"),
      sceneOptionSpec("--guide-probability"),
      sceneOptionSpec("--manifold"),
      sceneOptionSpec("--camera"),
      sceneOptionSpec("--backend"),
      sceneOptionSpec("--shader-dir"),
      sceneOptionSpec("--all-features"),
      {"--quiet", "-q", "", "print nothing but errors and the summary table"},
  };
  for (OptionSpec& s : sceneInputOptionSpecs()) specs.push_back(std::move(s));
  Options opts("caustica bench [SCENE...] [options]",
               "Measures run time against error: for each SCENE (default: every bundled scene), each estimator\n"
               "and each dispersion mode the scene uses, renders progressively and records relMSE against a\n"
               "reference (whole image and the scene's caustic region) at log-spaced times. Writes\n"
               "OUT/bench-SCENE.csv, OUT/bench-SCENE.png (log-log plot by gnuplot) and OUT/summary.md.",
               specs);
  if (!opts.parse(args)) return 0;
  return runBench(opts);
}

}  // namespace caustica::cli
