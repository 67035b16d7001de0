// environment_sampling_test.cpp — the environment map's convention, its importance sampler against its
// pdf (chi-square), and reading .hdr maps (C++ twin of glsl/lib/environment.glsl; no GL).
#include "chi_square.h"
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <vector>

#include <stb_image_write.h>

#include "image/image_io.h"
#include "shading/environment_sampling.h"
#include "shading/sampling.h"
#include "util/error.h"

using namespace caustica;
using caustica::test::chiSquare;
using caustica::test::chiSquareLimit;

namespace {

// A w x h map: a sky gradient (brighter towards +Y, bluish), black below the horizon except a
// dim ground, and a 2x2-texel sun of radiance `sun` at texel (sx, sy).
Environment sunSky(int w, int h, int sx, int sy, float sun, float rotationDegrees = 0.0f) {
  Environment e;
  e.kind = Environment::Kind::Map;
  e.source = "test";
  e.width = w;
  e.height = h;
  e.rotationDegrees = rotationDegrees;
  e.rgb.resize(static_cast<size_t>(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float v = (y + 0.5f) / h;
      glm::vec3 c = v < 0.5f ? glm::vec3(0.3f, 0.5f, 1.0f) * (1.0f - v) : glm::vec3(0.05f * (x % 4 == 0));
      if ((x == sx || x == sx + 1) && (y == sy || y == sy + 1)) c = glm::vec3(sun);
      for (int k = 0; k < 3; ++k) e.rgb[(static_cast<size_t>(y) * w + x) * 3 + k] = c[k];
    }
  return e;
}

}  // namespace

TEST_CASE("environment convention: centre +X, a camera looking down -Z sees u = 0.25, +Y is the top row") {
  auto uv = [](glm::vec3 d, float deg = 0.0f) {
    float r = deg * kPi / 180.0f;
    return envDirectionToUv(glm::normalize(d), std::cos(r), std::sin(r));
  };
  CHECK(uv({1, 0, 0}).x == doctest::Approx(0.5).epsilon(1e-6));
  CHECK(uv({1, 0, 0}).y == doctest::Approx(0.5).epsilon(1e-6));
  CHECK(uv({0, 0, -1}).x == doctest::Approx(0.25).epsilon(1e-6));
  CHECK(uv({0, 0, 1}).x == doctest::Approx(0.75).epsilon(1e-6));
  CHECK(uv({0, 1, 0}).y == doctest::Approx(0.0).epsilon(1e-6));
  CHECK(uv({0, -1, 0}).y == doctest::Approx(1.0).epsilon(1e-6));
  // Rotated by +90 degrees about +Y (right-handed): what was at +X (u = 0.5) is now seen at -Z.
  CHECK(uv({0, 0, -1}, 90.0f).x == doctest::Approx(0.5).epsilon(1e-6));
  // uv -> direction -> uv round trip, with and without rotation.
  std::mt19937 gen(3);
  std::uniform_real_distribution<float> U(0.01f, 0.99f);
  for (int i = 0; i < 1000; ++i) {
    glm::vec2 a(U(gen), U(gen));
    float r = 0.7f * i;
    glm::vec3 d = envUvToDirection(a, std::cos(r), std::sin(r));
    CHECK(glm::length(d) == doctest::Approx(1.0).epsilon(1e-5));
    glm::vec2 b = envDirectionToUv(d, std::cos(r), std::sin(r));
    CHECK(std::abs(a.x - b.x) < 2e-5f);
    CHECK(std::abs(a.y - b.y) < 2e-5f);
  }
}

TEST_CASE("environment sampling: chi-square against its pdf; the pdf integrates to 1; sample and pdf agree") {
  for (float rotation : {0.0f, 30.0f}) {
    CAPTURE(rotation);
    const int w = 64, h = 32;
    EnvironmentDistribution d = buildEnvironmentDistribution(sunSky(w, h, 40, 9, 500.0f, rotation));
    // Bins: 2 x 2 texels. Expected bin probability from environmentPdf at texel centres: the density in
    // (u, v) is constant per texel, so pdf * 2 pi^2 sin(theta) at the centre times the texel's area is exact.
    const int bw = w / 2, bh = h / 2;
    std::vector<double> expected(static_cast<size_t>(bw) * bh, 0.0), observed(expected.size(), 0.0);
    double integral = 0.0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        glm::vec2 c((x + 0.5f) / w, (y + 0.5f) / h);
        glm::vec3 dir = envUvToDirection(c, d.cosRotation, d.sinRotation);
        double sinTheta = std::sqrt(std::max(0.0, 1.0 - double(dir.y) * dir.y));
        double p = environmentPdf(d, dir) * 2.0 * kPiD * kPiD * sinTheta / (double(w) * h);
        expected[static_cast<size_t>(y / 2) * bw + x / 2] += p;
        integral += p;
      }
    CHECK(integral == doctest::Approx(1.0).epsilon(1e-4));
    const int n = 400000;
    std::mt19937 gen(7);
    std::uniform_real_distribution<float> U(0.0f, 1.0f);
    int mismatched = 0;
    for (int i = 0; i < n; ++i) {
      glm::vec3 dir, le;
      float pdf;
      if (!sampleEnvironment(d, {U(gen), U(gen)}, dir, le, pdf)) continue;
      glm::vec2 uv = envDirectionToUv(dir, d.cosRotation, d.sinRotation);
      int x = std::min(int(uv.x * w), w - 1), y = std::min(int(uv.y * h), h - 1);
      observed[static_cast<size_t>(y / 2) * bw + x / 2] += 1.0;
      // The returned pdf and radiance are those of the direction (texel edges may round either way).
      float p2 = environmentPdf(d, dir);
      if (std::abs(p2 - pdf) > 1e-3f * pdf || environmentRadiance(d, dir) != le) ++mismatched;
    }
    CHECK(mismatched < n / 10000);
    for (double& e : expected) e *= n;
    int dof = 0;
    double chi = chiSquare(observed, expected, dof);
    CAPTURE(dof);
    CHECK(chi < chiSquareLimit(dof));
  }
}

TEST_CASE("environment sampling: the sun gets its share of samples; a uniform sky is sampled nearly uniformly") {
  const int w = 64, h = 32;
  Environment env = sunSky(w, h, 40, 9, 500.0f);
  EnvironmentDistribution d = buildEnvironmentDistribution(env);
  // Share of the sun's four texels in luminance x sin(theta), computed independently.
  double sun = 0.0, total = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float* t = &env.rgb[(size_t(y) * w + x) * 3];
      double f = luminance(glm::vec3(t[0], t[1], t[2])) * std::sin(kPiD * (y + 0.5) / h);
      total += f;
      if ((x == 40 || x == 41) && (y == 9 || y == 10)) sun += f;
    }
  std::mt19937 gen(11);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  int hits = 0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    glm::vec3 dir, le;
    float pdf;
    if (sampleEnvironment(d, {U(gen), U(gen)}, dir, le, pdf) && le.x == 500.0f) ++hits;
  }
  double share = sun / total;  // about 0.9
  CHECK(hits / double(n) == doctest::Approx(share).epsilon(4.0 * std::sqrt(share * (1 - share) / n) / share));

  EnvironmentDistribution u = buildEnvironmentDistribution(uniformEnvironment(glm::vec3(0.8f)));
  for (float y : {-0.99f, -0.5f, 0.0f, 0.3f, 0.9f}) {
    float pdf = environmentPdf(u, glm::normalize(glm::vec3(1.0f, y, 0.3f)));
    CHECK(pdf == doctest::Approx(1.0 / (4.0 * kPiD)).epsilon(0.02));  // 1-column map, 32 rows
    CHECK(environmentRadiance(u, glm::normalize(glm::vec3(1.0f, y, 0.3f))) == glm::vec3(0.8f));
  }
}

TEST_CASE("environment files: .hdr and .exr read with strength; bad input named; --env and --background text") {
  namespace fs = std::filesystem;
  fs::path p = fs::temp_directory_path() / "caustica_env_test.hdr";
  std::vector<float> px = {1.0f, 2.0f, 4.0f, 0.5f, 0.25f, 0.125f, 8.0f, 16.0f, 32.0f, 0.0f, 0.0f, 0.0f};
  REQUIRE(stbi_write_hdr(p.string().c_str(), 2, 2, 3, px.data()) != 0);
  Environment e = loadEnvironmentMap(p.string(), 2.0f, 15.0f);
  REQUIRE(e.width == 2);
  REQUIRE(e.height == 2);
  for (size_t i = 0; i < px.size(); ++i) CHECK(e.rgb[i] == doctest::Approx(2.0f * px[i]).epsilon(0.01));  // RGBE: 8-bit mantissa
  CHECK(e.emits());
  CHECK(e.rotationDegrees == 15.0f);
  CHECK(e.describe().find("2x2, strength 2, rotation 15 deg") != std::string::npos);

  // .exr through OpenEXR (linear float, no quantisation).
  fs::path exr = fs::temp_directory_path() / "caustica_env_test.exr";
  Image img{2, 2, px};
  writeImage(exr.string(), img);
  Environment x = loadEnvironmentMap(exr.string(), 0.5f);
  REQUIRE(x.width == 2);
  for (size_t i = 0; i < px.size(); ++i) CHECK(x.rgb[i] == 0.5f * px[i]);
  fs::remove(exr);

  fs::path bad = fs::temp_directory_path() / "caustica_env_bad.hdr";
  { std::FILE* f = std::fopen(bad.string().c_str(), "wb"); std::fputs("not an image", f); std::fclose(f); }
  CHECK_THROWS_WITH_AS(loadEnvironmentMap(bad.string()), doctest::Contains("caustica_env_bad.hdr: not a Radiance"), Error);
  CHECK_THROWS_WITH_AS(parseEnvironment("/nonexistent/sky.hdr", 1.0f, 0.0f), doctest::Contains("/nonexistent/sky.hdr"), Error);
  CHECK_THROWS_WITH_AS(parseEnvironment("sky.png", 1.0f, 0.0f), doctest::Contains("option --env needs"), Error);
  CHECK_THROWS_WITH_AS(parseEnvironment("1,2", 1.0f, 0.0f), doctest::Contains("option --env needs"), Error);
  CHECK_THROWS_WITH_AS(parseEnvironment("-1", 1.0f, 0.0f), doctest::Contains("option --env needs"), Error);
  CHECK(parseEnvironment("none", 1.0f, 0.0f).kind == Environment::Kind::None);
  CHECK(!parseEnvironment("0", 1.0f, 0.0f).emits());
  Environment u = parseEnvironment("0.5,1,2", 2.0f, 0.0f);
  CHECK(u.kind == Environment::Kind::Uniform);
  CHECK(u.uniform == glm::vec3(1.0f, 2.0f, 4.0f));
  CHECK(parseBackground("env").kind == Background::Kind::Environment);
  CHECK(parseBackground("transparent").kind == Background::Kind::Transparent);
  CHECK(parseBackground("0.2").color == glm::vec3(0.2f));
  CHECK_THROWS_WITH_AS(parseBackground("blue"), doctest::Contains("option --background needs"), Error);
  fs::remove(p);
  fs::remove(bad);
}
