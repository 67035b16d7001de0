// error_estimate.cpp — relMSE estimates from even/odd half-images and the live tiles of adaptive sampling.
#include "image/error_estimate.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace caustica {

double pixelChannelVariance(double sumA, double nA, double sumB, double nB) {
  if (!(nA > 0.0) || !(nB > 0.0)) return std::numeric_limits<double>::infinity();
  const double n = nA + nB;
  const double d = sumA / nA - sumB / nB;
  // E[d^2] = s^2 (1/nA + 1/nB) for per-sample variance s^2; Var(m) = s^2 / n.
  return d * d / (1.0 / nA + 1.0 / nB) / n;
}

double pixelChannelRelMse(double sumA, double nA, double sumB, double nB) {
  const double m = (sumA + sumB) / (nA + nB);
  return pixelChannelVariance(sumA, nA, sumB, nB) / (m * m + kErrorEpsilon);
}

ErrorEstimate estimateError(int width, int height, const std::vector<float>& accum, const std::vector<float>& comp,
                            const std::vector<float>& half, int tileSize) {
  ErrorEstimate e;
  e.width = width;
  e.height = height;
  e.tileSize = tileSize;
  e.tilesX = (width + tileSize - 1) / tileSize;
  e.tilesY = (height + tileSize - 1) / tileSize;
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  e.pixel.assign(pixels, 0.0f);
  e.tile.assign(static_cast<size_t>(e.tilesX) * e.tilesY, 0.0);
  e.tileSppMin.assign(e.tile.size(), std::numeric_limits<int>::max());
  std::vector<int> tilePixels(e.tile.size(), 0);
  if (pixels == 0 || accum.size() < pixels * 4 || comp.size() < pixels * 4 || half.size() < pixels * 4) return e;
  // Pixel means first. The denominator is the median of three estimates of the pixel's true mean:
  // its own mean m (correlated with (mA - mB)^2: a bright outlier raises both, and alone it
  // underestimates skewed pixels, 0.58x at 8 spp on the Cornell box at 24x24), the mean of its 8
  // neighbours (independent of its samples, but wrong at edges: a caustic pixel among dark ones is
  // overestimated 1.7-7.7x, a dark pixel beside the light underestimated ~0.75x) and the lower of its
  // two half means (an outlier sits in one half only; biased low by the halves' noise). Each is wrong
  // in a different case, and in each case the other two agree (docs/adaptive-sampling.md).
  std::vector<double> mean(pixels * 3), var(pixels * 3), lowHalf(pixels * 3);
  std::vector<int> count(pixels);
  for (size_t i = 0; i < pixels; ++i) {
    const float* a = &accum[i * 4];
    const float* c = &comp[i * 4];
    const float* b = &half[i * 4];
    // Kahan: the true running sum is sum - compensation.
    const double n = double(a[3]) - double(c[3]), nB = b[3], nA = n - nB;
    count[i] = static_cast<int>(std::lround(n));
    for (int ch = 0; ch < 3; ++ch) {
      const double total = double(a[ch]) - double(c[ch]);
      mean[i * 3 + ch] = n > 0.0 ? total / n : 0.0;
      lowHalf[i * 3 + ch] = nA > 0.0 && nB > 0.0 ? std::min((total - b[ch]) / nA, double(b[ch]) / nB) : 0.0;
      var[i * 3 + ch] = pixelChannelVariance(total - b[ch], nA, b[ch], nB);
    }
  }
  double sum = 0.0, sppSum = 0.0;
  e.sppMin = std::numeric_limits<int>::max();
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const size_t i = static_cast<size_t>(y) * width + x;
      double rel = 0.0;
      for (int ch = 0; ch < 3; ++ch) {
        double m = 0.0;
        int k = 0;
        for (int yy = std::max(0, y - 1); yy <= std::min(height - 1, y + 1); ++yy)
          for (int xx = std::max(0, x - 1); xx <= std::min(width - 1, x + 1); ++xx)
            if (xx != x || yy != y || (width == 1 && height == 1)) {
              m += mean[(static_cast<size_t>(yy) * width + xx) * 3 + ch];
              ++k;
            }
        m /= std::max(k, 1);
        // Median of three: own mean, neighbours' mean, the lower half's mean (see above).
        const double own = mean[i * 3 + ch], low = lowHalf[i * 3 + ch];
        m = std::max(std::min(own, m), std::min(std::max(own, m), low));
        rel += var[i * 3 + ch] / (m * m + kErrorEpsilon);
      }
      rel /= 3.0;
      e.pixel[i] = static_cast<float>(rel);
      sum += rel;
      const int spp = count[i];
      sppSum += spp;
      e.sppMin = std::min(e.sppMin, spp);
      e.sppMax = std::max(e.sppMax, spp);
      const size_t t = static_cast<size_t>(y / tileSize) * e.tilesX + x / tileSize;
      e.tile[t] += rel;
      ++tilePixels[t];
      e.tileSppMin[t] = std::min(e.tileSppMin[t], spp);
    }
  for (size_t t = 0; t < e.tile.size(); ++t) e.tile[t] /= std::max(tilePixels[t], 1);
  e.image = sum / static_cast<double>(pixels);
  e.sppMean = sppSum / static_cast<double>(pixels);
  return e;
}

std::vector<std::uint32_t> liveTiles(const ErrorEstimate& e, int minSpp, int maxSppRatio, int dilation,
                                     double smoothing) {
  const size_t tiles = e.tile.size();
  // Each tile's per-sample variance v = e n, blended with the mean over its 3x3 neighbourhood (finite
  // values only; non-finite ones stay as they are and keep the tile live).
  std::vector<double> perSample(tiles), gain(tiles);
  for (size_t t = 0; t < tiles; ++t) perSample[t] = e.tile[t] * std::max(e.tileSppMin[t], 1);
  double meanGain = 0.0;
  int mostSpp = 0, finite = 0;
  for (size_t t = 0; t < tiles; ++t) {
    double v = perSample[t];
    if (smoothing > 0.0 && std::isfinite(v)) {
      const int tx = static_cast<int>(t % e.tilesX), ty = static_cast<int>(t / e.tilesX);
      double sum = 0.0;
      int k = 0;
      for (int y = std::max(0, ty - 1); y <= std::min(e.tilesY - 1, ty + 1); ++y)
        for (int x = std::max(0, tx - 1); x <= std::min(e.tilesX - 1, tx + 1); ++x) {
          const double u = perSample[static_cast<size_t>(y) * e.tilesX + x];
          if (std::isfinite(u)) {
            sum += u;
            ++k;
          }
        }
      v = (1.0 - smoothing) * v + smoothing * sum / k;  // k >= 1: the tile itself is finite
    }
    const double n = std::max(e.tileSppMin[t], 1);
    gain[t] = smoothing > 0.0 ? v / (n * n) : e.tile[t] / n;  // e / n exactly without smoothing
    if (std::isfinite(gain[t])) {
      meanGain += gain[t];
      ++finite;
    }
    mostSpp = std::max(mostSpp, e.tileSppMin[t]);
  }
  // Slightly below the mean, so that tiles of equal gain all count as "at the mean" despite rounding.
  meanGain = meanGain / std::max(finite, 1) * (1.0 - 1e-9);
  std::vector<char> live(tiles, 0);
  for (int ty = 0; ty < e.tilesY; ++ty)
    for (int tx = 0; tx < e.tilesX; ++tx) {
      const size_t t = static_cast<size_t>(ty) * e.tilesX + tx;
      const bool behind = e.tileSppMin[t] < minSpp || static_cast<double>(e.tileSppMin[t]) * maxSppRatio < mostSpp;
      if (behind || !(gain[t] < meanGain) || !std::isfinite(gain[t])) live[t] = 1;
      if (!(gain[t] <= 4.0 * meanGain))
        for (int y = std::max(0, ty - dilation); y <= std::min(e.tilesY - 1, ty + dilation); ++y)
          for (int x = std::max(0, tx - dilation); x <= std::min(e.tilesX - 1, tx + dilation); ++x)
            live[static_cast<size_t>(y) * e.tilesX + x] = 1;
    }
  std::vector<std::uint32_t> out;
  for (int ty = 0; ty < e.tilesY; ++ty)
    for (int tx = 0; tx < e.tilesX; ++tx)
      if (live[static_cast<size_t>(ty) * e.tilesX + tx])
        out.push_back(static_cast<std::uint32_t>(tx) | (static_cast<std::uint32_t>(ty) << 16));
  return out;
}

double adaptiveGainBound(const std::vector<double>& v) {
  double sumV = 0.0, sumSigma = 0.0;
  for (double x : v) {
    if (!std::isfinite(x) || x < 0.0) return std::nan("");
    sumV += x;
    sumSigma += std::sqrt(x);
  }
  if (v.empty() || !(sumSigma > 0.0)) return std::nan("");
  const double n = static_cast<double>(v.size());
  return (sumV / n) / ((sumSigma / n) * (sumSigma / n));
}

double guardedAdaptiveGainBound(const std::vector<double>& v, double meanSpp, int minSpp, int maxSppRatio) {
  const double bound = adaptiveGainBound(v);
  if (!std::isfinite(bound)) return bound;
  if (meanSpp <= minSpp) return 1.0;
  const double count = static_cast<double>(v.size());
  double sumV = 0.0;
  for (double x : v) sumV += x;
  // Under floor `lo` and cap `hi` the best allocation is n = clamp(c sigma, lo, hi) (Lagrange, with the
  // box constraints active where they bind), c such that mean(n) = meanSpp; its mean relMSE:
  auto relMseFor = [&](double lo, double hi) {
    auto meanOf = [&](double c) {
      double s = 0.0;
      for (double x : v) s += std::clamp(c * std::sqrt(x), lo, hi);
      return s / count;
    };
    double a = 0.0, b = 1.0;
    while (meanOf(b) < meanSpp && b < 1e300) b *= 2.0;
    for (int i = 0; i < 100; ++i) {
      const double mid = 0.5 * (a + b);
      (meanOf(mid) < meanSpp ? a : b) = mid;
    }
    double e = 0.0;
    for (double x : v) e += x / std::clamp(b * std::sqrt(x), lo, hi);
    return e / count;
  };
  double best = std::numeric_limits<double>::infinity();
  if (maxSppRatio <= 0) {
    best = relMseFor(minSpp, std::numeric_limits<double>::infinity());
  } else {
    // No tile more than maxSppRatio behind the most sampled: n in [hi / ratio, hi] with the floor at
    // least minSpp and hi / ratio <= meanSpp <= hi. Scan the cap hi (log-spaced) for the least error.
    for (int k = 0; k <= 400; ++k) {
      const double hi = meanSpp * std::pow(static_cast<double>(maxSppRatio), k / 400.0);
      const double lo = std::max(static_cast<double>(minSpp), hi / maxSppRatio);
      if (lo <= meanSpp) best = std::min(best, relMseFor(lo, hi));
    }
  }
  return (sumV / count / meanSpp) / best;
}

}  // namespace caustica
