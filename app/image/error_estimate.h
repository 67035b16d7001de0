// error_estimate.h — the renderer's own estimate of its error, from two independent half-images (even
// and odd samples of each pixel): relMSE per pixel, per tile and over the image, and the live tiles
// of adaptive sampling. Pure arithmetic on the read-back images; no GL (docs/adaptive-sampling.md).
#pragma once
#include <cstdint>
#include <limits>
#include <vector>

namespace caustica {

// The denominator's constant, as in the bench's relMSE (bench_metrics.h kRelMseEpsilon).
constexpr double kErrorEpsilon = 0.01;

// Per pixel and colour channel, with the pixel's n samples split into nA even and nB odd ones and the
// half means mA, mB, the variance of the pixel's mean m is estimated without bias by
//   Var(m) ≈ (mA - mB)^2 / (1/nA + 1/nB) / n     (= (mA - mB)^2 / 4 when nA = nB = n/2),
// and the pixel's relMSE by the mean over channels of Var(m) / (mbar^2 + kErrorEpsilon), with mbar the
// mean of its 8 neighbours' means: independent of the pixel's own samples, which the numerator
// depends on (with m itself, bright outliers lower their own estimate; error_estimate.cpp).
struct ErrorEstimate {
  int width = 0, height = 0;
  int tileSize = 8, tilesX = 0, tilesY = 0;  // tiles of tileSize x tileSize pixels (edge tiles smaller)
  std::vector<float> pixel;       // relMSE estimate per pixel; +inf where a half has no sample
  std::vector<double> tile;       // mean of `pixel` over each tile (row-major, tilesX x tilesY)
  std::vector<int> tileSppMin;    // fewest samples of any pixel of the tile
  double image = std::numeric_limits<double>::infinity();  // mean of `pixel` over the image
  int sppMin = 0, sppMax = 0;     // samples per pixel (finite samples; non-finite ones are not counted)
  double sppMean = 0.0;
};

// From the three rgba32f images of Renderer (width*height*4 floats each): accum (running sums,
// a = count), comp (their Kahan compensation) and half (odd-numbered samples' sum and count).
ErrorEstimate estimateError(int width, int height, const std::vector<float>& accum, const std::vector<float>& comp,
                            const std::vector<float>& half, int tileSize = 8);

// The variance estimate of one pixel channel's mean from its two halves: sums sumA, sumB of nA, nB
// samples (+inf when a half is empty), and its relMSE with the pixel's own mean in the denominator.
double pixelChannelVariance(double sumA, double nA, double sumB, double nB);
double pixelChannelRelMse(double sumA, double nA, double sumB, double nB);

// Adaptive sampling: the tiles that receive the next samples, packed x | y << 16 (row-major order).
// The mean relMSE over the image falls fastest by sampling the tiles whose error falls most per sample:
// with e = v / n, -de/dn = e / n, the tile's "gain". Tiles whose gain is at least the mean gain over
// all tiles are live; sampling lowers their gain (as 1/n^2) until the paused ones are ahead again, so
// the allocation tends to n proportional to each tile's standard deviation, the allocation with the
// least mean error for a given number of samples. Guards against starving a tile whose few samples
// missed rare paths: a tile with fewer than `minSpp` samples, or less than 1/`maxSppRatio` of the most
// sampled tile's, is live whatever its estimate; a tile whose gain is over 4x the mean makes its
// neighbours within `dilation` tiles live (they may share its rare paths). NaN and +inf are live.
// `smoothing` in [0, 1]: the gain is taken from each tile's per-sample variance e n blended with the
// mean over its 3x3 tile neighbourhood, (1 - smoothing) own + smoothing neighbourhood: a 4x4 tile's
// own estimate swings with single bright samples and misses rare paths its neighbours share
// (docs/adaptive-sampling.md, "How much it can gain": 0.5 allocates better).
std::vector<std::uint32_t> liveTiles(const ErrorEstimate& estimate, int minSpp, int maxSppRatio, int dilation,
                                     double smoothing = 0.0);

// How much adaptive sampling can gain at all (docs/adaptive-sampling.md, "How much it can gain"). `tileVariance`:
// each tile's per-sample relative variance v (relMSE x samples per pixel under uniform sampling; tiles
// of equal size). The image's mean relMSE, mean(v / n), is least for a given mean n when n is
// proportional to sqrt(v); that allocation's gain over uniform sampling is mean(v) / mean(sqrt(v))^2.
// 1 when every v is equal; NaN when every v is 0 or any is not finite.
double adaptiveGainBound(const std::vector<double>& tileVariance);

// The same best allocation under liveTiles' guards, at a mean of `meanSpp` samples per pixel: every
// tile gets at least `minSpp` samples, and none has fewer than 1/`maxSppRatio` of the most sampled
// tile's (the best such allocation is n = clamp(c sqrt(v), lo, hi) with hi <= maxSppRatio lo; found by
// scanning hi). 1 when meanSpp <= minSpp (every tile then needs the minimum). maxSppRatio <= 0: no ratio guard.
double guardedAdaptiveGainBound(const std::vector<double>& tileVariance, double meanSpp, int minSpp, int maxSppRatio);

}  // namespace caustica
