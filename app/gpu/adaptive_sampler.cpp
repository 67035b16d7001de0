// adaptive_sampler.cpp — the check schedule and the live-tile decision of adaptive sampling.
#include "gpu/adaptive_sampler.h"

#include <algorithm>
#include <cstdlib>
#include <string>

#include "util/error.h"

namespace caustica {

int defaultAdaptiveTile() {
  const char* v = std::getenv("CAUSTICA_ADAPTIVE_TILE");
  if (v == nullptr || *v == '\0') return kAdaptiveTile;
  const std::string s(v);
  if (s == "1" || s == "2" || s == "4" || s == "8") return std::stoi(s);
  throw Error("CAUSTICA_ADAPTIVE_TILE must be 1, 2, 4 or 8, not '" + s + "'");
}

int defaultMaxSppRatio() {
  const char* v = std::getenv("CAUSTICA_ADAPTIVE_RATIO");
  if (v == nullptr || *v == '\0') return kMaxSppRatio;
  const std::string s(v);
  if (s.find_first_not_of("0123456789") != std::string::npos || s.size() > 6 || std::stoi(s) < 1)
    throw Error("CAUSTICA_ADAPTIVE_RATIO must be an integer from 1 to 999999, not '" + s + "'");
  return std::stoi(s);
}

double defaultVarianceSmoothing() {
  const char* v = std::getenv("CAUSTICA_ADAPTIVE_SMOOTHING");
  if (v == nullptr || *v == '\0') return kVarianceSmoothing;
  char* end = nullptr;
  const double w = std::strtod(v, &end);
  if (end == v || *end != '\0' || !(w >= 0.0 && w <= 1.0))
    throw Error("CAUSTICA_ADAPTIVE_SMOOTHING must be a number from 0 to 1, not '" + std::string(v) + "'");
  return w;
}

AdaptiveSampler::AdaptiveSampler(double targetError, bool adaptive, int minSpp, int tileSize)
    : target_(targetError), adaptive_(adaptive), minSpp_(std::max(2, minSpp)), tileSize_(tileSize) {
  if (tileSize != 1 && tileSize != 2 && tileSize != 4 && tileSize != 8) throw Error("adaptive tile size must be 1, 2, 4 or 8");
}

int AdaptiveSampler::checkAtOrAfter(int spp) const {
  int c = minSpp_;
  while (c < spp) c += std::max(4, c / 8);
  return c;
}

const ErrorEstimate& AdaptiveSampler::check(Renderer& renderer) {
  estimate_ = renderer.errorEstimate(tileSize_);
  liveTiles_ = renderer.liveTileCount();
  if (adaptive_) {
    std::vector<std::uint32_t> live = caustica::liveTiles(estimate_, minSpp_, maxSppRatio_, kTileDilation, smoothing_);
    renderer.setLiveTiles(live, tileSize_);
    liveTiles_ = live.size();
  }
  done_ = estimate_.image <= target_ || (adaptive_ && liveTiles_ == 0);
  return estimate_;
}

}  // namespace caustica
