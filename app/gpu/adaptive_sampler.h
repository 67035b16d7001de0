// adaptive_sampler.h — when to check a render's error estimate and which tiles keep receiving samples
// (adaptive sampling): a fixed schedule of checks in samples per pixel, so that a render resumed from
// a checkpoint takes the same decisions as an uninterrupted one (docs/adaptive-sampling.md).
#pragma once
#include <cstddef>

#include "gpu/renderer.h"
#include "image/error_estimate.h"

namespace caustica {

constexpr int kMinAdaptiveSpp = 16;  // no tile stops before every pixel has this many samples
constexpr int kTileDilation = 1;     // a tile with over 4x the mean gain keeps its 8 neighbours live
constexpr int kMaxSppRatio = 8;      // no tile falls behind the most sampled one by more than this factor
constexpr double kVarianceSmoothing = 0.5;  // weight of the 3x3 tile neighbourhood in a tile's variance (liveTiles)
constexpr int kAdaptiveTile = 4;     // side of the tiles in pixels (1, 2, 4 or 8): 4 pays best (docs/adaptive-sampling.md)

// kAdaptiveTile, or the environment variable CAUSTICA_ADAPTIVE_TILE (1, 2, 4 or 8) where set: a knob
// to measure other tile sizes with (docs/adaptive-sampling.md, "How much it can gain"). Throws Error otherwise.
int defaultAdaptiveTile();
// kMaxSppRatio, or the environment variable CAUSTICA_ADAPTIVE_RATIO (an integer >= 1) where set: a knob
// to measure the ratio guard with (docs/adaptive-sampling.md, "How much it can gain"). Throws Error otherwise.
int defaultMaxSppRatio();
// kVarianceSmoothing, or the environment variable CAUSTICA_ADAPTIVE_SMOOTHING (a number in [0, 1]) where
// set: a knob to measure the smoothing with (0 = each tile's own estimate). Throws Error otherwise.
double defaultVarianceSmoothing();

class AdaptiveSampler {
 public:
  // `targetError`: relMSE at which the render is done (> 0), `adaptive`: whether only the tiles whose
  // error falls fastest receive samples (liveTiles in error_estimate.h), else every tile does.
  // `tileSize`: side of the tiles in pixels (1, 2, 4 or 8).
  AdaptiveSampler(double targetError, bool adaptive, int minSpp = kMinAdaptiveSpp, int tileSize = defaultAdaptiveTile());

  // The first scheduled check at `spp` or above: minSpp, then each previous one + max(4, previous / 8).
  int checkAtOrAfter(int spp) const;
  // Estimates the error of `renderer`'s image and, when adaptive, sets its live tiles.
  const ErrorEstimate& check(Renderer& renderer);
  // After a check: the image estimate reached the target.
  bool done() const { return done_; }
  const ErrorEstimate& estimate() const { return estimate_; }
  std::size_t liveTiles() const { return liveTiles_; }
  double targetError() const { return target_; }
  bool adaptive() const { return adaptive_; }
  int tileSize() const { return tileSize_; }

 private:
  double target_;
  bool adaptive_;
  int minSpp_;
  int tileSize_;
  int maxSppRatio_ = defaultMaxSppRatio();
  double smoothing_ = defaultVarianceSmoothing();
  ErrorEstimate estimate_;
  std::size_t liveTiles_ = 0;
  bool done_ = false;
};

}  // namespace caustica
