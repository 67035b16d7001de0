// bench_metrics_test.cpp — the benchmark's arithmetic: relMSE and its crop, the reference-noise
// estimate against a known truth, checkpoint spacing, threshold times, batch sizes, FNV-1a,
// scenes.json, CSV and number formatting.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <sstream>

#include "scene/assets.h"
#include "cli/bench/bench_metrics.h"
#include "image/error_estimate.h"
#include "util/error.h"
#include "util/file_io.h"

using namespace caustica;

namespace {

// |a / b - 1|: doctest::Approx has an absolute floor of epsilon, useless for small relMSE values.
double relDiff(double a, double b) { return std::fabs(a / b - 1.0); }

Image constantImage(int w, int h, float v) { return Image{w, h, std::vector<float>(size_t(w) * h * 3, v)}; }

// Splits one CSV line (RFC 4180 quoting) into fields.
std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') out.back() += '"', ++i;
      else if (c == '"') quoted = false;
      else out.back() += c;
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      out.emplace_back();
    } else {
      out.back() += c;
    }
  }
  return out;
}

}  // namespace

TEST_CASE("relMSE follows its definition over the whole image and over a crop") {
  Image ref = constantImage(8, 4, 0.5f);
  CHECK(relMse(ref, ref) == 0.0);

  // An error d on every value of the right half: (d^2 / (r^2 + eps)) there, zero elsewhere.
  Image x = ref;
  const float d = 0.25f;
  for (int y = 0; y < 4; ++y)
    for (int px = 4; px < 8; ++px)
      for (int c = 0; c < 3; ++c) x.at(px, y, c) += d;
  double perValue = double(d) * d / (0.25 + kRelMseEpsilon);
  CHECK(relMse(x, ref) == doctest::Approx(perValue / 2).epsilon(1e-6));
  PixelRect right = cropToPixels(CropRect{0.5, 0.0, 1.0, 1.0}, 8, 4);
  CHECK(relMse(x, ref, right) == doctest::Approx(perValue).epsilon(1e-6));
  PixelRect left = cropToPixels(CropRect{0.0, 0.0, 0.5, 1.0}, 8, 4);
  CHECK(relMse(x, ref, left) == 0.0);

  // Relative: the same relative error weighs the same on bright and dim pixels (well above eps).
  Image bright = constantImage(2, 2, 100.0f), brightX = constantImage(2, 2, 110.0f);
  Image dim = constantImage(2, 2, 10.0f), dimX = constantImage(2, 2, 11.0f);
  CHECK(relDiff(relMse(brightX, bright), relMse(dimX, dim)) < 1e-3);
  // On black pixels the epsilon bounds the weight.
  CHECK(relMse(constantImage(2, 2, 0.1f), constantImage(2, 2, 0.0f)) == doctest::Approx(1.0).epsilon(1e-5));

  CHECK_THROWS_AS(relMse(constantImage(8, 4, 0.0f), constantImage(4, 8, 0.0f)), Error);
  CHECK_THROWS_AS(relMse(ref, ref, PixelRect{0, 0, 9, 4}), Error);
}

TEST_CASE("crops map to the pixels whose centres they contain") {
  PixelRect all = cropToPixels(CropRect{0, 0, 1, 1}, 256, 128);
  CHECK(all.x0 == 0);
  CHECK(all.y0 == 0);
  CHECK(all.x1 == 256);
  CHECK(all.y1 == 128);
  PixelRect q = cropToPixels(CropRect{0.25, 0.5, 0.75, 1.0}, 8, 4);
  CHECK(q.x0 == 2);
  CHECK(q.x1 == 6);
  CHECK(q.y0 == 2);
  CHECK(q.y1 == 4);
  // Pixel centres of a 10-wide image are 0.05, 0.15, ...: [0.32, 0.68) holds those of pixels 3 to 6.
  PixelRect c = cropToPixels(CropRect{0.32, 0.0, 0.68, 1.0}, 10, 1);
  CHECK(c.x0 == 3);
  CHECK(c.x1 == 7);
  PixelRect tiny = cropToPixels(CropRect{0.501, 0.501, 0.502, 0.502}, 4, 4);
  CHECK(tiny.width() == 1);
  CHECK(tiny.height() == 1);
  CHECK(tiny.x1 <= 4);
}

TEST_CASE("the reference-noise estimate matches the true error of the averaged halves") {
  // Truth mu varies per pixel; each half is mu plus independent noise. The estimate from the two
  // halves alone must match the error of their mean against the truth.
  const int w = 96, h = 96;
  std::mt19937 rng(12345);
  std::uniform_real_distribution<float> level(0.2f, 3.0f);
  std::normal_distribution<float> noise(0.0f, 1.0f);
  Image truth{w, h, std::vector<float>(size_t(w) * h * 3)};
  for (auto& v : truth.rgb) v = level(rng);
  Image a = truth, b = truth;
  for (size_t i = 0; i < truth.rgb.size(); ++i) {
    a.rgb[i] += 0.05f * truth.rgb[i] * noise(rng);
    b.rgb[i] += 0.05f * truth.rgb[i] * noise(rng);
  }
  Image mean = averageImages(a, b);
  double actual = relMse(mean, truth);
  double estimate = referenceNoise(a, b);
  CHECK(actual > 0.0);
  CHECK(relDiff(estimate, actual) < 0.05);
  // Each half alone is twice as noisy as the mean.
  CHECK(relDiff(relMse(a, truth), 2.0 * actual) < 0.05);

  PixelRect crop = cropToPixels(CropRect{0.1, 0.6, 0.5, 0.9}, w, h);
  CHECK(relDiff(referenceNoise(a, b, crop), relMse(mean, truth, crop)) < 0.15);
  CHECK(referenceNoise(truth, truth) == 0.0);
}

TEST_CASE("checkpoints are log-spaced and end at the time limit") {
  auto t = checkpointSchedule(0.25, 20.0, 2);
  REQUIRE(t.size() >= 3);
  CHECK(t.front() == doctest::Approx(0.25));
  CHECK(t.back() == doctest::Approx(20.0));
  for (size_t i = 1; i + 1 < t.size(); ++i) CHECK(t[i] / t[i - 1] == doctest::Approx(std::sqrt(2.0)));
  for (size_t i = 1; i < t.size(); ++i) CHECK(t[i] > t[i - 1]);
  CHECK(t[t.size() - 2] < 20.0);
  CHECK(t[t.size() - 2] * std::sqrt(2.0) >= 20.0 * (1 - 1e-9));
  // A power-of-two limit is not repeated.
  auto p = checkpointSchedule(0.5, 4.0, 1);
  CHECK(p == std::vector<double>{0.5, 1.0, 2.0, 4.0});
  CHECK(checkpointSchedule(1.0, 0.5, 1) == std::vector<double>{0.5});
  CHECK_THROWS_AS(checkpointSchedule(0.0, 1.0, 1), Error);
}

TEST_CASE("time to threshold interpolates on log-log axes and extrapolates as 1/time") {
  // An unbiased estimator: relMSE = c / t exactly, so every threshold time is c / threshold.
  const double c = 0.04;
  std::vector<double> t, e;
  for (int k = 0; k < 8; ++k) {
    t.push_back(0.25 * std::exp2(k));
    e.push_back(c / t.back());
  }
  ThresholdTime r = timeToThreshold(t, e, 0.01);
  CHECK(r.kind == ThresholdTime::Kind::Interpolated);
  CHECK(r.seconds == doctest::Approx(4.0));
  r = timeToThreshold(t, e, 0.003);
  CHECK(r.kind == ThresholdTime::Kind::Interpolated);
  CHECK(r.seconds == doctest::Approx(c / 0.003));
  r = timeToThreshold(t, e, 0.001);  // the last point is 0.04 / 32 = 0.00125: not reached
  CHECK(r.kind == ThresholdTime::Kind::Extrapolated);
  CHECK(r.seconds == doctest::Approx(40.0));
  r = timeToThreshold(t, e, 1.0);
  CHECK(r.kind == ThresholdTime::Kind::AtFirst);
  CHECK(r.seconds == doctest::Approx(0.25));

  // NaN checkpoints are skipped; noisy non-monotone data uses the first crossing.
  std::vector<double> e2 = e;
  e2[4] = std::nan("");
  r = timeToThreshold(t, e2, 0.01);
  CHECK(r.kind == ThresholdTime::Kind::Interpolated);
  CHECK(r.seconds == doctest::Approx(4.0));
  CHECK(timeToThreshold({}, {}, 0.01).kind == ThresholdTime::Kind::Unknown);
  CHECK(formatThresholdTime(ThresholdTime{}) == "n/a");
  CHECK(formatThresholdTime({ThresholdTime::Kind::Extrapolated, 41.0}) == "~41 s");

  CHECK(efficiency(0.01, 4.0) == doctest::Approx(25.0));
  CHECK(std::isnan(efficiency(0.0, 1.0)));
}

TEST_CASE("progressive batches aim at the next checkpoint, capped at the longest dispatch") {
  // Before the first dispatch there is no rate yet: one sample per pixel.
  CHECK(nextBatchSpp(0, 0.0, 0.25, 0.1) == 1);
  // 128 spp in 1 s: 0.0625 s more to the checkpoint is 8 spp; the cap is floor(12.8) = 12 spp.
  CHECK(nextBatchSpp(128, 1.0, 1.0625, 0.1) == 8);
  CHECK(nextBatchSpp(128, 1.0, 2.0, 0.1) == 12);
  CHECK(nextBatchSpp(128, 1.0, 2.0, 1.0) == 128);
  // Already past the target (the caller moves on): still at least one.
  CHECK(nextBatchSpp(128, 1.0, 0.5, 0.1) == 1);
  // Slower than one spp per dispatch time: one at a time.
  CHECK(nextBatchSpp(5, 1.0, 3.0, 0.1) == 1);
}

TEST_CASE("numbers are formatted with three significant digits, n/a when not finite") {
  CHECK(formatSci(0.0259) == "0.0259");
  CHECK(formatSci(1234567.0) == "1.23e+06");
  CHECK(formatSci(13.04) == "13");
  CHECK(formatSci(std::nan("")) == "n/a");
  CHECK(formatSci(INFINITY) == "n/a");
  CHECK(formatDouble("%.2fx", 1.5) == "1.50x");
  CHECK(formatDouble("%.6g", 0.2007168) == "0.200717");
  CHECK(formatDouble(" casters=%g", 0.3f) == " casters=0.3");
}

TEST_CASE("FNV-1a 64 matches the published test vectors and chains") {
  CHECK(fnv1a64(std::string()) == 0xcbf29ce484222325ull);
  CHECK(fnv1a64(std::string("a")) == 0xaf63dc4c8601ec8cull);
  CHECK(fnv1a64(std::string("foobar")) == 0x85944171f73967e8ull);
  CHECK(fnv1a64(std::string("bar"), fnv1a64(std::string("foo"))) == fnv1a64(std::string("foobar")));
  CHECK(hex64(0xaf63dc4c8601ec8cull) == "af63dc4c8601ec8c");
  CHECK(hex64(1) == "0000000000000001");
}

TEST_CASE("scenes.json: caustic crops are validated") {
  auto m = parseBenchScenes(R"({"scenes": {"a": {"caustic": [0.1, 0.2, 0.3, 0.4], "note": "floor"},
                                           "b": {"caustic": null}, "c": {}}})",
                            "x.json");
  REQUIRE(m.size() == 3);
  REQUIRE(m["a"].caustic.has_value());
  CHECK(m["a"].caustic->y1 == doctest::Approx(0.4));
  CHECK(m["a"].note == "floor");
  CHECK(!m["b"].caustic.has_value());
  CHECK(!m["c"].caustic.has_value());
  CHECK_THROWS_WITH_AS(parseBenchScenes("{", "x.json"), doctest::Contains("x.json"), Error);
  CHECK_THROWS_AS(parseBenchScenes(R"({"scenes": {"a": {"caustic": [0.5, 0.2, 0.3, 0.4]}}})", "x.json"), Error);
  CHECK_THROWS_AS(parseBenchScenes(R"({"scenes": {"a": {"caustic": [0.1, 0.2, 1.3, 0.4]}}})", "x.json"), Error);
  CHECK_THROWS_AS(parseBenchScenes(R"({"scenes": {"a": {"caustic": [0.1, 0.2, 0.3]}}})", "x.json"), Error);
  CHECK_THROWS_AS(parseBenchScenes(R"({"scenes": []})", "x.json"), Error);
  CHECK(m["a"].referenceSpp == 0);
  CHECK(parseBenchScenes(R"({"scenes": {"a": {"reference_spp": 256}}})", "x.json")["a"].referenceSpp == 256);
  CHECK_THROWS_AS(parseBenchScenes(R"({"scenes": {"a": {"reference_spp": 255}}})", "x.json"), Error);
  CHECK_THROWS_AS(parseBenchScenes(R"({"scenes": {"a": {"reference_spp": 0}}})", "x.json"), Error);
  CHECK_THROWS_AS(parseBenchScenes(R"({"scenes": {"a": {"reference_spp": "many"}}})", "x.json"), Error);
}

TEST_CASE("bench/scenes.json covers every bundled scene and marks the glass caustic") {
  std::string path = sourceDir() + "/bench/scenes.json";
  REQUIRE(std::filesystem::exists(path));
  auto m = readBenchScenes(path);
  for (const auto& name : assetSceneNames()) CHECK_MESSAGE(m.count(name) == 1, name);
  REQUIRE(m.count("cornell-glass") == 1);
  CHECK(m["cornell-glass"].caustic.has_value());
  CHECK(!m["cornell-box"].caustic.has_value());  // diffuse only: no caustic
}

TEST_CASE("CSV rows have one field per header column, quoted where needed") {
  BenchRow r;
  r.scene = "cornell-glass";
  r.integrator = "mis";
  r.dispersion = "rgb";
  r.glRenderer = "llvmpipe (LLVM 15.0.6, 256 bits)";  // holds a comma
  r.width = 256;
  r.height = 256;
  r.seconds = 1.5;
  r.cpuSeconds = 2.75;
  r.spp = 12;
  r.relMse = 0.0123;
  r.relMseCaustic = std::nan("");
  auto header = splitCsv(benchCsvHeader());
  auto fields = splitCsv(benchCsvRow(r));
  REQUIRE(fields.size() == header.size());
  auto field = [&](const std::string& name) {
    for (size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return fields[i];
    FAIL("no column " << name);
    return std::string();
  };
  CHECK(field("scene") == "cornell-glass");
  CHECK(field("gl_renderer") == r.glRenderer);
  CHECK(std::stod(field("relmse")) == doctest::Approx(0.0123));
  CHECK(std::stod(field("seconds")) == doctest::Approx(1.5));
  CHECK(std::stod(field("cpu_seconds")) == doctest::Approx(2.75));
  CHECK(field("spp") == "12");
  CHECK(field("relmse_caustic") == "nan");

  std::string path = (std::filesystem::temp_directory_path() / "caustica_bench_metrics_test.csv").string();
  writeBenchCsv(path, {r, r});
  std::istringstream text(readFileText(path));
  std::string line;
  int lines = 0;
  while (std::getline(text, line)) ++lines;
  CHECK(lines == 3);
  std::filesystem::remove(path);
  CHECK_THROWS_AS(writeBenchCsv("/nonexistent-dir/x.csv", {r}), Error);
}

TEST_CASE("tile variance: per-sample relative variance per tile from a render's halves, weighted by a reference") {
  // 16x8 pixels, 64 samples each: 32 even ones of mean 1 + d and 32 odd ones (the half image) of mean
  // 1 - d, d = 0.1 on the left 8 columns and 0.4 on the right. Var(mean) = (2d)^2 / (1/32 + 1/32) / 64
  // = d^2, so the per-sample relative variance is 64 d^2 / (1 + 0.01) against a reference of 1, and
  // the bound over the 4x4 tiles mean(v) / mean(sqrt v)^2 = ((0.01 + 0.16) / 2) / ((0.1 + 0.4) / 2)^2.
  const int w = 16, h = 8;
  std::vector<float> accum(size_t(w) * h * 4, 0.0f), comp = accum, half = accum;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      const float d = x < w / 2 ? 0.1f : 0.4f;
      for (int c = 0; c < 3; ++c) {
        half[i * 4 + c] = 32.0f * (1.0f - d);
        accum[i * 4 + c] = half[i * 4 + c] + 32.0f * (1.0f + d);
      }
      half[i * 4 + 3] = 32.0f;
      accum[i * 4 + 3] = 64.0f;
    }
  const std::vector<double> v = tileRelVariance(accum, comp, half, constantImage(w, h, 1.0f), 4);
  REQUIRE(v.size() == size_t(4 * 2));
  for (int t = 0; t < 8; ++t) {
    const double d = t % 4 < 2 ? 0.1 : 0.4;
    CHECK(relDiff(v[size_t(t)], 64.0 * d * d / 1.01) < 1e-5);
  }
  CHECK(relDiff(adaptiveGainBound(v), (0.17 / 2.0) / (0.25 * 0.25)) < 1e-5);
  // The Kahan compensation is subtracted from the count: 32 of 64 leaves half A empty, the tile unknown.
  comp[3] = 32.0f;
  CHECK(std::isinf(tileRelVariance(accum, comp, half, constantImage(w, h, 1.0f), 4)[0]));
  CHECK_THROWS_AS(tileRelVariance(accum, comp, half, constantImage(w, h + 1, 1.0f), 4), Error);
}
