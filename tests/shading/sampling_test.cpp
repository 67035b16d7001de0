// sampling_test.cpp — chi-square and moment tests of the C++ twins of the shader sampling routines.
#include "chi_square.h"
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "shading/sampling.h"

using namespace caustica;
using caustica::test::chiSquare;
using caustica::test::chiSquareLimit;

namespace {

}  // namespace

TEST_CASE("rand01 is uniform in [0,1)") {
  RngState s = rngSeed(7, 3, 1);
  const int n = 200000, bins = 64;
  std::vector<double> obs(bins, 0), exp(bins, double(n) / bins);
  for (int i = 0; i < n; ++i) {
    float u = rand01(s);
    REQUIRE(u >= 0.0f);
    REQUIRE(u < 1.0f);
    obs[static_cast<int>(u * bins)]++;
  }
  int dof = 0;
  double chi = chiSquare(obs, exp, dof);
  CHECK(chi < chiSquareLimit(dof));
}

TEST_CASE("different pixels, samples and seeds give different streams") {
  RngState a = rngSeed(1, 0, 1), b = rngSeed(2, 0, 1), c = rngSeed(1, 1, 1), d = rngSeed(1, 0, 2);
  CHECK(a != b);
  CHECK(a != c);
  CHECK(a != d);
  CHECK(rngSeed(1, 0, 1) == a);
}

TEST_CASE("cosine hemisphere sampling matches cos(theta)/pi (chi-square over theta x phi)") {
  const int nTheta = 10, nPhi = 20, n = 400000;
  std::vector<double> obs(nTheta * nPhi, 0), exp(nTheta * nPhi, 0);
  for (int i = 0; i < nTheta; ++i) {
    // Integral of cos/pi over a band in theta: (sin^2(t1) - sin^2(t0)) / 2, per phi bin a 1/nPhi share times 2pi/2pi.
    double t0 = (kPi / 2) * i / nTheta, t1 = (kPi / 2) * (i + 1) / nTheta;
    double p = (std::sin(t1) * std::sin(t1) - std::sin(t0) * std::sin(t0));
    for (int j = 0; j < nPhi; ++j) exp[i * nPhi + j] = n * p / nPhi;
  }
  RngState s = rngSeed(99, 0, 0);
  double sumCos = 0;
  for (int k = 0; k < n; ++k) {
    glm::vec3 d = sampleCosineHemisphere({rand01(s), rand01(s)});
    REQUIRE(std::abs(glm::length(d) - 1.0f) < 1e-4f);
    REQUIRE(d.z >= 0.0f);
    double theta = std::acos(std::min(1.0f, d.z));
    double phi = std::atan2(d.y, d.x);
    if (phi < 0) phi += 2 * kPi;
    int i = std::min(nTheta - 1, static_cast<int>(theta / (kPi / 2) * nTheta));
    int j = std::min(nPhi - 1, static_cast<int>(phi / (2 * kPi) * nPhi));
    obs[i * nPhi + j]++;
    sumCos += d.z;
  }
  int dof = 0;
  double chi = chiSquare(obs, exp, dof);
  CHECK(chi < chiSquareLimit(dof));
  CHECK(sumCos / n == doctest::Approx(2.0 / 3.0).epsilon(0.005));  // E[cos] = 2/3
}

TEST_CASE("orthonormal basis is orthonormal for any unit normal") {
  std::mt19937 g(3);
  std::normal_distribution<float> nd;
  for (int k = 0; k < 10000; ++k) {
    glm::vec3 n = glm::normalize(glm::vec3(nd(g), nd(g), nd(g)));
    if (k == 0) n = glm::vec3(0, 0, -1);
    if (k == 1) n = glm::vec3(0, 0, 1);
    glm::vec3 t, b;
    orthonormalBasis(n, t, b);
    REQUIRE(std::abs(glm::dot(t, n)) < 1e-5f);
    REQUIRE(std::abs(glm::dot(b, n)) < 1e-5f);
    REQUIRE(std::abs(glm::dot(t, b)) < 1e-5f);
    REQUIRE(std::abs(glm::length(t) - 1) < 1e-5f);
    REQUIRE(std::abs(glm::length(b) - 1) < 1e-5f);
  }
}

TEST_CASE("uniform triangle sampling is uniform over the (b1, b2) simplex") {
  // Grid of m x m cells in barycentric space: cells with i + j < m - 1 lie inside the simplex
  // (expected share 2/m^2), cells on the diagonal are half inside (1/m^2), the rest must stay empty.
  const int m = 8, n = 256000;
  std::vector<double> obs(m * m, 0), exp(m * m, 0);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) exp[i * m + j] = i + j < m - 1 ? 2.0 * n / (m * m) : (i + j == m - 1 ? double(n) / (m * m) : 0.0);
  RngState s = rngSeed(5, 0, 0);
  double m1 = 0, m2 = 0;
  for (int k = 0; k < n; ++k) {
    glm::vec2 b = sampleTriangleUniform({rand01(s), rand01(s)});
    REQUIRE(b.x >= 0.0f);
    REQUIRE(b.y >= 0.0f);
    REQUIRE(b.x + b.y <= 1.0f + 1e-6f);
    m1 += b.x;
    m2 += b.y;
    obs[std::min(m - 1, static_cast<int>(b.x * m)) * m + std::min(m - 1, static_cast<int>(b.y * m))]++;
  }
  std::vector<double> o, e;
  for (int c = 0; c < m * m; ++c) {
    if (exp[c] == 0.0) {
      CHECK(obs[c] <= 2.0);  // only float rounding on the diagonal edge may land here
      continue;
    }
    o.push_back(obs[c]);
    e.push_back(exp[c]);
  }
  int dof = 0;
  double chi = chiSquare(o, e, dof);
  CHECK(chi < chiSquareLimit(dof));
  CHECK(m1 / n == doctest::Approx(1.0 / 3.0).epsilon(0.01));
  CHECK(m2 / n == doctest::Approx(1.0 / 3.0).epsilon(0.01));
}

TEST_CASE("Fresnel: normal incidence, total internal reflection, reciprocity") {
  CHECK(fresnelDielectric(1.0f, 1.5f) == doctest::Approx(0.04).epsilon(1e-4));
  CHECK(fresnelDielectric(1.0f, 1.0f / 1.5f) == doctest::Approx(0.04).epsilon(1e-4));
  CHECK(fresnelDielectric(0.0f, 1.5f) == doctest::Approx(1.0));
  float critical = std::sqrt(1.0f - 1.0f / (1.5f * 1.5f));  // cos of the critical angle inside glass
  CHECK(fresnelDielectric(critical * 0.99f, 1.0f / 1.5f) == 1.0f);
  CHECK(fresnelDielectric(critical * 1.01f, 1.0f / 1.5f) < 1.0f);
  for (float cosI = 0.05f; cosI <= 1.0f; cosI += 0.05f) {
    float sinT = std::sqrt(1 - cosI * cosI) / 1.5f;
    float cosT = std::sqrt(1 - sinT * sinT);
    CHECK(fresnelDielectric(cosI, 1.5f) == doctest::Approx(fresnelDielectric(cosT, 1.0f / 1.5f)).epsilon(1e-4));
    CHECK(fresnelDielectric(cosI, 1.5f) >= 0.0f);
    CHECK(fresnelDielectric(cosI, 1.5f) <= 1.0f);
  }
}

TEST_CASE("dielectric sampling: reflects with probability F, refracts by Snell, scales radiance by 1/eta^2") {
  const glm::vec3 n(0, 0, 1);
  for (float eta : {1.5f, 1.0f / 1.5f, 2.4f}) {
    for (float cosI : {0.95f, 0.6f, 0.3f, 0.05f}) {
      glm::vec3 d = glm::normalize(glm::vec3(std::sqrt(1 - cosI * cosI), 0, -cosI));
      float f = fresnelDielectric(cosI, eta);
      RngState s = rngSeed(17, 0, 0);
      const int trials = 40000;
      int reflected = 0;
      for (int k = 0; k < trials; ++k) {
        glm::vec3 wi;
        bool transmitted;
        float w = sampleDielectric(d, n, eta, rand01(s), wi, transmitted);
        REQUIRE(std::isfinite(w));
        REQUIRE(std::abs(glm::length(wi) - 1.0f) < 1e-4f);
        if (!transmitted) {
          ++reflected;
          REQUIRE(w == 1.0f);
          REQUIRE(wi.z == doctest::Approx(cosI).epsilon(1e-4));
        } else {
          REQUIRE(wi.z < 0.0f);
          REQUIRE(w == doctest::Approx(1.0f / (eta * eta)));
          float sinI = std::sqrt(1 - cosI * cosI), sinT = std::sqrt(1 - wi.z * wi.z);
          REQUIRE(sinI == doctest::Approx(eta * sinT).epsilon(1e-3));  // n_i sin_i = n_t sin_t
          REQUIRE(wi.x >= 0.0f);  // stays in the plane of incidence, forward
        }
      }
      double p = double(reflected) / trials, sigma = std::sqrt(f * (1 - f) / trials) + 1e-6;
      INFO("eta ", eta, " cosI ", cosI);
      CHECK(std::abs(p - f) < 5 * sigma + 1e-4);
    }
  }
}

TEST_CASE("Cauchy fit reproduces the index at the d line and the Abbe number") {
  for (float ior : {1.33f, 1.5f, 1.9f})
    for (float abbe : {20.0f, 40.0f, 64.0f}) {
      CHECK(cauchyIor(ior, abbe, 587.6f) == doctest::Approx(ior).epsilon(1e-5));
      float nF = cauchyIor(ior, abbe, 486.1f), nC = cauchyIor(ior, abbe, 656.3f);
      CHECK((ior - 1.0f) / (nF - nC) == doctest::Approx(abbe).epsilon(1e-3));
      CHECK(cauchyIor(ior, abbe, 450.0f) > cauchyIor(ior, abbe, 650.0f));  // normal dispersion
    }
  CHECK(cauchyIor(1.5f, 0.0f, 400.0f) == 1.5f);  // no dispersion
}

TEST_CASE("channel sensitivities integrate to 1 over the visible range") {
  glm::dvec3 sum(0.0);
  const int n = 4000;
  for (int i = 0; i < n; ++i) sum += glm::dvec3(channelSensitivity(380.0f + 400.0f * (i + 0.5f) / n)) * (400.0 / n);
  CHECK(sum.x == doctest::Approx(1.0).epsilon(1e-3));
  CHECK(sum.y == doctest::Approx(1.0).epsilon(1e-3));
  CHECK(sum.z == doctest::Approx(1.0).epsilon(1e-3));
}

TEST_CASE("power heuristic weights of two techniques sum to one") {
  for (float a : {0.0f, 0.1f, 1.0f, 30.0f})
    for (float b : {0.01f, 1.0f, 7.0f}) CHECK(powerHeuristic(a, b) + powerHeuristic(b, a) == doctest::Approx(1.0f));
  CHECK(powerHeuristic(INFINITY, 3.0f) == 1.0f);
  CHECK(powerHeuristic(0.0f, 0.0f) == 0.0f);
  // Pdfs whose square overflows a float (tiny lights, grazing angles) still give finite weights.
  CHECK(powerHeuristic(1e20f, 1.0f) == 1.0f);
  CHECK(powerHeuristic(1.0f, 1e20f) == doctest::Approx(0.0f));
  CHECK(powerHeuristic(3e19f, 3e19f) == doctest::Approx(0.5f));
}

TEST_CASE("uniform cone sampling: every direction inside, cos(theta) uniform over [cos max, 1]") {
  glm::vec3 axis = glm::normalize(glm::vec3(0.3f, -0.5f, 0.8f));
  glm::vec4 sphere(glm::vec3(0.0f) + 2.0f * axis, 0.7f);  // seen from the origin
  glm::vec3 a;
  float omc = 0;
  REQUIRE(casterCone(glm::vec3(0.0f), axis, sphere, a, omc));
  float cosMax = 1.0f - omc;
  CHECK(glm::length(a - axis) < 1e-5f);
  CHECK(cosMax == doctest::Approx(std::sqrt(1.0 - 0.49 / 4.0)).epsilon(1e-5));
  CHECK(omc == doctest::Approx(1.0 - std::sqrt(1.0 - 0.49 / 4.0)).epsilon(1e-4));
  const int bins = 16, n = 160000;
  std::vector<double> obs(bins, 0), exp(bins, n / double(bins));
  RngState s = rngSeed(5, 0, 0);
  for (int k = 0; k < n; ++k) {
    glm::vec3 d = sampleUniformCone(a, omc, {rand01(s), rand01(s)});
    float c = glm::dot(d, a);
    REQUIRE(c >= cosMax - 1e-5f);
    obs[std::min(bins - 1, static_cast<int>((1.0f - c) / omc * bins))]++;
  }
  int dof = 0;
  double chi = chiSquare(obs, exp, dof);
  CHECK(chi < chiSquareLimit(dof));
}

TEST_CASE("casters: inside a sphere or with the cone below the horizon a caster is not usable") {
  glm::vec3 axis, n(0, 1, 0);
  float omc;
  CHECK_FALSE(casterCone(glm::vec3(0.0f), n, glm::vec4(0.1f, 0.0f, 0.0f, 0.5f), axis, omc));  // inside
  CHECK_FALSE(casterCone(glm::vec3(0.0f), n, glm::vec4(0.0f, -2.0f, 0.0f, 0.5f), axis, omc));  // below
  CHECK(casterCone(glm::vec3(0.0f), n, glm::vec4(2.0f, -0.4f, 0.0f, 0.5f), axis, omc));        // straddles
}

namespace {
// Checks one diffuse vertex: the mixture pdf integrates to 1 over the sphere, and the sampler draws
// from that pdf (E[g / pdf] = integral of g for g = cos/pi on the hemisphere and for g = cos/pi on
// each usable cone, whose projected solid angle is known in closed form when above the horizon).
void checkMixture(const glm::vec3& p, const glm::vec3& n, const std::vector<glm::vec4>& spheres, float a,
                  std::uint32_t expectUsable, bool narrow = false) {
  RngState s = rngSeed(17, 0, 0);
  CasterVertex v = prepareCasters(p, n, 0.5f, spheres.data(), static_cast<std::uint32_t>(spheres.size()), 0u, glm::vec4(0.0f), 0.0f);
  REQUIRE(v.usable == expectUsable);
  const int m = 400000;
  if (!narrow) {  // integral of the pdf over the sphere, by uniform directions (too few hit a narrow cone)
    double integral = 0;
    for (int k = 0; k < m; ++k) {
      float z = 1.0f - 2.0f * rand01(s), phi = 2.0f * kPi * rand01(s), r = std::sqrt(std::max(0.0f, 1.0f - z * z));
      integral += diffuseDirectionPdf(v, a, n, glm::vec3(r * std::cos(phi), r * std::sin(phi), z)) * 4.0 * kPi;
    }
    CHECK(integral / m == doctest::Approx(1.0).epsilon(0.01));
  }
  // Every direction drawn from a cone lies in it, even at the rim of a narrow cone.
  for (std::uint32_t k = 0; k < v.usable; ++k)
    for (int j = 0; j < 20000; ++j) {
      glm::vec3 d = sampleUniformCone(v.axis[k], v.oneMinusCos[k], {rand01(s), rand01(s)});
      REQUIRE(inCone(d, v.axis[k], v.oneMinusCos[k]));
    }
  // Sampler against pdf. Picks are redrawn per sample, as in the shader.
  double hemi = 0, cone0 = 0;
  for (int k = 0; k < m; ++k) {
    CasterVertex w = prepareCasters(p, n, rand01(s), spheres.data(), static_cast<std::uint32_t>(spheres.size()), 0u, glm::vec4(0.0f), 0.0f);
    float uPick = rand01(s);
    glm::vec3 d = sampleDiffuseDirection(w, a, n, uPick, {rand01(s), rand01(s)});
    REQUIRE(std::abs(glm::length(d) - 1.0f) < 1e-4f);
    float cosN = glm::dot(d, n);
    if (cosN <= 0.0f) continue;
    double pdf = diffuseDirectionPdf(w, a, n, d);
    REQUIRE(pdf > 0.0);
    hemi += cosN / kPi / pdf;
    if (v.usable > 0 && inCone(d, v.axis[0], v.oneMinusCos[0])) cone0 += cosN / kPi / pdf;
  }
  CHECK(hemi / m == doctest::Approx(1.0).epsilon(0.01));
  if (v.usable > 0) {
    // Projected solid angle of a cone fully above the horizon: pi sin^2(half angle) cos(axis angle).
    float sin2 = v.oneMinusCos[0] * (2.0f - v.oneMinusCos[0]);
    float cosAxis = glm::dot(v.axis[0], n);
    if (std::acos(cosAxis) + std::asin(std::sqrt(sin2)) < kPi / 2)
      CHECK(cone0 / m == doctest::Approx(sin2 * cosAxis).epsilon(0.02));
  }
}
}  // namespace

TEST_CASE("diffuse directions mixed with caster cones: pdf integrates to 1 and matches the sampler") {
  glm::vec3 n(0, 1, 0);
  SUBCASE("no caster: pure cosine") { checkMixture(glm::vec3(0.0f), n, {}, 0.5f, 0); }
  SUBCASE("one caster above") { checkMixture(glm::vec3(0.0f), n, {glm::vec4(0.3f, 0.7f, 0.1f, 0.3f)}, 0.5f, 1); }
  SUBCASE("two overlapping casters and one straddling the horizon") {
    checkMixture(glm::vec3(0.0f), n,
                 {glm::vec4(0.3f, 0.7f, 0.1f, 0.3f), glm::vec4(0.45f, 0.8f, 0.1f, 0.25f), glm::vec4(2.0f, 0.1f, 0.0f, 0.4f)},
                 0.7f, 3);
  }
  SUBCASE("a narrow cone (half angle 0.4 degrees)") {
    checkMixture(glm::vec3(0.0f), n, {glm::vec4(0.6f, 1.2f, 0.3f, 0.01f)}, 0.5f, 1, true);
  }
  SUBCASE("a cone too narrow to aim at (half angle 0.06 degrees) is skipped") {
    checkMixture(glm::vec3(0.0f), n, {glm::vec4(0.0f, 3.0f, 0.0f, 0.003f)}, 0.5f, 0);
  }
  SUBCASE("a caster behind the surface is skipped") {
    checkMixture(glm::vec3(0.0f), n, {glm::vec4(0.0f, -1.0f, 0.0f, 0.3f), glm::vec4(0.0f, 1.0f, 0.5f, 0.2f)}, 0.5f, 1);
  }
}

TEST_CASE("refractive casters are aimed at only from where they overlap the lights") {
  glm::vec3 p(0.0f), n(0, 1, 0);
  glm::vec4 lights(0.0f, 2.0f, 0.0f, 0.2f);
  glm::vec4 above(0.0f, 1.0f, 0.0f, 0.1f), aside(1.0f, 0.5f, 0.0f, 0.1f), grazing(0.0f, 1.0f, 0.3f, 0.1f);
  glm::vec3 axis;
  float omc;
  REQUIRE(casterCone(p, n, above, axis, omc));
  CHECK(casterFacesLights(p, axis, omc, lights, 0.0f));  // straight between p and the light
  REQUIRE(casterCone(p, n, aside, axis, omc));
  CHECK_FALSE(casterFacesLights(p, axis, omc, lights, 0.0f));  // 63 degrees off the light
  CHECK(casterFacesLights(p, axis, omc, lights, 1.2f));          // unless the margin allows it
  // Cone edges: the caster's half angle (5.7 deg) + the lights' (5.7 deg) against the angle between axes.
  REQUIRE(casterCone(p, n, grazing, axis, omc));
  float between = std::acos(glm::dot(axis, glm::vec3(0, 1, 0)));  // 16.7 deg
  CHECK(between > std::asin(0.1f / glm::length(glm::vec3(grazing))) + std::asin(0.1f));
  CHECK_FALSE(casterFacesLights(p, axis, omc, lights, 0.0f));
  CHECK(casterFacesLights(p, axis, omc, lights, 0.1f));
  CHECK(casterFacesLights(p, axis, omc, glm::vec4(0.0f, 0.0f, 0.0f, 3.0f), 0.0f));   // p inside the lights' sphere
  CHECK_FALSE(casterFacesLights(p, axis, omc, glm::vec4(0.0f, 0.0f, 0.0f, -1.0f), 0.0f));  // no emitters
  // In prepareCasters the test applies to refractive casters (mask bit set) only.
  glm::vec4 spheres[2] = {above, aside};
  CHECK(prepareCasters(p, n, 0.5f, spheres, 2, 0u, lights, 0.0f).usable == 2);  // mirrors: both
  CasterVertex v = prepareCasters(p, n, 0.9f, spheres, 2, 3u, lights, 0.0f);     // glass: only `above`
  REQUIRE(v.usable == 1);
  CHECK(glm::length(v.axis[0] - glm::vec3(0, 1, 0)) < 1e-5f);
  CHECK(prepareCasters(p, n, 0.5f, spheres, 2, 2u, lights, 0.0f).usable == 1);  // `aside` glass, `above` mirror
  // The aim mask (aimCasterMask: unguided mirrors out) removes a caster's cone whatever else holds.
  CasterVertex only = prepareCasters(p, n, 0.5f, spheres, 2, 0u, lights, 0.0f, nullptr, 0.0f, 2u);
  REQUIRE(only.usable == 1);
  CHECK(glm::length(only.axis[0] - glm::normalize(glm::vec3(aside) - p)) < 1e-5f);
  CHECK(prepareCasters(p, n, 0.5f, spheres, 2, 0u, lights, 0.0f, nullptr, 0.0f, 0u).usable == 0);
}

TEST_CASE("the caster pick is uniform over the usable casters") {
  glm::vec4 spheres[4] = {{0.0f, 1.0f, 0.0f, 0.1f}, {0.5f, 1.0f, 0.0f, 0.1f}, {0.0f, -1.0f, 0.0f, 0.1f}, {-0.5f, 1.0f, 0.0f, 0.1f}};
  std::vector<double> obs(3, 0), exp(3, 30000.0 / 3);
  RngState s = rngSeed(3, 0, 0);
  for (int k = 0; k < 30000; ++k) {
    CasterVertex v = prepareCasters(glm::vec3(0.0f), glm::vec3(0, 1, 0), rand01(s), spheres, 4, 0u, glm::vec4(0.0f), 0.0f);
    REQUIRE(v.usable == 3);  // the one below the surface is skipped
    obs[v.pick]++;
  }
  int dof = 0;
  double chi = chiSquare(obs, exp, dof);
  CHECK(chi < chiSquareLimit(dof));
}

namespace {
// A guide cell as the guide photon pass leaves it: `count` photons whose directions sum to count times
// meanDir (mean resultant length |meanDir|), each rounded to kCellDirScale units as int bits.
glm::uvec4 guideCell(std::uint32_t count, const glm::vec3& meanDir) {
  glm::ivec3 d(glm::round(meanDir * static_cast<float>(count) * gpu::kCellDirScale));
  return glm::uvec4(count, glm::uvec3(d));
}
}  // namespace

TEST_CASE("vmfOneMinusCos draws 1 - cos theta from the lobe whose density vmfNorm gives, kappa 0.01 to 1e4") {
  RngState s = rngSeed(29, 0, 0);
  const int m = 4000000, bins = 32;
  for (float kappa : {0.01f, 0.1f, 1.0f, 10.0f, 200.0f, 1.0e3f, 1.0e4f}) {
    CAPTURE(kappa);
    // Finite everywhere: u at both ends, where u + (1 - u) exp(-2 kappa) reaches 0 or rounds to 1.
    for (float u : {0.0f, 1.0e-30f, 1.0e-7f, 0.5f, 0.99999994f}) {
      float t = vmfOneMinusCos(kappa, u);
      CHECK((t >= 0.0f && t <= 2.0f));
    }
    double norm = vmfNorm(kappa);
    REQUIRE(std::isfinite(norm));
    REQUIRE(norm > 0.0);
    // 4e6 samples: a 0.5 % error in vmfNorm (total 1.005, chi-square 120-147 of limit 80) or in
    // vmfOneMinusCos (chi-square 100-3176) fails at every kappa.
    // Bins of equal probability under the exact distribution of t = 1 - cos theta (double); the expected
    // count of each from the density vmfNorm(kappa) exp(-kappa t) per steradian, integrated in closed form
    // over the bin (dw = dt dphi): a wrong norm shows in both the chi-square and the total.
    std::vector<double> edge(bins + 1), obs(bins, 0), exp(bins);
    double k = kappa, tail = -std::expm1(-2.0 * k);
    for (int i = 0; i <= bins; ++i) edge[i] = i == bins ? 2.0 : -std::log1p(-tail * i / bins) / k;
    double total = 0;
    for (int i = 0; i < bins; ++i) {
      exp[i] = m * 2.0 * kPi * norm * (std::exp(-k * edge[i]) - std::exp(-k * edge[i + 1])) / k;
      total += exp[i] / m;
    }
    CHECK(total == doctest::Approx(1.0).epsilon(2e-5));  // float norm: cancellation in 1 - exp(-2 kappa) at kappa 0.01
    int bad = 0;
    for (int j = 0; j < m; ++j) {
      double t = vmfOneMinusCos(kappa, rand01(s));
      if (!(t >= 0.0 && t <= 2.0)) {
        ++bad;
        continue;
      }
      obs[static_cast<size_t>(std::upper_bound(edge.begin() + 1, edge.end() - 1, t) - edge.begin() - 1)]++;
    }
    CHECK(bad == 0);
    int dof = 0;
    double chi = chiSquare(obs, exp, dof);
    CHECK(chi < chiSquareLimit(dof));
  }
}

TEST_CASE("guideLobe: a vMF about the photons' mean direction, none from too few photons or from below") {
  glm::vec3 n(0, 1, 0), axis;
  float kappa;
  glm::vec3 dir = glm::normalize(glm::vec3(0.3f, 0.8f, -0.2f));
  REQUIRE(guideLobe(guideCell(5000, 0.995f * dir), n, axis, kappa));
  CHECK(glm::length(axis - dir) < 1e-5f);
  CHECK(kappa == doctest::Approx(0.995 * (3.0 - 0.995 * 0.995) / (1.0 - 0.995 * 0.995)).epsilon(1e-3));  // 200.5
  REQUIRE(guideLobe(guideCell(kMinGuidePhotons, 1.0f * dir), n, axis, kappa));
  // All photons from one direction: the narrowest lobe (r clamped to 0.9999: kappa 9998 in float, under the cap).
  CHECK((kappa > 9990.0f && kappa <= kMaxGuideKappa));
  CHECK_FALSE(guideLobe(guideCell(kMinGuidePhotons - 1, 0.9f * dir), n, axis, kappa));  // too few
  CHECK_FALSE(guideLobe(guideCell(100, 0.5f * glm::vec3(0, -0.6f, 0.8f)), n, axis, kappa));  // from below
  CHECK_FALSE(guideLobe(guideCell(100, 5.0e-4f * dir), n, axis, kappa));  // no mean direction
}

TEST_CASE("guided diffuse directions: the mixture of cosine, cones and guide lobes integrates to 1 and matches the sampler") {
  const glm::vec3 p(0.0f), n(0, 1, 0);
  const float a = 0.8f, guideProbability = 0.8f;
  const glm::vec4 spheres[3] = {
      {0.3f, 0.7f, 0.1f, 0.3f},    // cone and two lobes
      {0.0f, -1.0f, 0.0f, 0.3f},   // behind the surface: one lobe only
      {-0.6f, 0.9f, -0.2f, 0.2f}};  // cone only: its cells give no lobe
  const glm::vec3 narrow = glm::normalize(glm::vec3(0.35f, 0.8f, 0.1f));
  const glm::uvec4 cells[kGuideClasses * 3] = {
      guideCell(5000, 0.995f * narrow),                                     // kappa 200
      guideCell(300, 0.6f * glm::normalize(glm::vec3(1.0f, 0.15f, 0.0f))),   // kappa 2.5, mostly below the surface
      guideCell(50, 0.9f * glm::normalize(glm::vec3(-0.5f, 0.8f, 0.3f))),    // kappa 10
      guideCell(kMinGuidePhotons - 1, 0.9f * narrow),                        // too few photons
      guideCell(100, 0.5f * glm::normalize(glm::vec3(0.0f, -1.0f, 1.0f))),   // from below
      guideCell(100, 5.0e-4f * narrow)};                                     // no mean direction
  // The vertex for each caster pick (prepareCasters picks with u uniformly).
  std::vector<CasterVertex> byPick;
  for (int k = 0; k < 3; ++k)
    byPick.push_back(prepareCasters(p, n, (k + 0.5f) / 3.0f, spheres, 3, 0u, glm::vec4(0.0f), 0.0f, cells, guideProbability));
  const CasterVertex& v = byPick[0];
  REQUIRE(v.usable == 3);
  const float weights[kGuideClasses * 3] = {0.4f, 0.4f, 1.0f, 0.0f, 0.0f, 0.0f};
  for (int j = 0; j < kGuideClasses * 3; ++j) CHECK(v.guideWeight[j] == weights[j]);
  CHECK(v.oneMinusCos[1] == 0.0f);
  CHECK(v.guideKappa[0] == doctest::Approx(200.5).epsilon(1e-3));
  CHECK(glm::dot(v.guideAxis[1], n) < std::sqrt(1.0f - 0.8f * 0.8f));  // the wide lobe's axis 9 degrees above

  // Bins in the narrow lobe's frame: t = 1 - cos of the angle to its axis (fine where it peaks) times
  // the azimuth about it; dw = dt dphi, so the bins' integrals are midpoint sums over sub x sub cells
  // each and add up to the integral over the sphere.
  const std::vector<double> tEdge = {0, 0.0025, 0.005, 0.01, 0.02, 0.04, 0.08, 0.16, 0.32, 0.64, 1.0, 1.4, 2.0};
  const int tBins = static_cast<int>(tEdge.size()) - 1, phiBins = 8, sub = 384;
  glm::vec3 ta, ba;
  orthonormalBasis(narrow, ta, ba);
  std::vector<double> mass(tBins * phiBins, 0.0);
  double integral = 0;
  for (int i = 0; i < tBins; ++i)
    for (int k = 0; k < phiBins; ++k) {
      double dt = (tEdge[i + 1] - tEdge[i]) / sub, dphi = 2.0 * kPi / phiBins / sub, sum = 0;
      for (int x = 0; x < sub; ++x)
        for (int y = 0; y < sub; ++y) {
          double t = tEdge[i] + (x + 0.5) * dt, phi = 2.0 * kPi * k / phiBins + (y + 0.5) * dphi;
          double st = std::sqrt(t * (2.0 - t));
          glm::vec3 w = glm::normalize(glm::vec3(st * std::cos(phi) * glm::dvec3(ta) + st * std::sin(phi) * glm::dvec3(ba) +
                                                 (1.0 - t) * glm::dvec3(narrow)));
          sum += diffuseDirectionPdf(v, a, n, w);
        }
      mass[i * phiBins + k] = sum * dt * dphi;
      integral += sum * dt * dphi;
    }
  // Midpoint sums: the smooth parts to ~1e-9; the cone rims (steps) leave an error falling as 1 / sub
  // (measured 1.7e-4 at sub 128, 4.6e-5 at 384, of which 3.2e-5 is inCone's 1e-4 slack on the cones'
  // share 0.32). 1e-4 is 5 times below what a 0.5 % error of the narrow lobe's norm moves it (its share
  // of the mixture is 0.8 / 3 * 0.4 = 0.107).
  INFO("integral of the guided mixture pdf - 1: ", integral - 1.0);
  CHECK(std::abs(integral - 1.0) < 1e-4);

  // Sampler against pdf: 1e7 samples (chi-square 86 of limit 171 at 95 dof) fail at a 0.5 % error in the
  // sampler's lobe weights (198) or 1 % in a lobe's 1 - cos (290) or in every lobe's density (391).
  RngState s = rngSeed(31, 0, 0);
  const int m = 10000000;
  std::vector<double> obs(mass.size(), 0.0), exp(mass.size());
  for (size_t b = 0; b < mass.size(); ++b) exp[b] = mass[b] * m;
  int bad = 0;
  for (int j = 0; j < m; ++j) {
    const CasterVertex& w = byPick[std::min(static_cast<int>(rand01(s) * 3.0f), 2)];
    float uPick = rand01(s);
    glm::vec3 d = sampleDiffuseDirection(w, a, n, uPick, {rand01(s), rand01(s)});
    float pdf = diffuseDirectionPdf(w, a, n, d);
    if (!(std::abs(glm::length(d) - 1.0f) < 1e-4f) || !(pdf > 0.0f) || !std::isfinite(pdf)) {
      ++bad;
      continue;
    }
    glm::vec3 e = d - narrow;
    double t = 0.5 * glm::dot(e, e), phi = std::atan2(glm::dot(d, ba), glm::dot(d, ta));
    if (phi < 0) phi += 2.0 * kPi;
    int i = static_cast<int>(std::upper_bound(tEdge.begin() + 1, tEdge.end() - 1, t) - tEdge.begin() - 1);
    int k = std::min(static_cast<int>(phi / (2.0 * kPi) * phiBins), phiBins - 1);
    obs[i * phiBins + k]++;
  }
  CHECK(bad == 0);
  int dof = 0;
  double chi = chiSquare(obs, exp, dof);
  CHECK(chi < chiSquareLimit(dof));
}
