// light_trace_gpu_test.cpp — the light tracer's start sampler (sampleLtEmission, glsl/lib/light_trace.glsl,
// run by glsl/tests/light_trace_test.comp on llvmpipe over the scene as the Renderer uploads and binds it)
// against the density ltEmissionPdf claims for it: a chi-square test over emitter cells x direction bins,
// the expected counts integrating the GLSL pdf itself, and the pdf's integral against the share of samples
// that leave. The scene has what the mixture must get right: two casters whose cones from a one-sided lamp
// overlap (the density sums both), a third beside the lamp whose cone the lamp's plane cuts in half, and a
// two-sided emitter between the first two that lights one from its front and the other from its back.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "gpu/gl_objects.h"
#include "gpu/renderer.h"
#include "gpu/shader_features.h"
#include "../shading/chi_square.h"
#include "gl_test_util.h"
#include "scene_builder.h"

using namespace caustica;
using namespace caustica::test;

namespace {

enum class LtFn : GLuint { Sample = 0, Integrate = 1, Triangle = 2 };  // as in light_trace_test.comp

// Bins: per emissive triangle its four midpoint sub-triangles (cells), times kNz x kNphi direction bins of
// equal solid angle (z = cos of the angle to +z, phi around +z); each bin's integral by kSub x kSub
// directions at kPoints points of the cell.
constexpr std::uint32_t kNz = 24, kNphi = 48, kSub = 8, kPoints = 256;

// Two smooth casters and two emitters (docs: the file comment). Material 0: the one-sided lamp, 1: the
// two-sided emitter.
Scene overlappingCones() {
  Scene s;
  Material twoSided = emitterMaterial(30.0f);
  twoSided.doubleSided = true;
  s.materials = {emitterMaterial(10.0f), twoSided, glassMaterial(1.5f), metalMaterial(glm::vec3(0.9f))};
  const float h = 0.15f, top = 1.35f;  // the lamp, facing down: 40 and 15 degree cones to the casters
  addQuad(s, {-h, top, -h}, {h, top, -h}, {h, top, h}, {-h, top, h}, 0);
  addSphere(s, {0.0f, 0.8f, 0.0f}, 0.35f, 16, 2);
  addSphere(s, {0.6f, 0.6f, 0.1f}, 0.25f, 12, 3);
  addSphere(s, {0.6f, top, 0.0f}, 0.2f, 12, 3);  // beside the lamp, half above its plane: half its cone is not lit
  // The two-sided triangle below them, its plane between them (normal (1, 0.2, 0)).
  const glm::vec3 c(0.45f, 0.2f, 0.0f), t1(0.0f, 0.0f, 1.0f), t2 = glm::normalize(glm::vec3(0.2f, -1.0f, 0.0f));
  const float r = 0.12f;
  Triangle t{};
  t.p[0] = c + r * t2;
  t.p[1] = c + r * (-0.5f * t2 + 0.8660254f * t1);
  t.p[2] = c + r * (-0.5f * t2 - 0.8660254f * t1);
  const glm::vec3 n = glm::normalize(glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]));
  for (int k = 0; k < 3; ++k) t.setNormal(k, n);
  t.material = 1;
  s.triangles.push_back(t);
  finishBounds(s);
  s.cameras.push_back(lookAt({0.0f, 1.0f, 3.0f}, {0.2f, 0.6f, 0.0f}, 0.8f));
  return s;
}

// light_trace_test.comp compiled with the scene's feature defines (as the renderer compiles its passes) and
// run over the scene the renderer uploaded.
class GlslLightTrace {
 public:
  explicit GlslLightTrace(Renderer& renderer) : renderer_(renderer) {
    std::vector<std::string> defines = renderer.sceneFeatures().only(FeatureKind::Scene).defines();
    for (const std::string& d : renderer.bufferLayout().defines()) defines.push_back(d);
    for (const std::string& d : renderer.gpuScene().instanceDefines()) defines.push_back(d);
    ExpandedShader src = testShaderLibrary().expand("tests/light_trace_test.comp", defines);
    prog_ = GlProgram::compileCompute(src.source, [&](const std::string& log) { return src.mapLog(log); },
                                      "tests/light_trace_test.comp");
  }
  // count invocations of fn; in: kIntegrate's points; returns outFloats floats per invocation.
  std::vector<float> run(LtFn fn, std::uint32_t count, std::uint32_t outFloats, std::uint32_t seed,
                         const std::vector<glm::vec4>& in = {glm::vec4(0.0f)}) {
    GlBuffer inBuf = GlBuffer::fromVector(in);
    GlBuffer outBuf = GlBuffer::create(sizeof(float) * outFloats * count, nullptr);
    prog_.use();
    renderer_.bindSceneForDispatch();
    inBuf.bindBase(GL_SHADER_STORAGE_BUFFER, 0);
    outBuf.bindBase(GL_SHADER_STORAGE_BUFFER, 1);
    glUniform1ui(0, count);
    glUniform1ui(1, static_cast<GLuint>(fn));
    glUniform1ui(2, seed);
    glUniform3ui(3, kNz, kNphi, kSub);
    glDispatchCompute((count + 63) / 64, 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    checkGlError("light trace test dispatch");
    std::vector<float> out(static_cast<std::size_t>(outFloats) * count);
    outBuf.read(0, out.size() * sizeof(float), out.data());
    return out;
  }

 private:
  Renderer& renderer_;
  GlProgram prog_;
};

// Which of a triangle's four midpoint sub-triangles holds barycentrics (b1, b2): 0, 1, 2 at v0, v1, v2, 3 the middle.
int cellOf(float b1, float b2) {
  float b0 = 1.0f - b1 - b2;
  return b0 >= 0.5f ? 0 : b1 >= 0.5f ? 1 : b2 >= 0.5f ? 2 : 3;
}

// The corners of sub-triangle `cell` as barycentrics (b1, b2).
std::array<glm::vec2, 3> cellCorners(int cell) {
  const glm::vec2 v0(0, 0), v1(1, 0), v2(0, 1), m01(0.5f, 0), m12(0.5f, 0.5f), m02(0, 0.5f);
  switch (cell) {
    case 0: return {v0, m01, m02};
    case 1: return {m01, v1, m12};
    case 2: return {m02, m12, v2};
    default: return {m12, m02, m01};
  }
}

std::uint32_t directionBin(const glm::vec3& w) {
  auto iz = static_cast<std::uint32_t>(std::floor((w.z + 1.0f) * 0.5f * kNz));
  float phi = std::atan2(w.y, w.x);
  if (phi < 0.0f) phi += 2.0f * kPi;
  auto iphi = static_cast<std::uint32_t>(std::floor(phi / (2.0f * kPi) * kNphi));
  return std::min(iz, kNz - 1) * kNphi + std::min(iphi, kNphi - 1);
}

}  // namespace

TEST_CASE("light tracing: where light subpaths leave matches ltEmissionPdf (chi-square)") {
  Scene scene = overlappingCones();
  Renderer renderer(testShaderLibrary(), scene, scene.cameras[0], smallSettings(8, 8));
  const GpuScene& g = renderer.gpuScene();
  REQUIRE(g.casters.size() == 3);
  GlslLightTrace glsl(renderer);

  // The emissive triangles (GPU order) and their areas.
  std::vector<std::uint32_t> emitters;
  std::vector<double> areas;
  const auto triangleCount = static_cast<std::uint32_t>(g.triangleCount);
  std::vector<float> tris = glsl.run(LtFn::Triangle, triangleCount, 2, 0);
  for (std::uint32_t i = 0; i < triangleCount; ++i) {
    if (sameBits<std::uint32_t>(tris[2 * i]) > 1) continue;  // materials 0 and 1 emit
    emitters.push_back(i);
    areas.push_back(tris[2 * i + 1]);
  }
  REQUIRE(emitters.size() == 3);

  // Expected counts: the integral of ltEmissionPdf over each cell and direction bin, from kPoints stratified
  // points per cell (each area / 4 / kPoints) and the shader's midpoint rule over directions.
  const std::uint32_t bins = kNz * kNphi, cells = static_cast<std::uint32_t>(emitters.size()) * 4;
  std::vector<glm::vec4> points;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const int side = static_cast<int>(std::lround(std::sqrt(double(kPoints))));
  for (std::uint32_t e = 0; e < emitters.size(); ++e)
    for (int cell = 0; cell < 4; ++cell) {
      auto c = cellCorners(cell);
      for (int a = 0; a < side; ++a)
        for (int b = 0; b < side; ++b) {
          float u1 = (a + unit(rng)) / side, u2 = (b + unit(rng)) / side, s = std::sqrt(u1);
          glm::vec2 bc = (1.0f - s) * c[0] + s * (1.0f - u2) * c[1] + s * u2 * c[2];
          points.emplace_back(bc.x, bc.y, sameBits<float>(emitters[e]), 0.0f);
        }
    }
  std::vector<float> integrals = glsl.run(LtFn::Integrate, static_cast<std::uint32_t>(points.size()) * bins, 1, 0, points);

  const std::uint32_t batches = 8, perBatch = 1u << 18;
  const double n = double(batches) * perBatch;
  std::vector<double> expected(cells * bins + 1, 0.0), observed(cells * bins + 1, 0.0);
  double mass = 0.0;
  std::uint64_t notUnit = 0;
  for (std::uint32_t e = 0; e < emitters.size(); ++e)
    for (std::uint32_t cell = 0; cell < 4; ++cell)
      for (std::uint32_t p = 0; p < kPoints; ++p) {
        std::size_t point = (e * 4 + cell) * kPoints + p;
        for (std::uint32_t k = 0; k < bins; ++k) {
          double v = n * areas[e] / 4.0 / kPoints * integrals[point * bins + k];
          expected[(e * 4 + cell) * bins + k] += v;
          mass += v;
        }
      }

  // Observed: the sampler's histogram; samples that leave nothing in the last bin.
  for (std::uint32_t batch = 0; batch < batches; ++batch) {
    std::vector<float> out = glsl.run(LtFn::Sample, perBatch, 8, 1000 + batch);
    for (std::uint32_t i = 0; i < perBatch; ++i) {
      const float* o = &out[8 * i];
      std::uint32_t tri = sameBits<std::uint32_t>(o[2]);
      if (tri == ~0u) {
        observed.back() += 1.0;
        continue;
      }
      auto it = std::find(emitters.begin(), emitters.end(), tri);
      REQUIRE(it != emitters.end());
      std::uint32_t e = static_cast<std::uint32_t>(it - emitters.begin());
      glm::vec3 w(o[4], o[5], o[6]);
      if (!(std::abs(glm::length(w) - 1.0f) < 1e-4f)) ++notUnit;
      observed[(e * 4 + cellOf(o[0], o[1])) * bins + directionBin(w)] += 1.0;
    }
  }
  CHECK(notUnit == 0);
  expected.back() = std::max(0.0, n - mass);

  int dof = 0;
  double chi = chiSquare(observed, expected, dof);
  double limit = chiSquareLimit(dof);
  MESSAGE("chi-square ", chi, " over ", dof, " degrees of freedom (limit ", limit, ", p = ", chiSquarePValue(chi, dof),
          "); pdf integrates to ", mass / n, ", samples left ", 1.0 - observed.back() / n);
  CHECK(chi < limit);
  // The pdf's integral is the share of samples that leave: a density 0.5 % too large or small everywhere,
  // which the chi-square cannot see, fails this. Measured: within 1e-4 (the quadrature's error); the share's
  // own standard deviation is at most 0.00035 here.
  CHECK(std::abs(mass / n - (1.0 - observed.back() / n)) < 0.002);
}
