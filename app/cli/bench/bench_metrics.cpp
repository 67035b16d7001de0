// bench_metrics.cpp — error metrics, checkpoint schedule, threshold times, batch sizes, hashing,
// bench/scenes.json parsing, CSV rows and number formatting for `caustica bench`.
#include "cli/bench/bench_metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "image/error_estimate.h"
#include "util/error.h"
#include "util/file_io.h"

namespace caustica {

namespace {

void checkSameSize(const Image& a, const Image& b, const char* what) {
  if (a.width != b.width || a.height != b.height)
    throw Error(std::string(what) + ": image is " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                " but the reference is " + std::to_string(b.width) + "x" + std::to_string(b.height));
  if (a.rgb.size() != static_cast<size_t>(a.width) * a.height * 3 || b.rgb.size() != a.rgb.size())
    throw Error(std::string(what) + ": image data does not match its size");
}

void checkRegion(const Image& a, const PixelRect& r, const char* what) {
  if (r.empty() || r.x0 < 0 || r.y0 < 0 || r.x1 > a.width || r.y1 > a.height)
    throw Error(std::string(what) + ": region [" + std::to_string(r.x0) + "," + std::to_string(r.y0) + ")-[" +
                std::to_string(r.x1) + "," + std::to_string(r.y1) + ") is empty or outside the " +
                std::to_string(a.width) + "x" + std::to_string(a.height) + " image");
}

std::string formatNumber(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

// Quotes a CSV field when it holds a separator, quote or line break (RFC 4180).
std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

}  // namespace

PixelRect fullImage(int width, int height) { return PixelRect{0, 0, width, height}; }

PixelRect cropToPixels(const CropRect& crop, int width, int height) {
  // Pixel i covers [i, i + 1) / size; its centre (i + 0.5) / size is inside when x0 <= centre < x1.
  auto lo = [](double t, int n) { return std::clamp(static_cast<int>(std::ceil(t * n - 0.5)), 0, n - 1); };
  auto hi = [](double t, int n) { return std::clamp(static_cast<int>(std::ceil(t * n - 0.5)), 0, n); };
  PixelRect r{lo(crop.x0, width), lo(crop.y0, height), hi(crop.x1, width), hi(crop.y1, height)};
  if (r.x1 <= r.x0) r.x1 = r.x0 + 1;  // a crop thinner than a pixel keeps the pixel it touches
  if (r.y1 <= r.y0) r.y1 = r.y0 + 1;
  return r;
}

double relMse(const Image& image, const Image& reference) {
  return relMse(image, reference, fullImage(reference.width, reference.height));
}

double relMse(const Image& image, const Image& reference, const PixelRect& region) {
  checkSameSize(image, reference, "relMSE");
  checkRegion(reference, region, "relMSE");
  double sum = 0.0;
  for (int y = region.y0; y < region.y1; ++y)
    for (int x = region.x0; x < region.x1; ++x)
      for (int c = 0; c < 3; ++c) {
        double r = reference.at(x, y, c), d = double(image.at(x, y, c)) - r;
        sum += d * d / (r * r + kRelMseEpsilon);
      }
  return sum / (3.0 * region.width() * region.height());
}

double referenceNoise(const Image& halfA, const Image& halfB) {
  return referenceNoise(halfA, halfB, fullImage(halfA.width, halfA.height));
}

double referenceNoise(const Image& halfA, const Image& halfB, const PixelRect& region) {
  checkSameSize(halfA, halfB, "reference noise");
  checkRegion(halfA, region, "reference noise");
  // A - M = (A - B) / 2, so mean((A - B)^2 / (M^2 + eps)) / 4 is the relMSE of A against M.
  return relMse(halfA, averageImages(halfA, halfB), region);
}

std::vector<double> tileRelVariance(const std::vector<float>& accum, const std::vector<float>& comp,
                                    const std::vector<float>& half, const Image& reference, int tileSize) {
  const size_t pixels = static_cast<size_t>(reference.width) * reference.height;
  if (tileSize < 1 || accum.size() != pixels * 4 || comp.size() != pixels * 4 || half.size() != pixels * 4)
    throw Error("tile variance: the render's images do not match the reference's size");
  const int tilesX = (reference.width + tileSize - 1) / tileSize, tilesY = (reference.height + tileSize - 1) / tileSize;
  std::vector<double> sum(static_cast<size_t>(tilesX) * tilesY, 0.0);
  std::vector<int> count(sum.size(), 0);
  for (int y = 0; y < reference.height; ++y)
    for (int x = 0; x < reference.width; ++x) {
      const size_t i = static_cast<size_t>(y) * reference.width + x;
      const double n = double(accum[i * 4 + 3]) - double(comp[i * 4 + 3]), nB = half[i * 4 + 3];
      double v = 0.0;
      for (int c = 0; c < 3; ++c) {
        const double total = double(accum[i * 4 + c]) - double(comp[i * 4 + c]), r = reference.at(x, y, c);
        v += pixelChannelVariance(total - half[i * 4 + c], n - nB, half[i * 4 + c], nB) * n / (r * r + kRelMseEpsilon);
      }
      const size_t t = static_cast<size_t>(y / tileSize) * tilesX + x / tileSize;
      sum[t] += v / 3.0;
      ++count[t];
    }
  for (size_t t = 0; t < sum.size(); ++t) sum[t] /= std::max(count[t], 1);
  return sum;
}

Image averageImages(const Image& a, const Image& b) {
  checkSameSize(a, b, "average");
  Image out{a.width, a.height, std::vector<float>(a.rgb.size())};
  for (size_t i = 0; i < a.rgb.size(); ++i) out.rgb[i] = 0.5f * (a.rgb[i] + b.rgb[i]);
  return out;
}

std::vector<double> checkpointSchedule(double first, double maxSeconds, int perOctave) {
  if (!(first > 0.0) || perOctave < 1 || !(maxSeconds > 0.0))
    throw Error("checkpoint schedule: needs first > 0, maxSeconds > 0 and perOctave >= 1");
  std::vector<double> t;
  for (int k = 0;; ++k) {
    double v = first * std::exp2(double(k) / perOctave);
    if (v >= maxSeconds * (1.0 - 1e-9)) break;  // maxSeconds itself is appended below
    t.push_back(v);
  }
  t.push_back(maxSeconds);
  return t;
}

ThresholdTime timeToThreshold(const std::vector<double>& seconds, const std::vector<double>& errors, double threshold) {
  ThresholdTime out;
  size_t n = std::min(seconds.size(), errors.size());
  bool havePrev = false;
  double prevT = 0.0, prevE = 0.0;
  for (size_t i = 0; i < n; ++i) {
    double t = seconds[i], e = errors[i];
    if (!(std::isfinite(t) && t > 0.0 && std::isfinite(e) && e > 0.0)) continue;
    if (e <= threshold) {
      if (!havePrev) return {ThresholdTime::Kind::AtFirst, t};
      // log e is linear in log t between the two checkpoints: solve for log e = log threshold.
      double le0 = std::log(prevE), le1 = std::log(e), lt0 = std::log(prevT), lt1 = std::log(t);
      double f = le1 == le0 ? 1.0 : (std::log(threshold) - le0) / (le1 - le0);
      return {ThresholdTime::Kind::Interpolated, std::exp(lt0 + f * (lt1 - lt0))};
    }
    havePrev = true;
    prevT = t;
    prevE = e;
  }
  if (havePrev) return {ThresholdTime::Kind::Extrapolated, prevT * prevE / threshold};
  return out;
}

std::string formatThresholdTime(const ThresholdTime& t) {
  char buf[64];
  const char* prefix = "";
  switch (t.kind) {
    case ThresholdTime::Kind::Unknown: return "n/a";
    case ThresholdTime::Kind::AtFirst: prefix = "<="; break;
    case ThresholdTime::Kind::Extrapolated: prefix = "~"; break;
    case ThresholdTime::Kind::Interpolated: break;
  }
  std::snprintf(buf, sizeof buf, "%s%.3g s", prefix, t.seconds);
  return buf;
}

double efficiency(double relMseValue, double seconds) {
  if (!(relMseValue > 0.0) || !(seconds > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return 1.0 / (relMseValue * seconds);
}

int nextBatchSpp(int sppSoFar, double elapsedSeconds, double targetSeconds, double maxDispatchSeconds) {
  if (sppSoFar <= 0) return 1;
  double sppPerSecond = sppSoFar / elapsedSeconds;
  double wanted = std::ceil((targetSeconds - elapsedSeconds) * sppPerSecond);
  double cap = std::max(1.0, std::floor(sppPerSecond * maxDispatchSeconds));
  return static_cast<int>(std::clamp(wanted, 1.0, cap));
}

std::string formatDouble(const char* printfFormat, double value) {
  char buf[64];
  std::snprintf(buf, sizeof buf, printfFormat, value);
  return buf;
}

std::string formatSci(double value) { return std::isfinite(value) ? formatDouble("%.3g", value) : "n/a"; }

std::map<std::string, BenchSceneInfo> parseBenchScenes(const std::string& jsonText, const std::string& fileName) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(jsonText);
  } catch (const nlohmann::json::exception& e) {
    throw Error(fileName + ": not valid JSON (" + e.what() + ")");
  }
  if (!j.is_object() || !j.contains("scenes") || !j["scenes"].is_object())
    throw Error(fileName + ": expected an object with a \"scenes\" object");
  std::map<std::string, BenchSceneInfo> out;
  for (const auto& [name, entry] : j["scenes"].items()) {
    const std::string where = fileName + ": scene '" + name + "'";
    if (!entry.is_object()) throw Error(where + " must be an object");
    BenchSceneInfo info;
    if (entry.contains("caustic") && !entry["caustic"].is_null()) {
      const auto& c = entry["caustic"];
      if (!c.is_array() || c.size() != 4) throw Error(where + ": \"caustic\" must be [x0, y0, x1, y1] or null");
      double v[4];
      for (int i = 0; i < 4; ++i) {
        if (!c[i].is_number()) throw Error(where + ": \"caustic\" values must be numbers");
        v[i] = c[i].get<double>();
        if (!(v[i] >= 0.0 && v[i] <= 1.0)) throw Error(where + ": \"caustic\" values must lie in [0, 1]");
      }
      if (!(v[0] < v[2] && v[1] < v[3])) throw Error(where + ": \"caustic\" needs x0 < x1 and y0 < y1");
      info.caustic = CropRect{v[0], v[1], v[2], v[3]};
    }
    if (entry.contains("note")) {
      if (!entry["note"].is_string()) throw Error(where + ": \"note\" must be a string");
      info.note = entry["note"].get<std::string>();
    }
    if (entry.contains("reference_spp")) {
      const auto& n = entry["reference_spp"];
      if (!n.is_number_integer() || n.get<long long>() < 2 || n.get<long long>() % 2 != 0 || n.get<long long>() > (1 << 24))
        throw Error(where + ": \"reference_spp\" must be an even integer from 2 to 16777216");
      info.referenceSpp = n.get<int>();
    }
    out[name] = info;
  }
  return out;
}

std::map<std::string, BenchSceneInfo> readBenchScenes(const std::string& path) {
  return parseBenchScenes(readFileText(path), path);
}

double imageMean(const Image& image, const PixelRect& r) {
  if (r.empty() || r.x0 < 0 || r.y0 < 0 || r.x1 > image.width || r.y1 > image.height)
    throw Error("internal: region outside the image");
  double s = 0.0;
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x)
      for (int c = 0; c < 3; ++c) s += image.at(x, y, c);
  return s / (3.0 * r.width() * r.height());
}

std::string benchCsvHeader() {
  return "scene,integrator,dispersion,width,height,checkpoint,seconds,spp,samples_per_s,rays_per_s,primary_rays,"
         "secondary_rays,shadow_rays,non_finite,relmse,relmse_caustic,reference_noise,reference_noise_caustic,"
         "gl_renderer,cpu_seconds,mean_ratio,mean_ratio_caustic,filter_seconds";
}

std::string benchCsvRow(const BenchRow& r) {
  std::ostringstream o;
  o << csvField(r.scene) << ',' << csvField(r.integrator) << ',' << csvField(r.dispersion) << ',' << r.width << ','
    << r.height << ',' << r.checkpoint << ',' << formatNumber(r.seconds) << ',' << r.spp << ','
    << formatNumber(r.samplesPerSecond) << ',' << formatNumber(r.raysPerSecond) << ',' << r.primaryRays << ','
    << r.secondaryRays << ',' << r.shadowRays << ',' << r.nonFinite << ',' << formatNumber(r.relMse) << ','
    << formatNumber(r.relMseCaustic) << ',' << formatNumber(r.referenceNoise) << ','
    << formatNumber(r.referenceNoiseCaustic) << ',' << csvField(r.glRenderer) << ',' << formatNumber(r.cpuSeconds) << ','
    << formatNumber(r.meanRatio) << ',' << formatNumber(r.meanRatioCaustic) << ',' << formatNumber(r.filterSeconds);
  return o.str();
}

void writeBenchCsv(const std::string& path, const std::vector<BenchRow>& rows) {
  std::ofstream f(path, std::ios::binary);
  if (!f) throw Error(path + ": cannot open for writing");
  f << benchCsvHeader() << '\n';
  for (const auto& r : rows) f << benchCsvRow(r) << '\n';
  f.flush();
  if (!f) throw Error(path + ": write failed");
}

}  // namespace caustica
