// budget_render.h — a render that stops at whichever budget it reaches first: samples per pixel
// (--spp, a cap), seconds (--time) or an estimated relMSE (--target-error, with adaptive sampling),
// and the statistics a script reads afterwards (--stats FILE.json).
#pragma once
#include <optional>
#include <string>

#include "cli/cli_common.h"
#include "gpu/adaptive_sampler.h"
#include "gpu/renderer.h"

namespace caustica::cli {

struct RenderBudget {
  int maxSpp = 64;           // samples per pixel: a cap (the most any pixel receives)
  double seconds = 0.0;      // > 0: stop after about this long (the pass under way finishes)
  double targetError = 0.0;  // > 0: stop once the estimated relMSE of the image is at most this
  bool adaptive = true;      // with targetError: converged tiles stop receiving samples
};

enum class StopReason { Spp, Time, TargetError, Interrupted };
const char* stopReasonName(StopReason r);  // "spp", "time", "target-error", "interrupted"

struct BudgetResult {
  StopReason reason = StopReason::Spp;
  double seconds = 0.0;
};

// Renders until the first budget is reached, with the progress line and hooks of renderWithProgress.
// Passes never cross a scheduled error check (AdaptiveSampler), so a resumed adaptive render takes
// the decisions an uninterrupted one would; after a resume the live tiles are recomputed first.
BudgetResult renderWithBudget(Renderer& renderer, const RenderBudget& budget, const std::string& label, bool quiet,
                              const ProgressHooks& hooks);

// The statistics of a finished render as one JSON line: seconds, spp_min, spp_mean, spp_max,
// estimated_relmse (null when unknown: fewer than 2 samples somewhere), nonfinite_samples, rays,
// samples, stop ("spp", "time", "target-error", "interrupted"), live_tiles, adaptive.
std::string renderStatsJson(const Renderer& renderer, const ErrorEstimate& estimate, const BudgetResult& result,
                            bool adaptive);

}  // namespace caustica::cli
