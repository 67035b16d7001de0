// punctual_test.cpp — KHR_lights_punctual on llvmpipe against analytic irradiance: a point light, a
// spot's cone falloff and a directional light over a diffuse plane (pixel = albedo / pi * E), and
// --light-radius spheres converging to the point-light image as the radius shrinks.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <functional>

#include "scene/punctual_lights.h"
#include "gl_test_util.h"

using namespace caustica;
using namespace caustica::test;

namespace {

constexpr float kAlbedo = 0.5f;
constexpr int kSize = 48;

// A diffuse plane y = 0 (albedo 0.5, 20 x 20) seen straight down from (0, 3, 0), 60 degrees field of view.
Scene planeScene() {
  Scene s;
  s.path = "plane";
  s.materials.push_back(diffuseMaterial(kAlbedo));
  addQuad(s, {-10, 0, 10}, {10, 0, 10}, {10, 0, -10}, {-10, 0, -10}, 0);
  finishBounds(s);
  return s;
}

Camera topCamera() {
  return cameraAt(glm::vec3(0.0f, 3.0f, 0.0f), glm::vec3(0.0f, -1.0f, 0.0f), glm::vec3(0.0f, 0.0f, -1.0f), 60.0f * kPi / 180.0f);
}

RenderSettings settings(Integrator integrator = Integrator::Mis, std::uint32_t seed = 1) {
  RenderSettings s = smallSettings(kSize, kSize, integrator, seed);
  s.maxDepth = 4;
  return s;
}

// The expected pixel value: the mean over an 8 x 8 grid inside the pixel of albedo / pi * E(p), p the
// point of the plane the eye ray through that spot of the pixel hits (the shader's box filter).
double expectedPixel(int x, int y, const std::function<double(const glm::dvec3&)>& irradiance) {
  const Camera c = topCamera();
  const double tanHalf = std::tan(0.5 * double(c.yfov));
  const glm::dvec3 fwd(c.forward), up(c.up), right = glm::normalize(glm::cross(fwd, up));
  double sum = 0.0;
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i) {
      const double nx = (x + (i + 0.5) / 8.0) / kSize * 2.0 - 1.0, ny = 1.0 - (y + (j + 0.5) / 8.0) / kSize * 2.0;
      const glm::dvec3 d = glm::normalize(fwd + nx * tanHalf * right + ny * tanHalf * up);
      const glm::dvec3 p = glm::dvec3(c.position) + d * (-double(c.position.y) / d.y);
      sum += irradiance(p);
    }
  return double(kAlbedo) / kPiD * sum / 64.0;
}

// Irradiance on the plane (normal +y) from a point or spot light of intensity I at `pos`.
double pointIrradiance(const glm::dvec3& p, const glm::dvec3& pos, double intensity) {
  const glm::dvec3 l = pos - p;
  const double d2 = glm::dot(l, l);
  return intensity * std::max(0.0, l.y / std::sqrt(d2)) / d2;
}

// Relative errors of channel `ch` against `expected` (per pixel): the largest over 4 x 4 pixel blocks
// (whose mean the pixel jitter disturbs less than one pixel) and that of the image mean.
void compare(const Image& img, int ch, const std::function<double(int, int)>& expected, double& maxRel, double& meanRel) {
  maxRel = 0.0;
  double sum = 0.0, sumRef = 0.0;
  for (int by = 0; by < kSize; by += 4)
    for (int bx = 0; bx < kSize; bx += 4) {
      double v = 0.0, ref = 0.0;
      for (int y = by; y < by + 4; ++y)
        for (int x = bx; x < bx + 4; ++x) {
          v += img.at(x, y, ch);
          ref += expected(x, y);
        }
      maxRel = std::max(maxRel, std::abs(v - ref) / (ref + 16e-3));
      sum += v;
      sumRef += ref;
    }
  meanRel = std::abs(sum - sumRef) / sumRef;
}

}  // namespace

TEST_CASE("punctual: a point light over a diffuse plane gives albedo / pi * I cos(theta) / d^2") {
  Scene s = planeScene();
  PunctualLight l;
  l.position = glm::vec3(0.3f, 1.0f, 0.2f);
  l.intensity = glm::vec3(2.0f);
  s.punctualLights.push_back(l);
  const glm::dvec3 pos(l.position);
  for (Integrator integrator : {Integrator::Mis, Integrator::Naive}) {  // delta lights: NEE in both
    CAPTURE(std::string(integratorName(integrator)));
    RenderResult r = renderScene(s, topCamera(), settings(integrator), 64);
    CHECK(std::find(r.defines.begin(), r.defines.end(), "CAUSTICA_PUNCTUAL") != r.defines.end());
    double maxRel = 0.0, meanRel = 0.0;
    compare(r.image, 1, [&](int x, int y) { return expectedPixel(x, y, [&](const glm::dvec3& p) { return pointIrradiance(p, pos, 2.0); }); },
            maxRel, meanRel);
    MESSAGE("point light, ", std::string(integratorName(integrator)), ": largest block error ", maxRel, ", mean error ", meanRel);
    // Only the pixel jitter is random here (the plane is lit directly, nothing bounces back): measured
    // max 0.3 %, mean 0.01 %; a 0.5 % bias of the mean fails.
    CHECK(maxRel < 0.01);
    CHECK(meanRel < 0.002);
    CHECK(r.stats.nonFinite == 0);
  }
}

TEST_CASE("punctual: several lights chosen by power sum to the analytic irradiance of all of them") {
  // Two point lights of very different power, a spot and a sun: the choice by power (binary search over
  // the cumulative probabilities in the UBO) divided by its probability must add up to the sum.
  Scene s = planeScene();
  PunctualLight a, b, spot, sun;
  a.position = glm::vec3(-0.6f, 0.8f, 0.3f);
  a.intensity = glm::vec3(0.5f);
  b.position = glm::vec3(0.7f, 1.5f, -0.4f);
  b.intensity = glm::vec3(4.0f);
  spot.type = PunctualType::Spot;
  spot.position = glm::vec3(0.0f, 1.2f, 0.8f);
  spot.direction = glm::normalize(glm::vec3(0.0f, -1.0f, -0.5f));
  spot.intensity = glm::vec3(30.0f);
  spot.innerCone = 0.2f;
  spot.outerCone = 0.5f;
  sun.type = PunctualType::Directional;
  sun.direction = glm::normalize(glm::vec3(0.4f, -1.0f, 0.1f));
  sun.intensity = glm::vec3(0.05f);  // power 0.05 pi r^2 = 31 with the plane's bounding radius 14
  s.punctualLights = {a, b, spot, sun};
  const auto irradiance = [&](const glm::dvec3& p) {
    const glm::dvec3 sp(spot.position), sd(spot.direction);
    const double cosAxis = glm::dot(glm::normalize(p - sp), sd);
    return pointIrradiance(p, glm::dvec3(a.position), 0.5) + pointIrradiance(p, glm::dvec3(b.position), 4.0) +
           pointIrradiance(p, sp, 30.0) * spotFalloff(float(cosAxis), std::cos(0.5f), std::cos(0.2f)) +
           0.05 * double(-sun.direction.y);
  };
  RenderResult r = renderScene(s, topCamera(), settings(), 4096, 256);
  double maxRel = 0.0, meanRel = 0.0;
  compare(r.image, 0, [&](int x, int y) { return expectedPixel(x, y, irradiance); }, maxRel, meanRel);
  MESSAGE("four lights: largest block error ", maxRel, ", mean error ", meanRel);
  // Noise of the light choice at 4096 spp: measured blocks 1.6 %, mean 0.025 %; a 0.5 % bias fails the mean.
  CHECK(maxRel < 0.04);
  CHECK(meanRel < 0.003);
}

TEST_CASE("punctual: a spot light's smooth cone falloff at angles inside, on and outside the cone") {
  Scene s = planeScene();
  PunctualLight l;
  l.type = PunctualType::Spot;
  l.position = glm::vec3(0.0f, 1.0f, 0.0f);
  l.direction = glm::vec3(0.0f, -1.0f, 0.0f);
  l.intensity = glm::vec3(3.0f, 1.5f, 0.75f);
  l.innerCone = 0.3f;
  l.outerCone = 0.6f;
  s.punctualLights.push_back(l);
  const glm::dvec3 pos(l.position);
  auto irradiance = [&](const glm::dvec3& p, double intensity) {
    const double cosAxis = glm::dot(glm::normalize(p - pos), glm::dvec3(0, -1, 0));
    return pointIrradiance(p, pos, intensity) * spotFalloff(float(cosAxis), std::cos(0.6f), std::cos(0.3f));
  };
  RenderResult r = renderScene(s, topCamera(), settings(), 1024, 64);
  double maxRel = 0.0, meanRel = 0.0;
  compare(r.image, 1, [&](int x, int y) { return expectedPixel(x, y, [&](const glm::dvec3& p) { return irradiance(p, 1.5); }); },
          maxRel, meanRel);
  MESSAGE("spot light: largest block error ", maxRel, ", mean error ", meanRel);
  // Measured at 1024 spp: blocks 1.1 % (the pixel jitter across the steep ramp), mean 0.014 %.
  CHECK(maxRel < 0.025);
  CHECK(meanRel < 0.002);
  // Region means by the angle of a pixel's centre from the spot axis: inside the inner cone, on the
  // ramp, near the outer edge, and the whole lit disc. Only the pixel jitter is random here (one delta
  // light, nothing to bounce off). Measured errors at 1024 spp over seeds 1-3: inner cone <= 0.012 %,
  // ramp <= 0.10 %, outer ramp (dim: falloff 0-10 %) <= 0.21 %, disc <= 0.02 %. Tolerances 0.25 %, the
  // outer ramp 0.5 %: a 0.5 % bias of any region's mean fails (seen: the reference's intensity 0.5 %
  // high failed the inner cone, ramp and disc).
  {
    const double tanHalfFov = std::tan(30.0 * kPiD / 180.0);
    struct Ring {
      const char* name;
      double lo, hi, tolerance;  // angles from the axis (rad); relative
    };
    for (const Ring& ring : {Ring{"inner cone", 0.0, 0.25, 0.0025}, Ring{"ramp", 0.35, 0.55, 0.0025},
                             Ring{"outer ramp", 0.5, 0.6, 0.005}, Ring{"lit disc", 0.0, 0.6, 0.0025}}) {
      double sum = 0.0, ref = 0.0;
      int n = 0;
      for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
          const double nx = (x + 0.5) / kSize * 2.0 - 1.0, ny = 1.0 - (y + 0.5) / kSize * 2.0;
          const double angle = std::atan(3.0 * tanHalfFov * std::hypot(nx, ny));  // plane 1 below the spot
          if (angle < ring.lo || angle >= ring.hi) continue;
          sum += r.image.at(x, y, 1);
          ref += expectedPixel(x, y, [&](const glm::dvec3& p) { return irradiance(p, 1.5); });
          ++n;
        }
      MESSAGE("spot region ", std::string(ring.name), " (", n, " pixels): ", sum / n, " expected ", ref / n, ", error ",
              100.0 * (sum / ref - 1.0), " %");
      CHECK(n > 20);
      CHECK(sum == Rel(ref, ring.tolerance));
    }
  }
  // Pixels along the image's +x axis at angles 0.2 (inside the inner cone), 0.45 (on the ramp) and
  // 0.7 rad (outside): the pixel centre's angle from the spot axis is atan(x_world / 1).
  const double tanHalf = std::tan(30.0 * kPiD / 180.0);
  for (double angle : {0.2, 0.45, 0.7}) {
    CAPTURE(angle);
    const double xw = std::tan(angle);                                  // on the plane, 1 below the spot
    const double ndc = xw / 3.0 / tanHalf;                              // seen from 3 above the plane
    const int px = int((ndc + 1.0) / 2.0 * kSize), py = kSize / 2;
    const double ref = expectedPixel(px, py, [&](const glm::dvec3& p) { return irradiance(p, 1.5); });
    MESSAGE("spot at ", angle, " rad: ", r.image.at(px, py, 1), " expected ", ref);
    CHECK(r.image.at(px, py, 1) == Rel(ref, 0.03, 1e-4));  // measured: 0.003 %, 1.2 %, exactly 0
    if (angle > 0.6) CHECK(ref < 1e-4);
    if (angle < 0.3) CHECK(ref > 0.05);
  }
}

TEST_CASE("punctual: a directional light gives albedo / pi * E cos(theta) everywhere") {
  Scene s = planeScene();
  PunctualLight l;
  l.type = PunctualType::Directional;
  l.direction = glm::normalize(glm::vec3(-0.3f, -1.0f, 0.2f));
  l.intensity = glm::vec3(3.0f);
  s.punctualLights.push_back(l);
  RenderResult r = renderScene(s, topCamera(), settings(), 4);
  const double expected = kAlbedo / kPiD * 3.0 * double(-l.direction.y);
  double lo = 1e30, hi = 0.0;
  for (float v : r.image.rgb) {
    lo = std::min(lo, double(v));
    hi = std::max(hi, double(v));
  }
  CHECK(lo == Rel(expected, 1e-4));  // no randomness at all: every sample is the same
  CHECK(hi == Rel(expected, 1e-4));
  // An occluder casts a hard shadow: a small quad at y = 1 hides the plane below it along the light.
  s.materials.push_back(diffuseMaterial(0.0f));
  addQuad(s, {-0.2f, 1, 0.2f}, {0.2f, 1, 0.2f}, {0.2f, 1, -0.2f}, {-0.2f, 1, -0.2f}, 1);
  Image img = renderScene(s, topCamera(), settings(), 4).image;
  // The shadow's centre: from (0, 1, 0) along the light's direction down to y = 0.
  const glm::dvec3 c = glm::dvec3(0, 1, 0) + glm::dvec3(l.direction) * (1.0 / -double(l.direction.y));
  const double tanHalf = std::tan(30.0 * kPiD / 180.0);
  const int px = int((c.x / 3.0 / tanHalf + 1.0) / 2.0 * kSize), py = int((c.z / 3.0 / tanHalf + 1.0) / 2.0 * kSize);
  CHECK(img.at(px, py, 0) == 0.0f);
  CHECK(img.at(2, 2, 0) == Rel(expected, 1e-4));
}

TEST_CASE("punctual: --light-radius spheres converge to the point and spot images as the radius shrinks") {
  // A uniformly glowing sphere of intensity I lights a plane above its horizon exactly as a point of
  // intensity I at its centre does, so the reference is the analytic irradiance of the point or spot
  // light (expectedPixel; the punctual lights' own images are tested above), not a render.
  for (PunctualType type : {PunctualType::Point, PunctualType::Spot}) {
    CAPTURE(std::string(punctualTypeName(type)));
    Scene base = planeScene();
    PunctualLight l;
    l.type = type;
    // Outside the camera's view (which would see the sphere itself), shining into it.
    l.position = glm::vec3(1.5f, 1.0f, 0.2f);
    l.direction = glm::normalize(glm::vec3(-0.8f, -1.0f, 0.0f));
    l.innerCone = 0.2f;
    l.outerCone = 0.8f;
    l.intensity = glm::vec3(2.0f);
    base.punctualLights.push_back(l);
    const glm::dvec3 pos(l.position), axis(l.direction);
    std::vector<double> ref(static_cast<size_t>(kSize) * kSize);
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x)
        ref[static_cast<size_t>(y) * kSize + x] = expectedPixel(x, y, [&](const glm::dvec3& p) {
          double e = pointIrradiance(p, pos, 2.0);
          if (type == PunctualType::Spot)
            e *= spotFalloff(float(glm::dot(glm::normalize(p - pos), axis)), std::cos(0.8f), std::cos(0.2f));
          return e;
        });
    // Regions: the image, and its half towards the light (x >= 24), the brighter one.
    auto regionErrors = [&](const Image& img) {
      std::array<double, 2> v{}, r{};
      for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x)
          for (int k = 0; k < 2; ++k)
            if (k == 0 || x >= kSize / 2) {
              v[k] += img.at(x, y, 0);
              r[k] += ref[static_cast<size_t>(y) * kSize + x];
            }
      // and the worst 16 x 16 block (the spot's cone edge, which a larger sphere blurs)
      double worst = 0.0;
      for (int by = 0; by < kSize; by += 16)
        for (int bx = 0; bx < kSize; bx += 16) {
          double a = 0.0, b = 0.0;
          for (int y = by; y < by + 16; ++y)
            for (int x = bx; x < bx + 16; ++x) {
              a += img.at(x, y, 0);
              b += ref[static_cast<size_t>(y) * kSize + x];
            }
          if (b > 1e-2 * 256) worst = std::max(worst, std::abs(a / b - 1.0));
        }
      return std::array<double, 3>{v[0] / r[0] - 1.0, v[1] / r[1] - 1.0, worst};
    };
    std::vector<std::array<double, 3>> errors;
    for (float radius : {0.2f, 0.02f}) {
      Scene s = base;
      applyLightRadius(s, radius);
      REQUIRE(s.punctualLights.empty());
      RenderResult r = renderScene(s, topCamera(), settings(), radius > 0.1f ? 128 : 1024, 64);
      if (type == PunctualType::Spot)
        CHECK(std::find(r.defines.begin(), r.defines.end(), "CAUSTICA_SPOT_EMITTERS") != r.defines.end());
      errors.push_back(regionErrors(r.image));
      MESSAGE(std::string(punctualTypeName(type)), " radius ", radius, ": error of the image mean ",
              100.0 * errors.back()[0], " %, of the half towards the light ", 100.0 * errors.back()[1],
              " %, worst 16 x 16 block ", 100.0 * errors.back()[2], " %");
    }
    // Radius 0.02 at 1024 spp (~9 s on llvmpipe), measured over seeds 1-3 (the noise of sampling a
    // point on the sphere, ~1.5 per sample, standard error ~0.1 % a region): image mean -0.18..-0.02 %,
    // lit half -0.22..-0.05 % (point and spot; the tessellated sphere may sit ~0.1 % low). Tolerance
    // 0.4 %: a 0.5 % bias of either region fails (seen: the reference 0.5 % high failed both regions of
    // both types, -0.52..-0.58 %). Radius 0.2 blurs the spot's cone: worst block 2.6-5.4 % off, 0.02:
    // 0.4-0.8 %.
    CHECK(std::abs(errors[1][0]) < 0.004);
    CHECK(std::abs(errors[1][1]) < 0.004);
    if (type == PunctualType::Spot) CHECK(errors[1][2] < errors[0][2]);
  }
}

TEST_CASE("punctual: naive and mis agree on --light-radius spheres, spot-shaped emission included") {
  // naive finds the spheres only by hitting them (emission weighted by the spot's falloff in the hit
  // direction); mis mostly by light sampling (the same falloff at the sampled point), with MIS weights.
  // Large spheres (radius 0.6, partly in view) so that naive, which finds them only by hitting them,
  // gets its noise down in seconds; the spot's falloff still varies across them, which both must weigh
  // alike.
  Scene s = planeScene();
  PunctualLight point, spot;
  point.position = glm::vec3(-1.5f, 0.8f, -0.3f);
  point.intensity = glm::vec3(1.0f);
  spot.type = PunctualType::Spot;
  spot.position = glm::vec3(1.5f, 1.0f, 0.2f);
  spot.direction = glm::normalize(glm::vec3(-0.8f, -1.0f, 0.0f));
  spot.intensity = glm::vec3(2.0f);
  spot.innerCone = 0.2f;
  spot.outerCone = 0.6f;
  s.punctualLights = {point, spot};
  applyLightRadius(s, 0.6f);
  // Four renders per estimator (other seeds) of 24 x 24, direct light only (~8 s in all on llvmpipe):
  // region means, and their standard errors from the spread. Measured with two seed sets: the image
  // (region 0) differs by 0.21 % and 0.06 %, standard error 0.10-0.11 %; the brighter top-left quarter
  // (region 1, the point light) by -0.08 % and 0.12 %, se 0.10-0.15 %. Tolerance 0.3 % for both (~3 se;
  // the seeds are fixed, so the run is repeatable): a 0.5 % bias fails (seen: mis scaled by 1.005 read
  // -0.44 % and -0.37 %; 4.5 se = 0.45 % had let it pass). The dim quarters
  // (2-4, se 0.25-1 %) only get 4.5 se + 0.3 % (their naive tail is heavy): they resolve ~2-4 %.
  const int size = 24, h = size / 2;
  const std::vector<std::array<int, 4>> regions = {{0, 0, size, size}, {0, 0, h, h}, {h, 0, size, h}, {0, h, h, size}, {h, h, size, size}};
  auto regionMeans = [&](Integrator integrator, int spp, std::uint32_t seed) {
    std::vector<std::vector<double>> per(regions.size());
    for (std::uint32_t k = 0; k < 4; ++k) {
      RenderSettings rs = settings(integrator, seed + k);
      rs.width = rs.height = size;
      rs.maxDepth = 2;  // direct light only: both estimators' noise and cost are there
      const Image img = renderScene(s, topCamera(), rs, spp, 256).image;
      for (size_t r = 0; r < regions.size(); ++r) {
        double sum = 0.0;
        for (int y = regions[r][1]; y < regions[r][3]; ++y)
          for (int x = regions[r][0]; x < regions[r][2]; ++x) sum += img.at(x, y, 0);
        per[r].push_back(sum / ((regions[r][2] - regions[r][0]) * (regions[r][3] - regions[r][1])));
      }
    }
    std::vector<std::pair<double, double>> out;  // mean, variance of the mean
    for (const auto& v : per) {
      double m = 0.0, var = 0.0;
      for (double x : v) m += x / 4.0;
      for (double x : v) var += (x - m) * (x - m) / 3.0;
      out.emplace_back(m, var / 4.0);
    }
    return out;
  };
  const auto naive = regionMeans(Integrator::Naive, 1024, 50), mis = regionMeans(Integrator::Mis, 512, 60);
  for (size_t r = 0; r < regions.size(); ++r) {
    const double se = std::sqrt(naive[r].second + mis[r].second);
    const double z = (naive[r].first - mis[r].first) / se;
    MESSAGE("region ", r, ": naive ", naive[r].first, " mis ", mis[r].first, ", difference ",
            100.0 * (naive[r].first / mis[r].first - 1.0), " %, standard error ", 100.0 * se / mis[r].first, " %, z = ", z);
    const double tolerance = r <= 1 ? 0.003 * mis[r].first : 4.5 * se + 0.003 * mis[r].first;
    CHECK(std::abs(naive[r].first - mis[r].first) <= tolerance);
  }
}
