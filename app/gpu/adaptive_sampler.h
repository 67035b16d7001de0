// adaptive_sampler.h — when to check a render's error estimate and which tiles keep receiving samples
// (adaptive sampling): a fixed schedule of checks in samples per pixel, so that a render resumed from
// a checkpoint takes the same decisions as an uninterrupted one (docs/adaptive-sampling.md).
#pragma once
#include <cstddef>

#include "gpu/renderer.h"
#include "image/error_estimate.h"

namespace caustica {

constexpr int kMinAdaptiveSpp = 16;  // no tile stops before every pixel has this many samples
constexpr int kTileDilation = 1;     // live tiles keep their 8 neighbours live
// A tile stops once its estimate is below this fraction of the image's target; the render stops once
// the image's estimate reaches the target. Stopping tiles at the target itself would equalise the
// error (the minimax allocation), which spends as much as uniform sampling on the mean error; the
// mean error is least for samples proportional to each tile's standard deviation, which stopping at
// half the target approaches for images whose noise is concentrated (docs/adaptive-sampling.md).
constexpr double kTileTargetFraction = 0.5;

class AdaptiveSampler {
 public:
  // `targetError`: relMSE at which the render is done (> 0), `adaptive`: whether tiles below the
  // tile target stop receiving samples (else the whole image keeps sampling until the target).
  AdaptiveSampler(double targetError, bool adaptive, int minSpp = kMinAdaptiveSpp);

  // The first scheduled check at `spp` or above: minSpp, then each previous one + max(4, previous / 8).
  int checkAtOrAfter(int spp) const;
  // Estimates the error of `renderer`'s image and, when adaptive, sets its live tiles.
  const ErrorEstimate& check(Renderer& renderer);
  // After a check: the image estimate reached the target, or no tile is live any more.
  bool done() const { return done_; }
  const ErrorEstimate& estimate() const { return estimate_; }
  std::size_t liveTiles() const { return liveTiles_; }
  double targetError() const { return target_; }
  bool adaptive() const { return adaptive_; }

 private:
  double target_;
  bool adaptive_;
  int minSpp_;
  ErrorEstimate estimate_;
  std::size_t liveTiles_ = 0;
  bool done_ = false;
};

}  // namespace caustica
