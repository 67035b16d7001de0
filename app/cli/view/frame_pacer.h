// frame_pacer.h — the viewer's time model, pure logic (no GL, no window): row bands of a pass within a
// GPU time budget, samples per pixel of a pass, the preview resolution while the camera moves, and
// how often a frame is shown. Times in milliseconds (ms) unless named seconds; sizes in pixels.
#pragma once
#include <vector>

namespace caustica {

struct PacingConfig {
  double budgetMs = 30.0;           // path-tracing GPU time per frame, ms
  int maxSpp = 0;                   // stop refining at this many samples per pixel; 0 = never
  bool preview = true;              // lower resolution while the camera moves, when full passes do not fit
  bool scripted = false;            // --frames: one sample per pass, so spp counts passes exactly
  double initialCostMs = 3.3e-3;    // ms per pixel sample before any measurement (llvmpipe speed)
};

// Rows [y0, y1) of the pass in flight, `spp` samples per pixel each, and the time the model expects.
struct Band {
  int y0 = 0, y1 = 0;
  int spp = 1;
  double predictedMs = 0.0;
  int rows() const { return y1 - y0; }
};

// The render resolution wanted now, in pixels (FramePacer::chooseResolution).
struct ResolutionChoice {
  int width = 0, height = 0;
  bool preview = false;      // a 1/previewScale() preview of the full resolution
  bool leftPreview = false;  // a preview that finished a pass just ended: worth showing under the next full pass
};

class FramePacer {
 public:
  static constexpr double kSettleSeconds = 0.25;  // camera still this long: leave the preview for full resolution
  static constexpr int kMinPreviewScale = 2, kMaxPreviewScale = 16;
  static constexpr int kMaxPassSpp = 64;

  explicit FramePacer(const PacingConfig& config);
  const PacingConfig& config() const { return config_; }

  // ---- cost model
  double costMs() const { return costMs_; }  // ms per pixel sample: moving average over bands
  // Predicted ms of image row y at `width` pixels and `spp`: its cost in its last band, else costMs().
  double rowMs(int y, int width, int spp) const;

  // ---- the pass in flight, in row bands
  int passRow() const { return bandY_; }  // first row the pass in flight has not covered; 0 between passes
  int passSpp() const { return passSpp_; }
  void restartPass();  // accumulation restarted: the next band starts a pass at row 0
  // Samples per pixel for a pass over width x height: about half the budget, 1..kMaxPassSpp, no more
  // than what is left to --spp; 1 when scripted. `accumulatedSpp`: what the image already holds.
  int choosePassSpp(int width, int height, int accumulatedSpp) const;
  // The next band: as many rows as the model expects to fit `remainingMs`, at least one. At row 0 it
  // first chooses the pass's spp.
  Band nextBand(int width, int height, int accumulatedSpp, double remainingMs);
  // The band took `measuredMs`: its rows keep their relative costs scaled to the measured total, and
  // costMs() moves toward the measured cost. Returns true when the band finished the pass.
  bool finishBand(const Band& band, int width, int height, double measuredMs);
  // Whether the pass's next row is expected to fit `remainingMs`.
  bool nextRowFits(int width, double remainingMs) const { return remainingMs >= rowMs(bandY_, width, passSpp_); }
  // Refinement has reached --spp (at full resolution, between passes).
  bool done(int accumulatedSpp) const;

  // ---- preview while moving (times in seconds on the caller's clock)
  void noteMotion(double nowSeconds) { lastMotion_ = nowSeconds; }
  void settle() { lastMotion_ = -1e9; }  // treat the camera as long still
  bool previewing() const { return previewing_; }
  int previewScale() const { return previewScale_; }  // preview = full resolution / scale
  // The resolution for the renderer, given the full one: a preview when a full 1-spp pass does not fit
  // 0.8 of the budget and the camera moves or just restarted (or the preview has not finished a pass
  // yet). The scale aims preview passes at half the budget, kMinPreviewScale..kMaxPreviewScale, and is
  // re-chosen only at a restart that changes it by 2 or more.
  ResolutionChoice chooseResolution(int fullWidth, int fullHeight, double nowSeconds, bool restarted);

  // ---- frames shown
  double displayMs() const { return displayMs_; }  // tone mapping + blit, ms (moving average)
  // Records a display's cost; `shownBefore`: frames shown before it (the first two replace the estimate).
  void recordDisplay(double ms, int shownBefore);
  // Whether a frame with new samples should be shown now: always while previewing, else at a rate
  // that keeps display cost within a quarter of the time.
  bool presentDue(double msSincePresent) const;
  // Path-tracing budget of a frame; one that is shown leaves room for the display (at least 1/4).
  double tracingBudgetMs(bool presenting) const;

 private:
  PacingConfig config_;
  double costMs_;
  std::vector<double> rowCost_;  // per image row: ms per pixel sample in its last band (0 = unknown)
  double displayMs_ = 1.0;
  int bandY_ = 0;
  int passSpp_ = 1;
  bool previewing_ = false;
  int previewScale_ = 1;
  int previewPasses_ = 0;    // complete preview passes since the last restart
  double lastMotion_ = -1e9; // seconds
};

}  // namespace caustica
