// layers_test.cpp — the clear-coat and sheen layers' C++ twins (shading/layers.h): the sheen albedo table
// against an independent quadrature of the KHR_materials_sheen BRDF, the sheen lobe's white furnace, and
// the white furnace of the layered material (coat over sheen over a base) as the path tracer picks its
// lobes. (The sheen sampler's chi-square test is in microfacet_test.cpp with the other lobes.)
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "shading/layers.h"
#include "shading/microfacet.h"
#include "shading/rng.h"
#include "shading/sampling.h"
#include "shared/sheen_albedo.h"
#include "util/math_constants.h"

using namespace caustica;

namespace {

// The Charlie BRDF's Lambda of KHR_materials_sheen, in double, written from the extension's text.
double lambdaD(double cosTheta, double alpha) {
  const auto l = [alpha](double x) {
    const double t = (1.0 - alpha) * (1.0 - alpha);
    const double a = 21.5473 + (25.3245 - 21.5473) * t, b = 3.82987 + (3.32435 - 3.82987) * t;
    const double c = 0.19823 + (0.16801 - 0.19823) * t, d = -1.97760 + (-1.27393 + 1.97760) * t;
    const double e = -4.32054 + (-4.85967 + 4.32054) * t;
    return a / (1.0 + b * std::pow(x, c)) + d * x + e;
  };
  const double x = std::abs(cosTheta);
  return x < 0.5 ? std::exp(l(x)) : std::exp(2.0 * l(0.5) - l(1.0 - x));
}

// E(mu, r) = integral of D V cos(theta_i) over the hemisphere, by the midpoint rule in (sqrt(cos theta_i),
// phi): an independent check of scripts/make-sheen-albedo (other grid, other language).
double albedoQuadrature(double mu, double roughness, int nT = 160, int nPhi = 64) {
  const double alpha = roughness * roughness, inv = 1.0 / alpha;
  const double sinO = std::sqrt(std::max(0.0, 1.0 - mu * mu)), lamO = lambdaD(mu, alpha);
  double sum = 0.0;
  for (int i = 0; i < nT; ++i) {
    const double t = (i + 0.5) / nT, ci = t * t, si = std::sqrt(1.0 - ci * ci);
    const double v = 1.0 / ((1.0 + lamO + lambdaD(ci, alpha)) * 4.0 * mu * ci);
    for (int j = 0; j < nPhi; ++j) {
      const double phi = kPiD * (j + 0.5) / nPhi;
      const double hx = sinO + si * std::cos(phi), hy = si * std::sin(phi), hz = mu + ci;
      const double cos2 = hz * hz / (hx * hx + hy * hy + hz * hz);
      const double d = (2.0 + inv) * std::pow(std::max(0.0, 1.0 - cos2), 0.5 * inv) / (2.0 * kPiD);
      sum += d * v * ci * (2.0 * t / nT) * (2.0 * kPiD / nPhi);
    }
  }
  return sum;
}

glm::vec3 unitWo(float cosTheta) {
  const float s = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
  return glm::vec3(s * std::cos(0.7f), s * std::sin(0.7f), cosTheta);
}

}  // namespace

// The table is E of the BRDF as the extension writes it; above 1 at grazing angles for roughness below
// ~0.25 (measured: 2.9 at roughness 0.07, cos 0.001), which is why the layer clamps its weight to
// max(sheenColor) min(E, 1) and the lobe divides by E (docs/materials.md).
TEST_CASE("sheen albedo table: every entry and the bilinear lookup agree with an independent quadrature") {
  constexpr int nMu = CAUSTICA_SHEEN_ALBEDO_MU, nR = CAUSTICA_SHEEN_ALBEDO_ROUGHNESS;
  double worstEntry = 0.0;
  for (int j = 0; j < nR; j += 3)
    for (int i = 0; i < nMu; i += 2) {
      const double x = double(i) / (nMu - 1), mu = std::max(x * x, 1e-5);
      const double r = kMinSheenRoughness + (1.0 - kMinSheenRoughness) * j / (nR - 1);
      const double e = albedoQuadrature(mu, r);
      worstEntry = std::max(worstEntry, std::abs(e - kSheenAlbedo[j * nMu + i]) / std::max(1.0, e));
    }
  std::printf("sheen albedo table: largest difference to the quadrature %.2e\n", worstEntry);
  CHECK(worstEntry < 5e-4);  // both quadratures converge to ~2e-4 (measured 1.1e-4)
  // Lookups between the entries, where the path tracer reads them: min(E, 1) (the layer's weight) within
  // 0.01 at every point (the worst are at roughness below 0.15, where E changes fastest), 5e-4 on average
  // (measured 0.0072 and 2.6e-4). A white furnace of a white sheen over a white base is off by this.
  RngState rng = rngSeed(4, 4, 4);
  double worst = 0.0, sum = 0.0;
  const int n = 300;
  for (int k = 0; k < n; ++k) {
    const float mu = 0.003f + 0.997f * rand01(rng), r = kMinSheenRoughness + (1.0f - kMinSheenRoughness) * rand01(rng);
    const double err = std::abs(std::min(double(sheenAlbedo(mu, r)), 1.0) - std::min(albedoQuadrature(mu, r), 1.0));
    worst = std::max(worst, err);
    sum += err;
  }
  std::printf("sheen albedo lookup: min(E, 1) within %.2e (largest), %.2e (mean)\n", worst, sum / n);
  CHECK(worst < 0.01);
  CHECK(sum / n < 5e-4);
  CHECK(sheenAlbedo(0.001f, 0.07f) > 2.0f);  // the BRDF as written gains energy at grazing angles
  CHECK(sheenAlbedo(1.0f, 1.0f) == doctest::Approx(0.1638).epsilon(0.002));
}

// The sheen lobe is the Charlie BRDF divided by E(cos_o): its directional albedo is its tint (1 for a
// white sheen) at every angle and roughness, to the table's accuracy. Mean of 200,000 bsdfSample weights.
TEST_CASE("furnace: the white sheen lobe reflects its albedo 1") {
  Bsdf b;
  b.lobe = kLobeSheen;
  b.color = glm::vec3(1.0f);
  for (float r : {0.07f, 0.2f, 0.5f, 1.0f})
    for (float cosO : {0.05f, 0.3f, 0.7f, 0.95f}) {
      b.alpha = r * r;
      const glm::vec3 wo = unitWo(cosO);
      RngState rng = rngSeed(6, std::uint32_t(r * 100), std::uint32_t(cosO * 100));
      const int n = 200000;
      double sum = 0, sum2 = 0;
      for (int k = 0; k < n; ++k) {
        BsdfSample s;
        const double w = bsdfSample(b, wo, {rand01(rng), rand01(rng), rand01(rng)}, s) ? s.weight.x : 0.0;
        sum += w;
        sum2 += w * w;
      }
      const double mean = sum / n, sigma = std::sqrt((sum2 / n - mean * mean) / n);
      // Where the table has no sheen to speak of (E < 0.01: near-normal view at low roughness) the path
      // never takes the lobe; elsewhere E_true / E_table is 1 within the lookup's error.
      const double e = albedoQuadrature(cosO, r);
      std::printf("sheen lobe albedo, roughness %.2f, cos %.2f: %.4f +- %.4f (E %.4f; relative noise per sample %.2f)\n",
                  r, cosO, mean, sigma, e, sigma * std::sqrt(double(n)) / std::max(mean, 1e-9));
      CAPTURE(r);
      CAPTURE(cosO);
      if (e < 0.01) continue;
      CHECK(std::abs(mean - e / sheenAlbedo(cosO, r)) < 4.0 * sigma + 1e-3);  // the estimator is right
      CHECK(std::abs(mean - 1.0) < 4.0 * sigma + 0.015);                      // and the table makes it 1
    }
}

namespace {

// One layered material: coat over sheen over a base lobe (Lambertian or plastic), as chooseBounceLobe
// (glsl/lib/path_scatter.glsl) picks among them.
struct Layered {
  float coat = 0.0f, coatRoughness = 0.0f;
  glm::vec3 sheenColor{0.0f};
  float sheenRoughness = 0.5f;
  Bsdf base;  // kLobeDiffuse or kLobePlastic
};

// One sample's weight f |cos| / pdf of the layered BSDF at wo (the coat, sheen and base share the normal),
// the three numbers u choosing the layer and the direction. Delta coats weigh 1 (a mirror).
glm::vec3 layeredWeight(const Layered& m, const glm::vec3& wo, float uLayer, const glm::vec3& u) {
  const LayerWeights w = layerWeights(m.coat, wo.z, m.sheenColor, m.sheenRoughness, wo.z, luminance(m.base.color));
  BsdfSample s;
  if (uLayer < w.coatPick) {
    const float pick = w.coat / w.coatPick;
    if (m.coatRoughness * m.coatRoughness < kDeltaAlpha) return glm::vec3(pick);
    Bsdf c;
    c.lobe = kLobeConductor;
    c.color = glm::vec3(1.0f);
    c.alpha = m.coatRoughness * m.coatRoughness;
    return bsdfSample(c, wo, u, s) ? pick * s.weight : glm::vec3(0.0f);
  }
  const float pick = (1.0f - w.coat) / (1.0f - w.coatPick);
  uLayer = (uLayer - w.coatPick) / (1.0f - w.coatPick);
  if (uLayer < w.sheen) {
    Bsdf sh;
    sh.lobe = kLobeSheen;
    const float c = std::max(m.sheenColor.x, std::max(m.sheenColor.y, m.sheenColor.z));
    sh.color = m.sheenColor / c;
    const float r = sheenRoughnessClamped(m.sheenRoughness);
    sh.alpha = r * r;
    return bsdfSample(sh, wo, u, s) ? pick * s.weight : glm::vec3(0.0f);
  }
  return bsdfSample(m.base, wo, u, s) ? pick * s.weight : glm::vec3(0.0f);
}

glm::dvec3 layeredAlbedoSampled(const Layered& m, float cosO, std::uint32_t seed, int n, glm::dvec3* sigma) {
  RngState rng = rngSeed(seed, 1, 1);
  glm::dvec3 sum(0.0), sum2(0.0);
  for (int k = 0; k < n; ++k) {
    const float uLayer = rand01(rng);
    const glm::dvec3 w(layeredWeight(m, unitWo(cosO), uLayer, {rand01(rng), rand01(rng), rand01(rng)}));
    sum += w;
    sum2 += w * w;
  }
  const glm::dvec3 mean = sum / double(n);
  *sigma = glm::sqrt(glm::max(sum2 / double(n) - mean * mean, glm::dvec3(0.0)) / double(n));
  return mean;
}

}  // namespace

// White furnace of the layered material: what a white base reflects under a smooth coat is exactly what
// the coat leaves (1 in all), under a white sheen likewise (to the table's accuracy); a rough coat loses
// GGX's single-scattering deficit on its share; no combination of colours <= 1 reflects more than 1.
TEST_CASE("furnace: coat over sheen over a white base reflects 1 where nothing is lost, and never more") {
  Bsdf white;
  white.lobe = kLobeDiffuse;
  white.color = glm::vec3(1.0f);
  const int n = 200000;
  for (float cosO : {0.05f, 0.2f, 0.5f, 0.9f}) {
    glm::dvec3 sigma;
    Layered smoothCoat;
    smoothCoat.coat = 1.0f;
    smoothCoat.base = white;
    const glm::dvec3 a = layeredAlbedoSampled(smoothCoat, cosO, 1, n, &sigma);
    CHECK(a.x == doctest::Approx(1.0).epsilon(1e-6));  // every sample weighs 1 (to rounding)
    Layered darkBase = smoothCoat;                       // the coat picked more often than its weight
    darkBase.base.color = glm::vec3(0.1f);
    const float wc = coatFresnel(cosO);
    const glm::dvec3 d = layeredAlbedoSampled(darkBase, cosO, 5, n, &sigma);
    CHECK(std::abs(d.x - (wc + (1.0 - wc) * 0.1)) < 4.0 * sigma.x + 1e-4);
    Layered sheen = smoothCoat;
    sheen.coat = 0.0f;
    sheen.sheenColor = glm::vec3(1.0f);
    for (float r : {0.1f, 0.3f, 0.8f}) {
      sheen.sheenRoughness = r;
      const glm::dvec3 s = layeredAlbedoSampled(sheen, cosO, 2, n, &sigma);
      std::printf("white sheen (roughness %.2f) over a white base, cos %.2f: %.4f +- %.4f\n", r, cosO, s.x, sigma.x);
      CAPTURE(r);
      CAPTURE(cosO);
      CHECK(std::abs(s.x - 1.0) < 4.0 * sigma.x + 0.006);
    }
    Layered rough = smoothCoat;
    rough.coatRoughness = 0.6f;
    const glm::dvec3 c = layeredAlbedoSampled(rough, cosO, 3, n, &sigma);
    std::printf("rough coat (roughness 0.6) over a white base, cos %.2f: %.4f +- %.4f (coat weight %.3f)\n", cosO, c.x,
                sigma.x, wc);
    CHECK(c.x < 1.0);
    CHECK(c.x > 1.0 - wc - 4.0 * sigma.x);  // the coat's share loses at most all of itself
  }
  // Random materials: coloured sheens over plastic and Lambertian bases under coats; no channel above 1.
  RngState rng = rngSeed(9, 9, 9);
  for (int k = 0; k < 40; ++k) {
    Layered m;
    m.coat = rand01(rng);
    m.coatRoughness = rand01(rng);
    m.sheenColor = glm::vec3(rand01(rng), rand01(rng), rand01(rng));
    m.sheenRoughness = rand01(rng);
    m.base.lobe = k % 2 ? kLobePlastic : kLobeDiffuse;
    m.base.color = glm::vec3(1.0f);
    m.base.alpha = 0.05f + rand01(rng);
    m.base.f0 = glm::vec3(0.04f);
    m.base.f90 = 1.0f;
    const float cosO = 0.2f + 0.8f * rand01(rng);  // plastic's own overshoot (materials.md) stays small here
    glm::dvec3 sigma;
    const glm::dvec3 a = layeredAlbedoSampled(m, cosO, 10 + std::uint32_t(k), 40000, &sigma);
    CAPTURE(k);
    CHECK(std::max(a.x, std::max(a.y, a.z)) <= 1.0 + 4.0 * std::max(sigma.x, std::max(sigma.y, sigma.z)) + 0.006);
  }
}

TEST_CASE("layer weights: the coat's Fresnel at 0.04, the sheen's min(E, 1), none without layers") {
  CHECK(coatFresnel(1.0f) == doctest::Approx(0.04f));
  CHECK(coatFresnel(0.0f) == doctest::Approx(1.0f));
  CHECK(coatFresnel(-0.5f) == coatFresnel(0.5f));
  const LayerWeights none = layerWeights(0.0f, 0.3f, glm::vec3(0.0f), 0.5f, 0.3f, 0.0f);
  CHECK(none.coat == 0.0f);
  CHECK(none.sheen == 0.0f);
  CHECK(none.coatPick == 0.0f);  // the base's pick weighs (1 - 0) / (1 - 0) = 1 exactly: nothing changes
  const LayerWeights both = layerWeights(0.5f, 1.0f, glm::vec3(0.2f, 0.8f, 0.4f), 0.07f, 0.001f, 0.5f);
  CHECK(both.coat == doctest::Approx(0.02f));
  CHECK(both.sheen == doctest::Approx(0.8f));  // E > 1 there: the weight is clamped to max(sheenColor)
  CHECK(both.coatPick == doctest::Approx(0.02f / (0.02f + 0.98f * 0.5f)));
  CHECK(layerWeights(1.0f, 1.0f, glm::vec3(0.0f), 0.5f, 1.0f, 1.0f).coatPick == doctest::Approx(0.04f));  // white base
  CHECK(layerWeights(1.0f, 1.0f, glm::vec3(0.0f), 0.5f, 1.0f, 0.0f).coatPick == 0.9f);   // black base: still sampled
  CHECK(layerWeights(1.0f, 0.0f, glm::vec3(0.0f), 0.5f, 1.0f, 0.0f).coatPick == 1.0f);   // grazing: the coat is all
  const glm::vec3 a = layeredAlbedo(both, glm::vec3(0.2f, 0.8f, 0.4f), glm::vec3(0.5f));
  CHECK(a.y == doctest::Approx(0.02f + 0.98f * (0.8f + 0.2f * 0.5f)));
}
