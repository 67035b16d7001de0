// denoise_test.cpp — the denoiser's C++ twin (app/image/denoise.h) on synthetic sums: what must pass
// through unchanged does, noise goes where features agree, feature edges and bright features without
// one are kept, the output converges to the raw mean, the image keeps its energy; and the --aov images.
#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "image/denoise.h"
#include "shading/sampling.h"

using namespace caustica;

namespace {

// One pixel of a synthetic render: what every sample of it sees.
struct PixelTruth {
  glm::vec3 albedo{0.5f};
  glm::vec3 normal{0.0f, 0.0f, 1.0f};
  float depth = 2.0f;
};

// The renderer's sums (accum, albedo, normal images) of a w x h render with n samples per pixel, each
// sample's radiance drawn by `sample(x, y, rng)`.
struct Sums {
  int w, h;
  std::vector<float> accum, albedo, normal;
  DenoiseInput input() const { return DenoiseInput{w, h, &accum, &albedo, &normal}; }
};

Sums render(int w, int h, int n, const std::function<PixelTruth(int, int)>& truth,
            const std::function<glm::vec3(int, int, std::mt19937&)>& sample, unsigned seed = 1) {
  Sums s{w, h, std::vector<float>(size_t(w) * h * 4), std::vector<float>(size_t(w) * h * 4), std::vector<float>(size_t(w) * h * 4)};
  std::mt19937 rng(seed);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = (size_t(y) * w + x) * 4;
      const PixelTruth t = truth(x, y);
      for (int k = 0; k < n; ++k) {
        const glm::vec3 v = sample(x, y, rng);
        const float l = luminance(v);
        for (int c = 0; c < 3; ++c) {
          s.accum[i + c] += v[c];
          s.albedo[i + c] += t.albedo[c];
          s.normal[i + c] += t.normal[c];
        }
        s.accum[i + 3] += 1.0f;
        s.albedo[i + 3] += l * l;
        s.normal[i + 3] += t.depth;
      }
    }
  return s;
}

glm::vec3 meanAt(const std::vector<float>& sums, int w, int x, int y) {
  const size_t i = (size_t(y) * w + x) * 4;
  return glm::vec3(sums[i], sums[i + 1], sums[i + 2]) / sums[i + 3];
}

PixelTruth flat(int, int) { return PixelTruth{}; }

// Largest relative difference between the means of two sums images.
double maxRelDiff(const std::vector<float>& a, const std::vector<float>& b, int w, int h) {
  double worst = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const glm::vec3 u = meanAt(a, w, x, y), v = meanAt(b, w, x, y);
      for (int c = 0; c < 3; ++c) {
        double d = std::abs(double(u[c]) - v[c]) / std::max(std::abs(double(v[c])), 1e-30);
        worst = std::max(worst, d);
      }
    }
  return worst;
}

double meanLuminance(const std::vector<float>& sums, int w, int x0, int y0, int x1, int y1) {
  double s = 0.0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) s += luminance(meanAt(sums, w, x, y));
  return s / (double(x1 - x0) * (y1 - y0));
}

}  // namespace

TEST_CASE("denoiser: a constant image passes through unchanged, whatever its noise estimate") {
  // Every pixel's samples: the same colour, or two colours averaging to it (a variance, but equal means).
  for (bool noisy : {false, true}) {
    const Sums s = render(40, 30, 16, flat, [&](int, int, std::mt19937& g) {
      if (!noisy) return glm::vec3(0.3f, 0.5f, 0.7f);
      return g() % 2 ? glm::vec3(0.2f, 0.4f, 0.6f) : glm::vec3(0.4f, 0.6f, 0.8f);
    });
    // Make every pixel's sum the same (the noisy draws differ per pixel): copy the first pixel's sums.
    Sums c = s;
    for (size_t i = 0; i < c.accum.size(); ++i) {
      c.accum[i] = s.accum[i % 4];
      c.albedo[i] = s.albedo[i % 4];
    }
    const std::vector<float> out = denoiseSums(c.input());
    INFO((noisy ? "with a variance" : "noise-free"));
    // Demodulating and remodulating by the albedo and the residual passes round: measured 1.2e-7.
    CHECK(maxRelDiff(out, c.accum, c.w, c.h) <= 6e-7);
  }
}

TEST_CASE("denoiser: a noise-free image passes through unchanged (edges, textures, gradients)") {
  // Every sample of a pixel sees the same radiance: the variance of each mean is 0, so no neighbour that
  // differs gets any weight, however similar its features. Radiance: a gradient, a step and a texture.
  auto radiance = [](int x, int y) {
    float v = 0.1f + 0.01f * float(x) + (y > 15 ? 0.5f : 0.0f) + ((x / 3 + y / 3) % 2 ? 0.05f : 0.0f);
    return glm::vec3(v, 0.8f * v, 0.6f * v);
  };
  auto truth = [](int x, int y) {
    PixelTruth t;
    t.albedo = glm::vec3((x / 5) % 2 ? 0.8f : 0.3f);
    t.depth = 2.0f + 0.01f * float(y);
    return t;
  };
  const Sums s = render(32, 32, 16, truth, [&](int x, int y, std::mt19937&) { return radiance(x, y); });
  const std::vector<float> out = denoiseSums(s.input());
  CHECK(maxRelDiff(out, s.accum, s.w, s.h) <= 6e-7);  // float rounding only (measured 2.0e-7)
}

TEST_CASE("denoiser: the tap weight stops at normals, distances and luminance differences") {
  const float up[3] = {0, 0, 1}, side[3] = {1, 0, 0}, none[3] = {0, 0, 0};
  const float tilted[3] = {0.0f, std::sin(0.1f), std::cos(0.1f)};  // 5.7 degrees off
  CHECK(denoiseNormalWeight(up, up) == 1.0f);
  CHECK(denoiseNormalWeight(up, side) == 0.0f);
  CHECK(denoiseNormalWeight(none, none) == 1.0f);  // two pixels that saw no surface (sky)
  CHECK(denoiseNormalWeight(up, none) == 0.0f);
  CHECK(denoiseNormalWeight(up, tilted) == doctest::Approx(std::pow(std::cos(0.1f), 128.0f)).epsilon(1e-5));
  CHECK(denoiseTapWeight(up, up, 2.0f, 2.0f, 0.1f, 0.0f, 1.0f) == 1.0f);
  CHECK(denoiseTapWeight(up, up, 2.0f, 2.1f, 0.1f, 0.0f, 1.0f) == doctest::Approx(std::exp(-1.0f)).epsilon(1e-5));
  CHECK(denoiseTapWeight(up, up, 2.0f, 2.0f, 0.1f, -0.5f, 0.25f) == doctest::Approx(std::exp(-2.0f)).epsilon(1e-5));
}

TEST_CASE("denoiser: noise on a surface goes, its mean stays") {
  // A lit plane of radiance 0.5 with per-sample noise of standard deviation 0.5, 16 samples per pixel.
  const int w = 64, h = 64;
  const Sums s = render(w, h, 16, flat, [](int, int, std::mt19937& g) {
    const float v = 0.5f + 0.5f * std::normal_distribution<float>(0.0f, 1.0f)(g);
    return glm::vec3(v);
  });
  const std::vector<float> out = denoiseSums(s.input());
  double rawErr = 0.0, outErr = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      rawErr += std::pow(meanAt(s.accum, w, x, y).x - 0.5, 2.0);
      outErr += std::pow(meanAt(out, w, x, y).x - 0.5, 2.0);
    }
  INFO("MSE raw ", rawErr / (w * h), ", denoised ", outErr / (w * h));
  CHECK(outErr * 50.0 < rawErr);  // measured 1/400 of it
  // The residual passes give back what the filter moved: the mean is the raw one to float rounding.
  CHECK(meanLuminance(out, w, 0, 0, w, h) == doctest::Approx(meanLuminance(s.accum, w, 0, 0, w, h)).epsilon(1e-4));
}

TEST_CASE("denoiser: a feature edge keeps each side's radiance") {
  // Two walls meeting at x = 32 (normals 90 degrees apart), radiance 0.2 and 0.8, noisy.
  const int w = 64, h = 32;
  auto truth = [](int x, int) {
    PixelTruth t;
    t.normal = x < 32 ? glm::vec3(0, 0, 1) : glm::vec3(1, 0, 0);
    return t;
  };
  const Sums s = render(w, h, 16, truth, [](int x, int, std::mt19937& g) {
    return glm::vec3((x < 32 ? 0.2f : 0.8f) * (1.0f + 0.5f * std::normal_distribution<float>(0.0f, 1.0f)(g)));
  });
  const std::vector<float> out = denoiseSums(s.input());
  // The columns either side of the edge: a filter blind to the normal would bring them halfway (0.5).
  CHECK(meanLuminance(out, w, 31, 0, 32, h) == doctest::Approx(0.2).epsilon(0.02));
  CHECK(meanLuminance(out, w, 32, 0, 33, h) == doctest::Approx(0.8).epsilon(0.02));
}

TEST_CASE("denoiser: with many samples the output converges to the raw mean, also at a step without a feature edge") {
  // One plane, one albedo: radiance steps from 0.5 to 1.0 at x = 32 (a shadow edge, a caustic's rim: no
  // feature tells the filter) and has a gentle gradient. As the variance of each mean shrinks, the
  // denoised image must come within that noise of the raw one: mean((out - raw)^2 / var) stays bounded.
  // A filter without the variance term (sigmaLuminance huge) blurs the step at every sample count.
  const int w = 64, h = 16;
  auto value = [](int x, int y) { return (x < 32 ? 0.5f : 1.0f) + 0.002f * float(y); };
  auto score = [&](int n, const DenoiseSettings& settings) {
    const Sums s = render(w, h, n, flat, [&](int x, int y, std::mt19937& g) {
      return glm::vec3(value(x, y) * (1.0f + 0.5f * std::normal_distribution<float>(0.0f, 1.0f)(g)));
    });
    const std::vector<float> out = denoiseSums(s.input(), settings);
    double chi2 = 0.0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const double var = std::pow(0.5 * value(x, y), 2.0) / n;  // of the raw mean (known here)
        chi2 += std::pow(meanAt(out, w, x, y).x - meanAt(s.accum, w, x, y).x, 2.0) / var;
      }
    return chi2 / (w * h);
  };
  DenoiseSettings blind;
  blind.sigmaLuminance = 1e6f;
  for (int n : {64, 1024, 16384}) {
    INFO(n, " samples per pixel");
    // The filter removes most of each pixel's noise, so (out - raw)^2 is about the raw variance:
    // measured 0.90, 0.97 and 0.94.
    CHECK(score(n, DenoiseSettings{}) < 2.0);
    CHECK(score(n, blind) > 3.0);  // measured 5.6, 81 and 1275: the blurred step's bias does not shrink
  }
}

TEST_CASE("denoiser: a bright feature without a feature edge keeps its energy (a caustic's sparse samples)") {
  // A caustic on a floor: in a 12 x 12 patch, 1 sample in 10 carries radiance 9.1 (mean 1.0) over a floor
  // of 0.1 with mild noise; 16 samples per pixel. Its pixels' noise is too large for the filter to tell
  // them from the floor: it spreads them and takes some of the floor in; the residual passes put the light
  // it took back near where it was. Measured within the patch grown by 4 pixels (the whole patch's rim).
  const int w = 64, h = 64;
  auto inPatch = [](int x, int y) { return x >= 26 && x < 38 && y >= 26 && y < 38; };
  const Sums s = render(w, h, 16, flat, [&](int x, int y, std::mt19937& g) {
    const float floor = 0.1f * (1.0f + 0.3f * std::normal_distribution<float>(0.0f, 1.0f)(g));
    const bool hit = inPatch(x, y) && std::uniform_real_distribution<float>(0.0f, 1.0f)(g) < 0.1f;
    return glm::vec3(floor + (hit ? 9.0f : 0.0f));
  });
  const double raw = meanLuminance(s.accum, w, 22, 22, 42, 42);
  DenoiseSettings noResidual;
  noResidual.residualPasses = 0;
  const double kept = meanLuminance(denoiseSums(s.input()), w, 22, 22, 42, 42) / raw;
  const double lost = meanLuminance(denoiseSums(s.input(), noResidual), w, 22, 22, 42, 42) / raw;
  INFO("patch mean over the raw one: ", kept, " (without the residual passes ", lost, ")");
  CHECK(kept == doctest::Approx(1.0).epsilon(0.03));  // measured 0.982
  CHECK(lost < 0.95);  // measured 0.868: without them the filter darkens it
}

TEST_CASE("denoiser: the --aov feature images are the sums' means") {
  const Sums s = render(4, 3, 8, [](int x, int) {
    PixelTruth t;
    t.albedo = glm::vec3(0.1f * float(x), 0.5f, 0.9f);
    t.normal = glm::vec3(0, 1, 0);
    t.depth = 3.0f + float(x);
    return t;
  }, [](int x, int, std::mt19937& g) { return glm::vec3(g() % 2 ? 1.0f + float(x) : 3.0f + float(x)); });
  const FeatureImages f = featureImages(s.input());
  CHECK(f.albedo.at(2, 1, 0) == doctest::Approx(0.2f));
  CHECK(f.normal.at(3, 2, 1) == doctest::Approx(1.0f));
  CHECK(f.depth.at(1, 0, 2) == doctest::Approx(4.0f));
  // Samples of luminance 1 + x or 3 + x: the variance of the mean is the sample variance / n.
  const size_t i = 0;
  const float n = s.accum[i + 3], m = s.accum[i] / n, m2 = s.albedo[i + 3] / n;
  CHECK(f.variance.at(0, 0, 0) == doctest::Approx((m2 - m * m) / (n - 1.0f)).epsilon(1e-4));
  CHECK(f.variance.at(0, 0, 0) > 0.0f);
}
