// bench_metrics.h — the arithmetic of `caustica bench` (no OpenGL): relative MSE against a reference,
// the reference's own noise from two independent halves, log-spaced checkpoints, time to reach an
// error threshold, the batch size of a progressive run, FNV-1a hashing for the reference cache,
// bench/scenes.json, the CSV rows and number formatting for the report.
#pragma once
#include <cstddef>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "image/image_io.h"
#include "util/hash.h"  // fnv1a64, hex64 (the bench's reference cache keys)

namespace caustica {

// relMSE = mean over pixels and colour channels of (x - ref)^2 / (ref^2 + kRelMseEpsilon), with
// radiance in the scene's linear units. The epsilon keeps black pixels from dominating.
constexpr double kRelMseEpsilon = 0.01;

// A crop in normalized image coordinates: x right and y down, both in [0, 1]; x0 < x1, y0 < y1.
struct CropRect {
  double x0 = 0.0, y0 = 0.0, x1 = 1.0, y1 = 1.0;
};

// A crop in pixels, half-open: columns [x0, x1), rows [y0, y1) (row 0 is the top of the image).
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
  bool empty() const { return x1 <= x0 || y1 <= y0; }
};

// The pixels whose centres lie inside `crop` for a width x height image; at least one pixel.
PixelRect cropToPixels(const CropRect& crop, int width, int height);
PixelRect fullImage(int width, int height);

// relMSE of `image` against `reference` over `region` (whole image when omitted). Throws Error when
// the sizes differ or the region leaves the image.
double relMse(const Image& image, const Image& reference);
double relMse(const Image& image, const Image& reference, const PixelRect& region);

// The mean of `image` over `region`, every channel (linear radiance).
double imageMean(const Image& image, const PixelRect& region);

// The error of the reference (halfA + halfB) / 2 itself, in relMSE units, when halfA and halfB are
// independent renders with the same number of samples: E[(A - B)^2] = 2 var(half) = 4 var(mean), so
// the estimate is mean((A - B)^2 / (M^2 + eps)) / 4 with M = (A + B) / 2.
double referenceNoise(const Image& halfA, const Image& halfB);
double referenceNoise(const Image& halfA, const Image& halfB, const PixelRect& region);
// Each tileSize x tileSize tile's per-sample relative variance (row-major; edge tiles smaller), the input
// of adaptiveGainBound (image/error_estimate.h): from a render's running sums (accum, comp, half as
// error_estimate.h reads them: even and odd samples of each pixel), per pixel and channel the variance
// of one sample, pixelChannelVariance x n, over reference^2 + eps (the bench's relMSE weight, from a
// reference independent of the render: the render's own mean would be correlated with its variance
// estimate and lower it where bright outliers are), averaged over channels and the tile's pixels.
std::vector<double> tileRelVariance(const std::vector<float>& accum, const std::vector<float>& comp,
                                    const std::vector<float>& half, const Image& reference, int tileSize);
// (a + b) / 2 per value; throws Error when the sizes differ.
Image averageImages(const Image& a, const Image& b);

// Checkpoint times in seconds: first * 2^(k / perOctave) for every such time below maxSeconds,
// then maxSeconds itself. Needs first > 0 and perOctave >= 1; maxSeconds <= first gives {maxSeconds}.
std::vector<double> checkpointSchedule(double first, double maxSeconds, int perOctave);

// When a decreasing error curve reaches `threshold`.
struct ThresholdTime {
  enum class Kind {
    Interpolated,  // between two checkpoints, on log-log axes
    AtFirst,       // already below at the first checkpoint: `seconds` is that checkpoint's time (an upper bound)
    Extrapolated,  // never reached: last time * last error / threshold, assuming error ~ 1/time
    Unknown        // no finite positive data
  };
  Kind kind = Kind::Unknown;
  double seconds = 0.0;
};
// `seconds` increasing; errors may hold NaN (skipped). The first checkpoint at or below `threshold`
// counts; the crossing is interpolated linearly in (log seconds, log error).
ThresholdTime timeToThreshold(const std::vector<double>& seconds, const std::vector<double>& errors, double threshold);
// "1.23 s", "<= 0.25 s", "~41 s" (extrapolated) or "n/a".
std::string formatThresholdTime(const ThresholdTime& t);

// Efficiency of a Monte Carlo estimator: 1 / (relMSE * seconds); constant once error ~ 1/time.
double efficiency(double relMse, double seconds);

// Samples per pixel for the next dispatch of a progressive run that holds `sppSoFar` spp after
// `elapsedSeconds` of rendering: enough to reach `targetSeconds` at the rate so far, but no more than
// `maxDispatchSeconds` of work, and at least 1. Before the first dispatch (sppSoFar 0): 1.
int nextBatchSpp(int sppSoFar, double elapsedSeconds, double targetSeconds, double maxDispatchSeconds);

// One number through a printf format that takes one double ("%.6g", "%.2fx"); up to 63 characters.
std::string formatDouble(const char* printfFormat, double value);
// Three significant digits ("0.0259", "1.23e+06"); "n/a" when not finite.
std::string formatSci(double value);

// One entry of bench/scenes.json.
struct BenchSceneInfo {
  std::optional<CropRect> caustic;  // the caustic region; none for scenes without caustics
  std::string note;                 // what the region shows (for the docs)
  int referenceSpp = 0;             // samples per pixel of the rendered reference; 0 = the default
};
// Parses bench/scenes.json:
//   {"scenes": {"NAME": {"caustic": [x0, y0, x1, y1] | null, "note": "...", "reference_spp": N}}}
// ("note" and "reference_spp" optional; N even, >= 2).
// `fileName` names the file in error messages. Throws Error on bad JSON or bad rectangles.
std::map<std::string, BenchSceneInfo> parseBenchScenes(const std::string& jsonText, const std::string& fileName);
// The same, read from the file at `path` (named in errors; Error when it cannot be read).
std::map<std::string, BenchSceneInfo> readBenchScenes(const std::string& path);

// One checkpoint of one run: a row of the CSV.
struct BenchRow {
  std::string scene, integrator, dispersion, glRenderer;
  int width = 0, height = 0;
  int checkpoint = 0;             // index within the run, from 0
  double seconds = 0.0;           // render time so far (excludes checkpoint read-backs), seconds
  double cpuSeconds = 0.0;        // the process's CPU time (every thread, llvmpipe's too) over the same spans:
                                  // steadier than `seconds` on a machine whose load moves
  int spp = 0;                    // samples per pixel so far
  double samplesPerSecond = 0.0;  // camera paths per second
  double raysPerSecond = 0.0;     // primary + secondary + shadow rays per second (GPU counters)
  std::uint64_t primaryRays = 0, secondaryRays = 0, shadowRays = 0, nonFinite = 0;
  double relMse = 0.0;            // whole image
  double relMseCaustic = 0.0;     // caustic region; NaN when the scene has none
  double referenceNoise = 0.0;    // the reference's own relMSE estimate, whole image; NaN if unknown
  double referenceNoiseCaustic = 0.0;
  // The image's mean over the reference's (1: the same), whole image and caustic region (NaN: none).
  double meanRatio = std::nan(""), meanRatioCaustic = std::nan("");
  double filterSeconds = 0.0;     // denoised runs (bench --denoise): the denoiser's time, included in `seconds`
};
std::string benchCsvHeader();
std::string benchCsvRow(const BenchRow& row);  // no trailing newline; NaN written as "nan"
// Writes header and rows; throws Error naming the file on failure.
void writeBenchCsv(const std::string& path, const std::vector<BenchRow>& rows);

}  // namespace caustica
