// budget_render.cpp — the render loop with spp, time and error budgets, and its statistics line.
#include "cli/budget_render.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace caustica::cli {

const char* stopReasonName(StopReason r) {
  switch (r) {
    case StopReason::Spp: return "spp";
    case StopReason::Time: return "time";
    case StopReason::TargetError: return "target-error";
    case StopReason::Interrupted: return "interrupted";
  }
  return "?";
}

BudgetResult renderWithBudget(Renderer& renderer, const RenderBudget& budget, const std::string& label, bool quiet,
                              const ProgressHooks& hooks) {
  const auto start = std::chrono::steady_clock::now();
  auto seconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  const bool tty = isatty(STDERR_FILENO) != 0;
  std::optional<AdaptiveSampler> sampler;
  if (budget.targetError > 0.0) sampler.emplace(budget.targetError, budget.adaptive);
  BudgetResult result;
  int nextCheck = sampler ? sampler->checkAtOrAfter(renderer.samplesPerPixel()) : 0;
  // Resumed at or past a scheduled check: the live tiles are not saved; the same check recomputes them.
  if (sampler && renderer.samplesPerPixel() >= nextCheck && renderer.samplesPerPixel() > 0) {
    sampler->check(renderer);
    nextCheck = sampler->checkAtOrAfter(renderer.samplesPerPixel() + 1);
    if (sampler->done()) result.reason = StopReason::TargetError;
  }
  int batch = 1;
  double lastPrint = -1.0, lastCheckpoint = 0.0, secondsPerSample = 0.0;
  while (!(sampler && sampler->done())) {
    const int spp = renderer.samplesPerPixel();
    if (spp >= budget.maxSpp) {
      result.reason = StopReason::Spp;
      break;
    }
    double now = seconds();
    if (budget.seconds > 0.0 && now >= budget.seconds) {
      result.reason = StopReason::Time;
      break;
    }
    // At least the samples one dispatch traces (path regeneration, Renderer::samplesPerDispatch).
    int n = std::min(std::max(batch, renderer.samplesPerDispatch()), budget.maxSpp - spp);
    if (sampler) n = std::min(n, nextCheck - spp);
    if (budget.seconds > 0.0 && secondsPerSample > 0.0)  // do not run far past the time budget
      n = std::max(1, std::min(n, static_cast<int>((budget.seconds - now) / secondsPerSample) + 1));
    const double t0 = seconds();
    renderer.renderPass(n);
    const double dt = seconds() - t0;
    secondsPerSample = dt / n;
    if (dt < 0.05 && batch < 256) batch *= 2;
    else if (dt > 0.5 && batch > 1) batch /= 2;
    const int done = renderer.samplesPerPixel();
    if (sampler && done >= nextCheck) {
      sampler->check(renderer);
      nextCheck = sampler->checkAtOrAfter(done + 1);
      if (sampler->done()) result.reason = StopReason::TargetError;
    }
    now = seconds();
    const bool last = done >= budget.maxSpp || (sampler && sampler->done());
    if (!quiet && (now - lastPrint > (tty ? 0.5 : 10.0) || last)) {
      lastPrint = now;
      char extra[128] = "";
      if (sampler && std::isfinite(sampler->estimate().image))
        std::snprintf(extra, sizeof extra, "  relMSE~%.3g/%.3g  live tiles %zu", sampler->estimate().image,
                      budget.targetError, sampler->liveTiles());
      std::fprintf(stderr, "%scaustica: %s%s%d/%d spp  %.1f s%s%s", tty ? "\r" : "", label.c_str(),
                   label.empty() ? "" : " ", done, budget.maxSpp, now, extra, tty ? "   " : "\n");
      std::fflush(stderr);
    }
    if (hooks.stopOnInterrupt && interruptRequested()) {
      result.reason = StopReason::Interrupted;
      break;
    }
    if (hooks.checkpointSeconds > 0.0 && hooks.checkpoint && now - lastCheckpoint >= hooks.checkpointSeconds && !last) {
      hooks.checkpoint();
      lastCheckpoint = seconds();
    }
  }
  if (!quiet && tty) std::fprintf(stderr, "\n");
  result.seconds = seconds();
  return result;
}

std::string renderStatsJson(const Renderer& renderer, const ErrorEstimate& e, const BudgetResult& result, bool adaptive) {
  const RenderStats& st = renderer.stats();
  std::ostringstream j;
  j.precision(6);
  j << "{\"seconds\": " << result.seconds << ", \"spp_min\": " << e.sppMin << ", \"spp_mean\": " << e.sppMean
    << ", \"spp_max\": " << e.sppMax << ", \"estimated_relmse\": ";
  if (std::isfinite(e.image)) j << e.image;
  else j << "null";
  j << ", \"nonfinite_samples\": " << st.nonFinite << ", \"rays\": " << st.rays() << ", \"samples\": " << st.primaryRays
    << ", \"stop\": \"" << stopReasonName(result.reason) << "\", \"live_tiles\": " << renderer.liveTileCount()
    << ", \"adaptive\": " << (adaptive ? "true" : "false") << "}";
  return j.str();
}

}  // namespace caustica::cli
