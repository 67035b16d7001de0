// microfacet_test.cpp — the GGX lobes' C++ twins (shading/microfacet.h): normalisation of D, chi-square
// tests of every sampler against its pdf, reciprocity, and the directional albedo (the white furnace
// of a rough metal with F0 = 1) against an independent numerical integration.
#include "chi_square.h"
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "shading/microfacet.h"
#include "shading/rng.h"
#include "shading/sampling.h"
#include "util/math_constants.h"

using namespace caustica;
using caustica::test::chiSquare;
using caustica::test::chiSquareLimit;
using caustica::test::chiSquarePValue;

namespace {

glm::vec3 dirFromCosPhi(double c, double phi) {
  double s = std::sqrt(std::max(0.0, 1.0 - c * c));
  return glm::vec3(float(s * std::cos(phi)), float(s * std::sin(phi)), float(c));
}

glm::vec3 unitWo(float cosTheta) { return dirFromCosPhi(cosTheta, 0.7); }

// Chi-square of `sample` against `pdf` over the whole sphere, binned in cos(theta) x phi (equal solid
// angle); expected counts by a midpoint rule of sub x sub points per bin. Also checks that the pdf's
// integral equals the fraction of samples that were not lost.
template <class Sample, class Pdf>
void checkSampler(Sample sample, Pdf pdf, int n, std::uint32_t seed, const char* label = nullptr) {
  const int nCos = 20, nPhi = 24, sub = 24;
  std::vector<double> obs(nCos * nPhi, 0.0), exp(nCos * nPhi, 0.0);
  RngState rng = rngSeed(seed, 1, 2);
  int produced = 0;
  for (int k = 0; k < n; ++k) {
    glm::vec3 w;
    if (!sample(glm::vec3(rand01(rng), rand01(rng), rand01(rng)), w)) continue;
    ++produced;
    REQUIRE(std::abs(glm::length(w) - 1.0f) < 1e-3f);
    int i = std::min(nCos - 1, int((w.z + 1.0) * 0.5 * nCos));
    double phi = std::atan2(double(w.y), double(w.x));
    if (phi < 0) phi += 2 * kPiD;
    int j = std::min(nPhi - 1, int(phi / (2 * kPiD) * nPhi));
    obs[i * nPhi + j] += 1.0;
  }
  double total = 0;
  for (int i = 0; i < nCos; ++i)
    for (int j = 0; j < nPhi; ++j) {
      double sum = 0;
      for (int a = 0; a < sub; ++a)
        for (int b = 0; b < sub; ++b) {
          double c = -1.0 + 2.0 * (i + (a + 0.5) / sub) / nCos;
          double phi = 2 * kPiD * (j + (b + 0.5) / sub) / nPhi;
          sum += pdf(dirFromCosPhi(c, phi));
        }
      double binArea = (2.0 / nCos) * (2 * kPiD / nPhi);
      exp[i * nPhi + j] = n * sum / (sub * sub) * binArea;
      total += exp[i * nPhi + j];
    }
  int dof = 0;
  double chi = chiSquare(obs, exp, dof);
  CAPTURE(chi);
  CAPTURE(dof);
  if (label) std::printf("chi-square %s: %.1f with %d degrees of freedom, p = %.3f\n", label, chi, dof, chiSquarePValue(chi, dof));
  CHECK(chi < chiSquareLimit(dof));
  // The pdf integrates to the probability that a sample is produced (quadrature error < 0.5 %).
  CHECK(std::abs(total / n - double(produced) / n) < 0.005 + 4.0 / std::sqrt(double(n)));
}

// Smith Lambda of GGX in double, written independently of the twin.
double lambdaD(double cosT, double alpha) {
  double t2 = (1.0 - cosT * cosT) / (cosT * cosT);
  return (-1.0 + std::sqrt(1.0 + alpha * alpha * t2)) / 2.0;
}

// Directional albedo of GGX with F = 1 and height-correlated G2, by quadrature over the microfacet
// normal distributed as D(h) cos(theta_h): tan^2(theta_h) = alpha^2 xi / (1 - xi).
double ggxAlbedoQuadrature(double cosO, double alpha) {
  const int nXi = 2000, nPhi = 720;
  const double sinO = std::sqrt(1.0 - cosO * cosO);
  double sum = 0;
  for (int a = 0; a < nXi; ++a) {
    double xi = (a + 0.5) / nXi;
    double tan2 = alpha * alpha * xi / (1.0 - xi);
    double ch = 1.0 / std::sqrt(1.0 + tan2), sh = std::sqrt(tan2) * ch;
    for (int b = 0; b < nPhi; ++b) {
      double phi = 2 * kPiD * (b + 0.5) / nPhi;
      double hx = sh * std::cos(phi), hz = ch;  // h_y does not enter: wo lies in the xz plane
      double oh = sinO * hx + cosO * hz;  // wo = (sinO, 0, cosO)
      if (oh <= 0) continue;
      double iz = 2 * oh * hz - cosO;  // wi = 2 (wo.h) h - wo
      if (iz <= 0) continue;
      double g2 = 1.0 / (1.0 + lambdaD(cosO, alpha) + lambdaD(iz, alpha));
      sum += g2 * oh / (cosO * hz);
    }
  }
  return sum / (double(nXi) * nPhi);
}

}  // namespace

TEST_CASE("GGX: D cos(theta_h) integrates to 1; D, G1, G2 limits") {
  for (float alpha : {0.05f, 0.2f, 0.5f, 1.0f}) {
    // Integral over the hemisphere of D(h) h.z, in (cos theta, phi); fine grid near the pole.
    const int n = 200000;
    double sum = 0;
    for (int i = 0; i < n; ++i) {
      double t = (i + 0.5) / n;
      double c = 1.0 - t * t * t;  // denser near c = 1
      double dc = 3 * t * t / n;
      sum += ggxD(dirFromCosPhi(c, 0.3), alpha) * c * dc * 2 * kPiD;
    }
    CAPTURE(alpha);
    CHECK(std::abs(sum - 1.0) < 2e-3);
  }
  CHECK(ggxG1(glm::vec3(0, 0, 1), 0.5f) == 1.0f);
  CHECK(ggxG2(glm::vec3(0, 0, 1), glm::vec3(0, 0, 1), 0.5f) == 1.0f);
  CHECK(ggxG1(glm::vec3(1, 0, 0), 0.5f) < 1e-30f);
  CHECK(ggxD(glm::vec3(0, 0, -1), 0.5f) == 0.0f);
}

TEST_CASE("GGX visible normals: chi-square against G1 max(0, wo.h) D / wo.z") {
  for (float alpha : {0.3f, 0.8f})
    for (float cosO : {0.95f, 0.4f, 0.08f}) {
      CAPTURE(alpha);
      CAPTURE(cosO);
      glm::vec3 wo = unitWo(cosO);
      checkSampler([&](const glm::vec3& u, glm::vec3& w) { w = ggxSampleVisibleNormal(wo, alpha, {u.y, u.z}); return true; },
                   [&](const glm::vec3& w) { return double(ggxVisibleNormalPdf(wo, w, alpha)); }, 300000, 11);
    }
}

TEST_CASE("bsdfSample: chi-square against bsdfPdf for every GGX lobe, the clear coat and the sheen") {
  Bsdf metal;
  metal.lobe = kLobeConductor;
  metal.color = glm::vec3(0.9f, 0.6f, 0.3f);
  Bsdf plastic;
  plastic.lobe = kLobePlastic;
  plastic.color = glm::vec3(0.2f, 0.5f, 0.8f);
  plastic.f0 = glm::vec3(0.04f);
  plastic.f90 = 1.0f;
  Bsdf glass;
  glass.lobe = kLobeRoughGlass;
  glass.color = glm::vec3(1.0f);
  Bsdf sheen;
  sheen.lobe = kLobeSheen;
  sheen.color = glm::vec3(1.0f, 0.5f, 0.2f);
  Bsdf coat;  // the clear coat's lobe: a white GGX reflection (F = 1) about the coat normal (layers.glsl)
  coat.lobe = kLobeConductor;
  coat.color = glm::vec3(1.0f);
  const char* names[] = {"rough metal", "plastic", "rough glass entering", "rough glass leaving", "sheen", "clear coat"};
  for (float alpha : {0.3f, 0.7f})
    for (float cosO : {0.9f, 0.3f})
      for (int k = 0; k < 6; ++k) {
        Bsdf b = k == 0 ? metal : k == 1 ? plastic : k == 4 ? sheen : k == 5 ? coat : glass;
        b.alpha = alpha;
        if (k == 3) b.eta = 1.0f / 1.5f;  // leaving glass: total internal reflection beyond ~42 degrees
        CAPTURE(alpha);
        CAPTURE(cosO);
        CAPTURE(k);
        glm::vec3 wo = unitWo(cosO);
        checkSampler(
            [&](const glm::vec3& u, glm::vec3& w) {
              BsdfSample s;
              if (!bsdfSample(b, wo, u, s)) return false;
              w = s.wi;
              // The weight is f |cos| / pdf of the same direction.
              glm::vec3 expect = bsdfEval(b, wo, s.wi) * std::abs(s.wi.z) / bsdfPdf(b, wo, s.wi);
              REQUIRE(std::abs(s.weight.x - expect.x) <= 1e-5f * (1.0f + expect.x));
              REQUIRE(s.transmitted == (s.wi.z < 0.0f));
              return true;
            },
            [&](const glm::vec3& w) { return double(bsdfPdf(b, wo, w)); }, 200000, 17 + std::uint32_t(k),
            (std::string(names[k]) + ", alpha " + std::to_string(alpha).substr(0, 3) + ", cos " +
             std::to_string(cosO).substr(0, 3))
                .c_str());
      }
}

// With radiance divided by eta^2 on refraction, f(wo, wi) / n_o^2 = f(wi, wo) / n_i^2 (Veach's
// generalised reciprocity), n_o and n_i the indices on wo's and wi's sides.
TEST_CASE("bsdfEval is reciprocal: f(wo, wi) = f(wi, wo); refraction: f(wo, wi) / n_o^2 = f(wi, wo) / n_i^2") {
  RngState rng = rngSeed(5, 5, 5);
  int refracting = 0, pairs = 0;
  for (int k = 0; k < 2000; ++k) {
    glm::vec3 a = sampleCosineHemisphere({rand01(rng), rand01(rng)});
    glm::vec3 c = sampleCosineHemisphere({rand01(rng), rand01(rng)});
    if (a.z < 1e-3f || c.z < 1e-3f) continue;
    float alpha = 0.05f + 0.95f * rand01(rng);
    for (std::uint32_t lobe : {kLobeConductor, kLobePlastic, kLobeRoughGlass}) {
      Bsdf b;
      b.lobe = lobe;
      b.alpha = alpha;
      b.color = glm::vec3(0.7f, 0.4f, 0.2f);
      glm::vec3 f1 = bsdfEval(b, a, c), f2 = bsdfEval(b, c, a);
      CAPTURE(lobe);
      CHECK(glm::all(glm::lessThanEqual(glm::abs(f1 - f2), 2e-4f * (glm::vec3(1.0f) + f1))));
    }
    // Refraction: wo above (outside, n = 1), wi below (inside, n = 1.5), and the reverse path.
    Bsdf in;
    in.lobe = kLobeRoughGlass;
    in.alpha = alpha;
    in.eta = 1.5f;
    Bsdf out = in;
    out.eta = 1.0f / 1.5f;
    glm::vec3 below(c.x, c.y, -c.z);
    float fIn = bsdfEval(in, a, below).x;  // wo outside, wi inside (light comes from inside)
    // The reverse path in its own frame: wo' = -below flipped to +z, wi' = a flipped to -z.
    float fOut = bsdfEval(out, -below, -a).x;
    CHECK(std::abs(fIn / 1.0f - fOut / (1.5f * 1.5f)) <= 2e-4f * (1.0f + fIn));
    refracting += fIn > 0.0f;  // 0 where no microfacet refracts a into below (both behind it)
    ++pairs;
  }
  CHECK(refracting * 4 > pairs);  // the refraction check saw many non-zero values (measured: a third)
}

TEST_CASE("furnace: a rough metal with F0 = 1 reflects its GGX directional albedo (sampling vs quadrature)") {
  // E(mu_o) = integral of f cos over the hemisphere with F = 1: what single scattering keeps; 1 - E
  // is the energy lost to neglected multiple scattering between microfacets (docs/materials.md).
  Bsdf b;
  b.lobe = kLobeConductor;
  b.color = glm::vec3(1.0f);
  for (float alpha : {0.1f, 0.3f, 0.6f, 1.0f})
    for (float cosO : {1.0f, 0.5f, 0.2f}) {
      b.alpha = alpha;
      glm::vec3 wo = unitWo(cosO);
      double quad = ggxAlbedoQuadrature(cosO, alpha);
      RngState rng = rngSeed(3, std::uint32_t(alpha * 100), std::uint32_t(cosO * 100));
      const int n = 400000;
      double sum = 0, sum2 = 0;
      for (int k = 0; k < n; ++k) {
        BsdfSample s;
        double w = bsdfSample(b, wo, {rand01(rng), rand01(rng), rand01(rng)}, s) ? s.weight.x : 0.0;
        sum += w;
        sum2 += w * w;
      }
      double mean = sum / n, sigma = std::sqrt((sum2 / n - mean * mean) / n);
      std::printf("GGX albedo alpha %.2f cos %.2f: quadrature %.5f, sampled %.5f +- %.5f\n", alpha, cosO, quad, mean,
                  sigma);
      CAPTURE(alpha);
      CAPTURE(cosO);
      CHECK(quad <= 1.0 + 1e-4);
      // At alpha = 1 and normal incidence: D = 1/pi, G1 = 2 cos / (1 + cos), E = 1 - ln 2 exactly.
      if (alpha == 1.0f && cosO == 1.0f) CHECK(std::abs(quad - (1.0 - std::log(2.0))) < 2e-5);
      CHECK(std::abs(mean - quad) < 4.0 * sigma + 2e-4);
    }
}

// Rough glass (reflection plus refraction, transmitted flux counted without the radiance's 1 / eta^2)
// never returns more than it receives. glTF's fresnel_mix (plastic) weights the diffuse base by
// 1 - F(wo.h) with h the half vector of wo and wi: at grazing wo over a white base that overshoots
// (measured below: up to 1.44 at alpha 0.05, cos 0.05), a property of glTF's model, printed for
// docs/materials.md and bounded here so that a change shows.
TEST_CASE("energy: rough glass never returns more than it receives; the plastic lobe's albedo") {
  RngState rng = rngSeed(8, 8, 8);
  for (std::uint32_t lobe : {kLobeRoughGlass, kLobePlastic})
    for (float alpha : {0.05f, 0.5f, 1.0f})
      for (float cosO : {1.0f, 0.3f, 0.05f})
        for (float eta : {1.5f, 1.0f / 1.5f}) {
          if (lobe == kLobePlastic && eta != 1.5f) continue;
          Bsdf b;
          b.lobe = lobe;
          b.alpha = alpha;
          b.eta = eta;
          b.color = glm::vec3(1.0f);
          b.f0 = glm::vec3(0.04f);
          const int n = 100000;
          double sum = 0;
          for (int k = 0; k < n; ++k) {
            BsdfSample s;
            if (!bsdfSample(b, unitWo(cosO), {rand01(rng), rand01(rng), rand01(rng)}, s)) continue;
            sum += s.weight.x * (s.transmitted ? b.eta * b.eta : 1.0f);
          }
          CAPTURE(lobe);
          CAPTURE(alpha);
          CAPTURE(cosO);
          CAPTURE(eta);
          if (lobe == kLobePlastic)
            std::printf("plastic albedo (white base, F0 0.04) alpha %.2f cos %.2f: %.4f\n", alpha, cosO, sum / n);
          CHECK(sum / n <= (lobe == kLobePlastic ? 1.5 : 1.0) + 4.0 / std::sqrt(double(n)));
          CHECK(sum / n > 0.3);
        }
}
