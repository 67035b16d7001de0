// denoise_ladder.h — `caustica bench --denoise` at fixed sample counts (docs/denoising.md): the raw and
// the denoised image of one render at 4, 16, 64 and 256 spp against the reference (relMSE, whole image and
// caustic region, and their means), the denoiser's time against a 1-spp pass, a CSV, a plot, a summary
// table and the figure of raw, denoised and reference pictures. The text and pictures are pure functions
// (no OpenGL); runDenoiseLadder renders.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "cli/bench/bench_metrics.h"
#include "cli/bench/reference_cache.h"
#include "cli/bench/report.h"
#include "cli/compare_figure.h"
#include "gpu/renderer.h"

namespace caustica::cli {

// One sample count of the ladder. Means are over the reference's (1: the same); NaN without a caustic region.
struct DenoiseStep {
  int spp = 0;
  double rawRelMse = 0.0, denoisedRelMse = 0.0;
  double rawRelMseCaustic = 0.0, denoisedRelMseCaustic = 0.0;
  double rawMean = 0.0, denoisedMean = 0.0;
  double rawCausticMean = 0.0, denoisedCausticMean = 0.0;
};

struct DenoiseLadder {
  std::string scene, dispersion;
  int width = 0, height = 0;
  std::vector<DenoiseStep> steps;  // increasing spp
  double noise = 0.0, noiseCaustic = 0.0;  // the reference's own relMSE (NaN if unknown)
  int referenceSpp = 0;
  bool hasCaustic = false;
  // Medians of interleaved timings at the ladder's size, milliseconds: the denoiser, one 1-spp pass of
  // the plain path tracer, and one of the path tracer with feature buffers.
  double filterMs = 0.0, passMs = 0.0, featurePassMs = 0.0;
  // The raw and denoised pictures at the sample counts of the figure (4, 16, 64), and the reference.
  std::vector<std::pair<Image, Image>> pictures;
  std::vector<int> pictureSpp;
  Image reference;
};

// The sample counts of the ladder, and those shown in the figure.
const std::vector<int>& denoiseLadderSpp();
const std::vector<int>& denoiseFigureSpp();

// Renders the ladder: `featured` (feature buffers on, the measured settings) from 0 spp; `plain` the same
// settings without them (for the pass timing). Restarts both.
DenoiseLadder runDenoiseLadder(Renderer& featured, Renderer& plain, const std::string& scene, const Reference& ref,
                               const std::optional<PixelRect>& caustic, bool quiet);

// OUT/denoise.csv: a row per scene, mode and sample count.
std::string denoiseLadderCsv(const std::vector<DenoiseLadder>& ladders);
// gnuplot script of one ladder (relMSE against spp, log-log; raw and denoised, whole image and caustic
// region; the reference's noise), writing bench-denoise-STEM.png.
std::string denoiseLadderPlot(const BenchSetup& setup, const DenoiseLadder& ladder, const std::string& stem);
// The summary.md section: per scene, denoised 16 spp against raw 256 spp (and raw 1024 spp extrapolated
// from it), the means, and the denoiser's time against a 1-spp pass.
std::string denoiseSummaryMarkdown(const std::vector<DenoiseLadder>& ladders);
// The figure: a row per sample count (raw, denoised) and the reference, captioned with relMSE.
Canvas composeDenoiseFigure(const DenoiseLadder& ladder, const ToneMapSettings& tone);

}  // namespace caustica::cli
