// transparent_test.cpp — --background transparent on llvmpipe: alpha 0 where the camera sees nothing,
// 1 on geometry and behind glass, the fraction of a pixel an edge covers, RGB unchanged against
// --background env where alpha is 1, PNG/EXR alpha read back, and a checkpoint round trip.
#include <doctest/doctest.h>

#include <stb_image.h>

#include <cmath>
#include <filesystem>

#include "cli/checkpoint.h"
#include "gl_test_util.h"
#include "util/error.h"

using namespace caustica;
using namespace caustica::test;

namespace {

// Camera at the origin looking down -Z with tan(yfov / 2) = 0.5: on the plane z = -2 the image spans
// x, y in [-1, 1], so pixel column c of a w-wide image starts at x = 2c / w - 1.
Camera frontCamera() { return cameraAt(glm::vec3(0.0f), glm::vec3(0, 0, -1), glm::vec3(0, 1, 0), 2.0f * std::atan(0.5f)); }

constexpr int kSize = 32;
// The diffuse wall's left edge crosses pixel column 20 at 0.3 of its width: that column is 70 % wall.
constexpr float kEdgeColumn = 20.3f;
constexpr float kEdgeX = 2.0f * kEdgeColumn / kSize - 1.0f;

// Under a uniform sky of radiance 1: a diffuse wall (albedo 0.5) on the right, x >= kEdgeX, at z = -2,
// and a glass ball (ior 1.5) on the left, centred on pixel (8, 16), radius 4 pixels, in front of nothing
// and behind the wall's plane (so no bounce off the wall's front reaches it).
Scene wallAndBall(Background::Kind background) {
  Scene s;
  s.path = "transparent test";
  s.materials = {diffuseMaterial(0.5f), glassMaterial(1.5f)};
  addQuad(s, {kEdgeX, -5.0f, -2.0f}, {5.0f, -5.0f, -2.0f}, {5.0f, 5.0f, -2.0f}, {kEdgeX, 5.0f, -2.0f}, 0);
  addSphere(s, {-1.0f, 0.0f, -4.0f}, 0.5f, 24, 1);
  finishBounds(s);
  s.environment = uniformEnvironment(glm::vec3(1.0f));
  s.background.kind = background;
  return s;
}

RenderSettings settings(Integrator integrator, std::uint32_t seed = 3) { return smallSettings(kSize, kSize, integrator, seed); }

float alphaAt(const Image& img, int x, int y) { return img.alpha[static_cast<size_t>(y) * img.width + x]; }

std::string tempFile(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("caustica-transparent-" + name)).string();
}

}  // namespace

TEST_CASE("transparent background: alpha 0 where the camera sees nothing, 1 on geometry and glass, edge fractions") {
  // naive: every wall sample is exactly 0.5 (its bounce sees only the sky), so the straight colour
  // rgb / alpha of an edge pixel is exactly the wall's whatever its coverage.
  const int spp = 256;
  RenderResult r = renderScene(wallAndBall(Background::Kind::Transparent), frontCamera(), settings(Integrator::Naive), spp, 64);
  REQUIRE(r.image.alpha.size() == static_cast<size_t>(kSize) * kSize);
  CHECK(r.stats.nonFinite == 0);
  bool hasDefine = false;
  for (const auto& d : r.defines) hasDefine |= d == "CAUSTICA_TRANSPARENT";
  CHECK(hasDefine);
  int sky = 0, wall = 0, off = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const float a = alphaAt(r.image, x, y);
      const bool nearBall = std::hypot(x + 0.5f - 8.0f, y + 0.5f - 16.0f) < 5.5f;
      if (x < 20 && !nearBall) {  // nothing there: alpha 0, radiance 0
        ++sky;
        off += a != 0.0f || r.image.at(x, y, 0) != 0.0f || r.image.at(x, y, 1) != 0.0f;
      } else if (x > 20) {  // the wall: alpha 1, radiance 0.5
        ++wall;
        off += a != 1.0f || r.image.at(x, y, 0) != 0.5f;
      }
    }
  CHECK(off == 0);
  CHECK(sky > 400);
  CHECK(wall > 300);
  // Inside the glass ball (within 2.5 px of its centre): every camera ray hits it, refracts and sees the
  // sky through it: alpha 1 and radiance near 1 (the environment through glass, not the background).
  for (int y = 13; y < 19; ++y)
    for (int x = 5; x < 11; ++x)
      if (std::hypot(x + 0.5f - 8.0f, y + 0.5f - 16.0f) < 2.5f) {
        INFO("ball pixel ", x, ",", y);
        CHECK(alphaAt(r.image, x, y) == 1.0f);
        CHECK(r.image.at(x, y, 1) > 0.9f);
      }
  // The edge column: 70 % of each pixel is wall. Per pixel alpha is binomial: sd sqrt(0.21 / 256) =
  // 0.029; over the 32 pixels of the column sd 0.0051; tolerance 4.5 sd = 0.023 (measured mean: see
  // the message; a coverage off by one sample in 16 would fail).
  double sumAlpha = 0;
  for (int y = 0; y < kSize; ++y) {
    const float a = alphaAt(r.image, 20, y);
    CHECK(a > 0.4f);
    CHECK(a < 0.95f);
    for (int c = 0; c < 3; ++c) CHECK(r.image.at(20, y, c) / a == doctest::Approx(0.5f).epsilon(1e-5));
    sumAlpha += a;
  }
  const double meanAlpha = sumAlpha / kSize, sd = std::sqrt(0.21 / spp / kSize);
  MESSAGE("edge column: mean alpha ", meanAlpha, " (covered fraction 0.7, sd ", sd, ")");
  CHECK(std::abs(meanAlpha - 0.7) <= 4.5 * sd);
  // The straight colour of the PNG is rgb / alpha; with no samples hitting, 0.
  std::vector<float> straight = unpremultiplied(r.image);
  CHECK(straight[(16 * kSize + 20) * 3] == doctest::Approx(0.5f).epsilon(1e-5));
  CHECK(straight[(16 * kSize + 2) * 3] == 0.0f);

  // Whitted mode tracks coverage too: the wall is opaque, the empty left half transparent.
  RenderSettings whitted = settings(Integrator::Naive);
  whitted.mode = RenderMode::Whitted;
  RenderResult wr = renderScene(wallAndBall(Background::Kind::Transparent), frontCamera(), whitted, 4);
  REQUIRE(wr.image.alpha.size() == r.image.alpha.size());
  CHECK(alphaAt(wr.image, 2, 2) == 0.0f);
  CHECK(alphaAt(wr.image, 28, 28) == 1.0f);
}

TEST_CASE("transparent background: RGB where alpha is 1 is the env background's, bit for bit (mis, same seed)") {
  // Coverage draws no random numbers, so a transparent render follows the same random stream as one
  // with --background env: pixels every camera ray of which hit something are identical; pixels that
  // hit nothing are 0 instead of the sky; the environment still lights the wall and fills the ball.
  RenderResult env = renderScene(wallAndBall(Background::Kind::Environment), frontCamera(), settings(Integrator::Mis), 16);
  RenderResult tr = renderScene(wallAndBall(Background::Kind::Transparent), frontCamera(), settings(Integrator::Mis), 16);
  CHECK(env.image.alpha.empty());
  REQUIRE(tr.image.alpha.size() == static_cast<size_t>(kSize) * kSize);
  int opaque = 0, clear = 0, off = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const float a = alphaAt(tr.image, x, y);
      for (int c = 0; c < 3; ++c) {
        if (a == 1.0f) off += tr.image.at(x, y, c) != env.image.at(x, y, c);
        if (a == 0.0f) off += tr.image.at(x, y, c) != 0.0f || env.image.at(x, y, c) != 1.0f;
      }
      opaque += a == 1.0f;
      clear += a == 0.0f;
    }
  CHECK(off == 0);
  CHECK(opaque > 300);
  CHECK(clear > 400);
}

TEST_CASE("transparent background: PNG holds straight alpha, EXR premultiplied RGB and A; PFM is refused") {
  RenderResult r = renderScene(wallAndBall(Background::Kind::Transparent), frontCamera(), settings(Integrator::Naive), 32);
  REQUIRE(!r.image.alpha.empty());
  const std::string png = tempFile("a.png"), exr = tempFile("a.exr");
  ToneMapSettings clampOnly;
  clampOnly.curve = ToneCurve::Clamp;
  writeImage(png, r.image, clampOnly);
  writeImage(exr, r.image);
  CHECK_THROWS_WITH_AS(writeImage(tempFile("a.pfm"), r.image), doctest::Contains("PFM has no alpha"), Error);

  int w = 0, h = 0, channels = 0;
  unsigned char* px = stbi_load(png.c_str(), &w, &h, &channels, 0);
  REQUIRE(px != nullptr);
  CHECK(channels == 4);
  REQUIRE(w == kSize);
  const std::uint8_t wallSrgb = tonemapImage({0.5f, 0.5f, 0.5f}, clampOnly)[0];  // 188
  int pngOff = 0;
  for (int i = 0; i < kSize * kSize; ++i) {
    const int expectedA = static_cast<int>(std::lround(r.image.alpha[i] * 255.0f));
    pngOff += px[i * 4 + 3] != expectedA;
    // Straight colour: a partly covered wall pixel keeps the wall's colour, not a darker one.
    if (r.image.alpha[i] > 0.0f && i % kSize >= 20) pngOff += std::abs(int(px[i * 4]) - int(wallSrgb)) > 1;
  }
  stbi_image_free(px);
  CHECK(pngOff == 0);

  const Image back = readImage(exr);  // OpenEXR: R, G, B and A
  REQUIRE(back.alpha.size() == r.image.alpha.size());
  int exrOff = 0;
  for (int i = 0; i < kSize * kSize; ++i) {
    exrOff += back.alpha[i] != r.image.alpha[i];
    for (int c = 0; c < 3; ++c) exrOff += back.rgb[i * 3 + c] != r.image.rgb[i * 3 + c];
  }
  CHECK(exrOff == 0);
  std::filesystem::remove(png);
  std::filesystem::remove(exr);
}

TEST_CASE("transparent background: a checkpoint keeps the coverage: 8 + 8 spp equals 16 spp bit for bit") {
  ShaderLibrary& library = testShaderLibrary();
  const Scene scene = wallAndBall(Background::Kind::Transparent);
  const RenderSettings rs = settings(Integrator::Mis, 5);
  Renderer straight(library, scene, frontCamera(), rs);
  straight.renderPass(16);
  const Image expected = straight.image();

  const std::string path = tempFile("resume.ckpt");
  {
    Renderer first(library, scene, frontCamera(), rs);
    first.renderPass(8);
    cli::Checkpoint ck;
    ck.state = first.saveAccumulation();
    CHECK(ck.state.coverage.size() == static_cast<size_t>(kSize) * kSize);
    ck.identity = cli::accumulationIdentity(cli::ImageSettings{rs}, frontCamera());
    cli::writeCheckpoint(path, ck);
  }
  Renderer second(library, scene, frontCamera(), rs);
  second.restoreAccumulation(cli::readCheckpoint(path).state);
  second.renderPass(8);
  const Image resumed = second.image();
  CHECK(resumed.rgb == expected.rgb);
  CHECK(resumed.alpha == expected.alpha);

  // An opaque checkpoint cannot continue a transparent render: the error says why.
  Renderer opaque(library, wallAndBall(Background::Kind::Environment), frontCamera(), rs);
  opaque.renderPass(2);
  CHECK_THROWS_WITH_AS(second.restoreAccumulation(opaque.saveAccumulation()), doctest::Contains("no coverage"), Error);
  std::filesystem::remove(path);
}
