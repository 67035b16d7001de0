// frame_pacer.cpp — the viewer's time model: band sizes, pass spp, preview scale and display rate from
// measured GPU times (ms). No GL, no window: the viewer measures, this decides.
#include "cli/view/frame_pacer.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace caustica {

namespace {

constexpr double kCostBlend = 0.3;            // weight of a band's measurement in costMs()
constexpr double kDisplayBlend = 0.2;         // weight of a display measurement after the first two
constexpr double kPassShare = 0.5;            // a pass (or a preview pass) aims at this share of the budget
constexpr double kSlowShare = 0.8;            // a full 1-spp pass over this share of the budget is slow: preview
constexpr double kDisplayTimeFactor = 4.0;    // show frames at most every 4x the display cost (1/4 of the time)
constexpr double kMinTracingShare = 0.25;     // a shown frame still traces at least this share of the budget

}  // namespace

FramePacer::FramePacer(const PacingConfig& config) : config_(config), costMs_(config.initialCostMs) {}

double FramePacer::rowMs(int y, int width, int spp) const {
  bool known = y >= 0 && y < static_cast<int>(rowCost_.size()) && rowCost_[y] > 0.0;
  return (known ? rowCost_[y] : costMs_) * width * spp;
}

void FramePacer::restartPass() {
  bandY_ = 0;
  previewPasses_ = 0;
}

int FramePacer::choosePassSpp(int width, int height, int accumulatedSpp) const {
  if (config_.scripted) return 1;
  double passMs = costMs_ * width * height;
  int spp = static_cast<int>(std::clamp(std::floor(kPassShare * config_.budgetMs / passMs), 1.0, double(kMaxPassSpp)));
  if (config_.maxSpp > 0) spp = std::max(1, std::min(spp, config_.maxSpp - accumulatedSpp));
  return spp;
}

Band FramePacer::nextBand(int width, int height, int accumulatedSpp, double remainingMs) {
  if (static_cast<int>(rowCost_.size()) != height) rowCost_.assign(static_cast<size_t>(std::max(height, 0)), 0.0);
  if (bandY_ == 0) passSpp_ = choosePassSpp(width, height, accumulatedSpp);
  Band band;
  band.y0 = band.y1 = bandY_;
  band.spp = passSpp_;
  while (band.y1 < height &&
         (band.y1 == band.y0 || band.predictedMs + rowMs(band.y1, width, passSpp_) <= remainingMs))
    band.predictedMs += rowMs(band.y1++, width, passSpp_);
  return band;
}

bool FramePacer::finishBand(const Band& band, int width, int height, double measuredMs) {
  double ratio = measuredMs / std::max(band.predictedMs, 1e-9);
  for (int y = band.y0; y < band.y1; ++y) rowCost_[y] = (rowCost_[y] > 0.0 ? rowCost_[y] : costMs_) * ratio;
  double samples = static_cast<double>(band.rows()) * width * band.spp;
  costMs_ += kCostBlend * (measuredMs / samples - costMs_);
  bandY_ = band.y1;
  if (bandY_ < height) return false;
  bandY_ = 0;
  if (previewing_) ++previewPasses_;
  return true;
}

bool FramePacer::done(int accumulatedSpp) const {
  return config_.maxSpp > 0 && !previewing_ && bandY_ == 0 && accumulatedSpp >= config_.maxSpp;
}

ResolutionChoice FramePacer::chooseResolution(int fullWidth, int fullHeight, double nowSeconds, bool restarted) {
  bool moving = nowSeconds - lastMotion_ < kSettleSeconds;
  double fullPassMs = costMs_ * fullWidth * fullHeight;  // one sample per pixel
  // A full pass that does not fit the budget makes a restart show black rows for a while: preview.
  bool slow = config_.preview && fullPassMs > kSlowShare * config_.budgetMs;
  bool wantPreview = slow && (moving || restarted || (previewing_ && previewPasses_ == 0));
  ResolutionChoice choice;
  if (wantPreview) {
    int scale = static_cast<int>(std::clamp(std::ceil(std::sqrt(fullPassMs / (kPassShare * config_.budgetMs))),
                                            double(kMinPreviewScale), double(kMaxPreviewScale)));
    if (!previewing_ || (restarted && std::abs(scale - previewScale_) >= 2)) previewScale_ = scale;
    choice.width = std::max(1, fullWidth / previewScale_);
    choice.height = std::max(1, fullHeight / previewScale_);
    choice.preview = true;
  } else {
    choice.width = fullWidth;
    choice.height = fullHeight;
    choice.leftPreview = previewing_ && previewPasses_ > 0;
  }
  previewing_ = wantPreview;
  return choice;
}

void FramePacer::recordDisplay(double ms, int shownBefore) {
  displayMs_ += (shownBefore <= 1 ? 1.0 : kDisplayBlend) * (ms - displayMs_);
}

bool FramePacer::presentDue(double msSincePresent) const {
  return previewing_ || msSincePresent + 1e-3 >= kDisplayTimeFactor * displayMs_;
}

double FramePacer::tracingBudgetMs(bool presenting) const {
  if (!presenting) return config_.budgetMs;
  return std::max(config_.budgetMs - displayMs_, kMinTracingShare * config_.budgetMs);
}

}  // namespace caustica
