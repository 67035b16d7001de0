// report.h — what `caustica bench` writes from its measured runs: a CSV and a gnuplot log-log plot per
// scene, the reference previews, and the summary.md table. The text is built by pure functions (no
// OpenGL); the write* functions put it in the output folder.
#pragma once
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "cli/bench/bench_metrics.h"
#include "gpu/render_settings.h"
#include "image/image_io.h"

namespace caustica::cli {

// The checkpoints of one measured run: one scene, one estimator, one dispersion mode.
struct RunResult {
  std::string scene, integrator, dispersion;  // integrator: the estimator's name (estimatorName)
  std::vector<BenchRow> rows;                 // the checkpoints, in time order; at least one
  double noise = std::nan(""), noiseCaustic = std::nan("");  // the reference's own relMSE; NaN if unknown
  int referenceSpp = 0;                                       // 0: the reference was given as a file
  bool hasCaustic = false;                                    // the scene has a caustic region
};

// The machine and the limit the runs had: plot titles and the summary header name them.
struct BenchSetup {
  std::string glRenderer;   // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string backend;      // context backend, e.g. "osmesa"
  double maxSeconds = 0.0;  // render time per run, seconds
};

// "vendor | renderer | version" (the context's GL description) -> "renderer"; other text unchanged.
std::string glRendererName(const std::string& glInfo);
// The estimator's name in the CSV, plots and summary: "naive" or "mis", and for mis on a scene with
// caustic casters a non-default caster probability too ("mis casters=0.3").
std::string estimatorName(const RenderSettings& settings, bool sceneHasCasters);

// A gnuplot single-quoted string: 'it''s'.
std::string gnuplotQuote(const std::string& text);
// The gnuplot script of one scene's runs, data inline: writes bench-SCENE.png (pngcairo) when run in
// its folder; relMSE against render time on log-log axes, a dashed curve per run for the caustic
// region, dotted lines at the references' own noise. `width` x `height`: the image size in pixels.
std::string gnuplotScript(const BenchSetup& setup, const std::string& scene, int width, int height,
                          const std::vector<RunResult>& results);
// "t(0.01) 1.2 s against 3.4 s (2.83x less time), efficiency 2.9x": an adaptive run against the uniform
// run of the same estimator (caustic: in the caustic region), for the summary.
std::string adaptiveGainText(const RunResult& adaptive, const RunResult& uniform, bool caustic);
// summary.md: a header line, a table row per run, mis/naive efficiency ratios per scene and mode,
// and a note on the columns. `totalSeconds`: wall time of the whole bench, seconds.
std::string summaryMarkdown(const BenchSetup& setup, double totalSeconds, const std::vector<RunResult>& all);

// A copy of `image` with a one-pixel outline just outside `region` in (0, value, value); pixels
// outside the image are skipped. Marks the caustic region on the reference preview.
Image outlined(Image image, const PixelRect& region, float value);

// OUT/SCENE-MODE-reference.png: the reference, with the caustic region outlined when there is one.
void writeReferencePreview(const std::string& outDir, const std::string& scene, const std::string& dispersion,
                           const Image& reference, const std::optional<PixelRect>& caustic);
// OUT/bench-SCENE.csv: every checkpoint of every run of the scene. Returns the path.
std::string writeSceneCsv(const std::string& outDir, const std::string& scene, const std::vector<RunResult>& results);
// Writes OUT/bench-SCENE.gp and runs `gnuplot` on it in OUT to make bench-SCENE.png; when gnuplot
// fails or is missing, warns (unless quiet) and goes on.
void writePlot(const std::string& outDir, const std::string& scene, const std::string& script,
               const std::string& gnuplot, bool quiet);
// Prints the summary to stdout and writes it to OUT/summary.md.
void writeSummary(const std::string& outDir, const std::string& markdown, bool quiet);

}  // namespace caustica::cli
