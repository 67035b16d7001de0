// adaptive_sampler.cpp — the check schedule and the live-tile decision of adaptive sampling.
#include "gpu/adaptive_sampler.h"

#include <algorithm>

namespace caustica {

AdaptiveSampler::AdaptiveSampler(double targetError, bool adaptive, int minSpp)
    : target_(targetError), adaptive_(adaptive), minSpp_(std::max(2, minSpp)) {}

int AdaptiveSampler::checkAtOrAfter(int spp) const {
  int c = minSpp_;
  while (c < spp) c += std::max(4, c / 8);
  return c;
}

const ErrorEstimate& AdaptiveSampler::check(Renderer& renderer) {
  estimate_ = renderer.errorEstimate();
  liveTiles_ = renderer.liveTileCount();
  if (adaptive_) {
    std::vector<std::uint32_t> live = caustica::liveTiles(estimate_, minSpp_, kMaxSppRatio, kTileDilation);
    renderer.setLiveTiles(live);
    liveTiles_ = live.size();
  }
  done_ = estimate_.image <= target_ || (adaptive_ && liveTiles_ == 0);
  return estimate_;
}

}  // namespace caustica
