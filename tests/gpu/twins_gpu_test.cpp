// twins_gpu_test.cpp — the GLSL rng, sampling, Fresnel, dielectric, spectral and caster functions
// (tests/twins_test.comp on llvmpipe) agree with their C++ twins in app/shading/sampling.h, function for
// function, on random and edge-case inputs. Each tolerance says what it was measured against;
// CAUSTICA_TWINS_REPORT=1 prints every measured maximum.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "gpu/gl_objects.h"
#include "gpu/shader_library.h"
#include "accel/spawn.h"
#include "shading/layers.h"
#include "shading/microfacet.h"
#include "shading/oct_normal.h"
#include "shading/texture_wrap.h"
#include "shading/sampling.h"
#include "scene/punctual_lights.h"
#include "gl_test_util.h"
#include "image/denoise.h"

using namespace caustica;
using caustica::test::sameBits;

namespace {

// Function numbers of twins_test.comp, in its order.
enum class Fn : GLuint {
  Pcg4d, RngSeed, Rand01, Luminance, OrthonormalBasis, SampleCosineHemisphere, SampleTriangleUniform,
  PowerHeuristic, FresnelDielectric, RefractDir, OffsetRayOrigin, SampleDielectric, CauchyIor,
  ChannelSensitivity, InCone, CasterCone, SampleUniformCone, CasterFacesLights, PrepareCasters,
  DiffuseDirectionPdf, SampleDiffuseDirection, HitPointError, Ggx, GgxSampleVisibleNormal, BsdfEvalPdf, BsdfSample, SpotFalloff, OctDecode,
  WrapCoord, Layers, DenoiseTapWeight, GuideLobe, Vmf  // the last two: with CAUSTICA_GUIDING only
};

constexpr int kInWords = 4, kOutWords = 35;  // uvec4 per record, as in twins_test.comp

// One input record: the shader reads word k as uints (raw[k]) or as float bits (a[k]).
struct In {
  glm::uvec4 w[kInWords] = {};
};
In floats(const glm::vec4& a, const glm::vec4& b = glm::vec4(0), const glm::vec4& c = glm::vec4(0),
          const glm::vec4& d = glm::vec4(0)) {
  In r;
  r.w[0] = sameBits<glm::uvec4>(a);
  r.w[1] = sameBits<glm::uvec4>(b);
  r.w[2] = sameBits<glm::uvec4>(c);
  r.w[3] = sameBits<glm::uvec4>(d);
  return r;
}
In uints(const glm::uvec4& a) {
  In r;
  r.w[0] = a;
  return r;
}
glm::vec4 arg(const In& r, int k) { return sameBits<glm::vec4>(r.w[k]); }

// One output record: uints, float bits, or bools as 0 and 1.
struct Out {
  glm::uvec4 w[kOutWords];
  float f(int word, int c = 0) const { return sameBits<float>(w[word][c]); }
  glm::vec3 v(int word) const { return sameBits<glm::vec3>(glm::uvec3(w[word])); }
  bool b(int word, int c = 0) const { return w[word][c] != 0u; }
};
static_assert(sizeof(In) == kInWords * 16 && sizeof(Out) == kOutWords * 16, "records are packed uvec4 arrays");

// twins_test.comp, compiled once per test case (with `defines`); run() calls one function on every record.
class GlslTwins {
 public:
  explicit GlslTwins(const std::vector<std::string>& defines = {})
      : prog_(test::compileTestShader("tests/twins_test.comp", defines)) {}
  // guideCells (CAUSTICA_GUIDING): per record kGuideClasses * CAUSTICA_MAX_CASTERS cells, what
  // casterGuideCell returns.
  std::vector<Out> run(Fn fn, const std::vector<In>& in, const gpu::CasterParams& casters = {},
                       const std::vector<glm::uvec4>& guideCells = {}) const {
    GlBuffer inBuf = GlBuffer::fromVector(in);
    GlBuffer outBuf = GlBuffer::create(sizeof(Out) * in.size(), nullptr);
    GlBuffer ubo = GlBuffer::create(sizeof(casters), &casters);
    GlBuffer cellBuf = GlBuffer::fromVector(guideCells.empty() ? std::vector<glm::uvec4>(1) : guideCells);
    prog_.use();
    inBuf.bindBase(GL_SHADER_STORAGE_BUFFER, 0);
    outBuf.bindBase(GL_SHADER_STORAGE_BUFFER, 1);
    cellBuf.bindBase(GL_SHADER_STORAGE_BUFFER, 2);
    ubo.bindBase(GL_UNIFORM_BUFFER, CAUSTICA_BINDING_CASTERS);
    glUniform1ui(0, static_cast<GLuint>(in.size()));
    glUniform1ui(1, static_cast<GLuint>(fn));
    glDispatchCompute(static_cast<GLuint>((in.size() + 63) / 64), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    checkGlError("twins test dispatch");
    std::vector<Out> out(in.size());
    outBuf.read(0, out.size() * sizeof(Out), out.data());
    return out;
  }

 private:
  GlProgram prog_;
};

std::string str(float x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.9g", static_cast<double>(x));
  return b;
}
std::string str(const glm::vec3& v) { return "(" + str(v.x) + ", " + str(v.y) + ", " + str(v.z) + ")"; }
std::string str(const glm::vec4& v) { return "(" + str(glm::vec3(v)) + ", " + str(v.w) + ")"; }
std::string str(const In& r) {
  return "inputs " + str(arg(r, 0)) + " " + str(arg(r, 1)) + " " + str(arg(r, 2)) + " " + str(arg(r, 3));
}

bool reportWanted() { return std::getenv("CAUSTICA_TWINS_REPORT") != nullptr; }

// The largest GPU-vs-C++ difference of one output over all records, checked against its tolerance;
// keeps a description of the worst record for the message.
class MaxDiff {
 public:
  MaxDiff(std::string what, double tol) : what_(std::move(what)), tol_(tol) {}
  void add(double diff, const std::function<std::string()>& describe) {
    if (std::isnan(worst_) || diff <= worst_) return;  // a NaN difference sticks
    worst_ = diff;
    where_ = describe();
  }
  void check() const {
    if (reportWanted()) MESSAGE(what_, ": max difference ", worst_, " (tolerance ", tol_, ") at ", where_);
    INFO(what_, ": max difference ", worst_, " exceeds the tolerance ", tol_, " at ", where_);
    CHECK(worst_ <= tol_);
  }

 private:
  std::string what_;
  double tol_, worst_ = 0;
  std::string where_ = "-";
};

// A discrete output (bool, integer, bits) that must agree exactly, except on records the caller marks as
// lying on a threshold (the C++ twin itself flips there under a tiny change of the input); those are
// counted and must stay rare.
class Mismatches {
 public:
  explicit Mismatches(std::string what) : what_(std::move(what)) {}
  void add(bool same, bool onThreshold, const std::function<std::string()>& describe) {
    ++records_;
    if (same) return;
    if (onThreshold) {
      ++onThreshold_;
      return;
    }
    if (count_++ == 0) first_ = describe();
  }
  void add(bool same, const std::function<std::string()>& describe) { add(same, false, describe); }
  void check() const {
    if (reportWanted())
      MESSAGE(what_, ": ", count_, " mismatches, ", onThreshold_, " on a threshold, of ", records_, " records");
    INFO(what_, ": ", count_, " of ", records_, " records differ; first: ", first_);
    CHECK(count_ == 0);
    INFO(what_, ": ", onThreshold_, " of ", records_, " records differ on a threshold");
    CHECK(onThreshold_ * 50 <= records_);  // at most 2%: the edge cases aim at thresholds, random inputs rarely
  }

 private:
  std::string what_, first_;
  int records_ = 0, count_ = 0, onThreshold_ = 0;
};

constexpr double kEps = std::numeric_limits<float>::epsilon();  // 2^-23, one ULP of 1

// Where a discrete output decides on a threshold (a comparison of rounded floats), GPU and C++ may
// disagree when a few-ULP difference in an intermediate crosses it: a record counts as on the threshold
// when the C++ twin itself flips as the input that decides moves by kNudge (relative, about 8 ULP).
constexpr float kNudge = 1e-6f;

// llvmpipe's GLSL asin (Mesa 22.3) is a polynomial approximation: measured against std::asin on
// [0, 1] its absolute error reaches 3.9e-4 rad (near x = 0.94; 2e-4 at x = 0.5), against a few ULP in
// C++. casterFacesLights compares 2 asin(a) with asin(b) + asin(c) + margin, so its GPU and C++ answers
// may differ where those sides are within 4 x 4e-4 rad of each other; there it counts as on the threshold.
constexpr float kAsinBand = 4.0f * 4e-4f;

double absDiff(const glm::vec3& a, const glm::vec3& b) {
  glm::vec3 d = glm::abs(a - b);
  return std::max({d.x, d.y, d.z});
}
double absDiff(float a, float b) { return std::abs(static_cast<double>(a) - b); }
// Relative difference; below `floor` in magnitude it turns into an absolute difference scaled by 1 / floor.
double relDiff(float gpu, float cpu, double floor = 1e-30) {
  return absDiff(gpu, cpu) / std::max(std::abs(static_cast<double>(cpu)), floor);
}

enum class Measure { Absolute, Relative };

// Runs `fn` on every record and compares output word 0 (a float in .x, or a vec3) with twin(record).
template <class Twin>
void compareOutput(const GlslTwins& gpu, Fn fn, const std::vector<In>& in, MaxDiff diff, Measure measure,
                   const Twin& twin) {
  std::vector<Out> out = gpu.run(fn, in);
  for (size_t i = 0; i < in.size(); ++i) {
    auto c = twin(in[i]);
    if constexpr (std::is_same_v<decltype(c), float>) {
      float g = out[i].f(0);
      diff.add(measure == Measure::Relative ? relDiff(g, c) : absDiff(g, c),
               [&] { return str(in[i]) + ": " + str(g) + " vs " + str(c); });
    } else {
      glm::vec3 g = out[i].v(0);
      diff.add(absDiff(g, c), [&] { return str(in[i]) + ": " + str(g) + " vs " + str(c); });
    }
  }
  diff.check();
}

struct Random {
  std::mt19937 g;
  explicit Random(std::uint32_t seed) : g(seed) {}
  float uniform(float a = 0.0f, float b = 1.0f) { return std::uniform_real_distribution<float>(a, b)(g); }
  float logUniform(float lo, float hi) { return std::pow(10.0f, uniform(std::log10(lo), std::log10(hi))); }
  glm::vec3 unit() {
    std::normal_distribution<float> n;
    glm::vec3 v;
    do v = glm::vec3(n(g), n(g), n(g));
    while (glm::dot(v, v) < 1e-6f);
    return glm::normalize(v);
  }
  glm::vec3 inBox(float h) { return glm::vec3(uniform(-h, h), uniform(-h, h), uniform(-h, h)); }
  glm::vec2 u2() { return glm::vec2(uniform(), uniform()); }
};

const float kLastBelowOne = std::nextafter(1.0f, 0.0f);  // the largest rand01
const float kUEdges[] = {0.0f, 1e-7f, 0.25f, 0.5f, 0.75f, 1.0f - 1e-6f, kLastBelowOne};

// Unit normals at and near the poles, where orthonormalBasis switches sign, and along the axes.
std::vector<glm::vec3> edgeNormals() {
  std::vector<glm::vec3> ns = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {1, 0, -0.0f}, {0, 1, -0.0f}};
  for (float eps : {0.0f, 1e-8f, 1e-6f, 1e-4f, 1e-2f})
    for (float z : {1.0f, -1.0f})
      for (int k = 0; k < 4; ++k) {
        float phi = 0.4f + 1.5707964f * static_cast<float>(k);
        ns.push_back(glm::normalize(glm::vec3(eps * std::cos(phi), eps * std::sin(phi), z)));
      }
  return ns;
}

// A unit direction d towards a surface with unit normal n, at cos(angle) = cosI against -n.
glm::vec3 incident(const glm::vec3& n, float cosI, Random& r) {
  glm::vec3 t = glm::normalize(glm::cross(n, r.unit()));
  return glm::normalize(-cosI * n + std::sqrt(std::max(0.0f, 1.0f - cosI * cosI)) * t);
}

// How far the C++ twin's output moves when eta changes by a relative kNudge. Near the critical angle
// refraction is ill-conditioned: a one-ULP difference in cos(incidence) (a dot product, which llvmpipe
// rounds differently) moves the refracted direction by up to this much, so it is added to the tolerance.
template <class F>
double etaSpread(const F& f, float eta) {
  auto base = f(eta);
  return std::max(absDiff(f(eta * (1.0f - kNudge)), base), absDiff(f(eta * (1.0f + kNudge)), base));
}

const float kEtas[] = {1.5f, 1.0f / 1.5f, 1.33f, 1.0f / 1.33f, 2.4f, 1.0f / 2.4f, 1.0f, 1.0001f, 0.9999f};

}  // namespace

TEST_CASE("GLSL rng functions equal their C++ twins bit for bit: pcg4d, rngSeed, rand01") {
  GlslTwins gpu;
  Random r(1);
  std::vector<In> in;
  for (std::uint32_t v : {0u, 1u, 0x7fffffffu, 0x80000000u, 0xffffffffu}) in.push_back(uints({v, v, v, v}));
  in.push_back(uints({0, 0, 0, 0}));  // rngSeed's guarded key region and a zero xoshiro word
  for (std::uint32_t i = 0; i < 1024; ++i) in.push_back(uints({i, i & 7u, 1u, 0x9E3779B9u}));
  while (in.size() < 8192) in.push_back(uints({r.g(), r.g(), r.g(), r.g()}));

  // Integer arithmetic, and float(24-bit integer) * 2^-24, are exact on both sides: every bit must agree.
  std::vector<Out> hash = gpu.run(Fn::Pcg4d, in), seed = gpu.run(Fn::RngSeed, in), draws = gpu.run(Fn::Rand01, in);
  Mismatches mHash("pcg4d"), mSeed("rngSeed"), mRand("rand01 (three draws, then the state)");
  for (size_t i = 0; i < in.size(); ++i) {
    glm::uvec4 a = in[i].w[0];
    auto args = [&] {
      return "uints " + std::to_string(a.x) + " " + std::to_string(a.y) + " " + std::to_string(a.z) + " " +
             std::to_string(a.w);
    };
    mHash.add(hash[i].w[0] == pcg4d(a), args);
    mSeed.add(seed[i].w[0] == rngSeed(a.x, a.y, a.z), args);
    RngState state = a;
    float u0 = rand01(state), u1 = rand01(state), u2 = rand01(state);
    glm::uvec3 want(sameBits<std::uint32_t>(u0), sameBits<std::uint32_t>(u1), sameBits<std::uint32_t>(u2));
    mRand.add(glm::uvec3(draws[i].w[0]) == want && draws[i].w[1] == state, args);
  }
  mHash.check();
  mSeed.check();
  mRand.check();
}

TEST_CASE(
    "GLSL sampling helpers equal their C++ twins: luminance, orthonormalBasis, sampleCosineHemisphere, "
    "sampleTriangleUniform, powerHeuristic") {
  GlslTwins gpu;
  Random r(2);
  const size_t n = 4096;

  std::vector<In> colours = {floats({0, 0, 0, 0}), floats({1, 1, 1, 0}), floats({1e30f, 1e30f, 1e30f, 0})};
  while (colours.size() < n)
    colours.push_back(floats(glm::vec4(glm::abs(r.inBox(1.0f)) * r.logUniform(1e-3f, 1e3f), 0)));
  // One dot product, rounded in another order or fused on llvmpipe: measured 1.6e-7 (1.3 ULP).
  compareOutput(gpu, Fn::Luminance, colours, MaxDiff("luminance (relative)", 4 * kEps), Measure::Relative,
                [](const In& x) { return luminance(glm::vec3(arg(x, 0))); });

  std::vector<In> normals;
  for (const glm::vec3& nn : edgeNormals()) normals.push_back(floats(glm::vec4(nn, 0)));
  while (normals.size() < n) normals.push_back(floats(glm::vec4(r.unit(), 0)));
  std::vector<Out> basis = gpu.run(Fn::OrthonormalBasis, normals);
  // A handful of products and sums of magnitude <= 2: measured 1.2e-7 (one ULP of 1).
  MaxDiff dBasis("orthonormalBasis t and b", 4 * kEps);
  for (size_t i = 0; i < n; ++i) {
    glm::vec3 t, b;
    orthonormalBasis(glm::vec3(arg(normals[i], 0)), t, b);
    dBasis.add(std::max(absDiff(basis[i].v(0), t), absDiff(basis[i].v(1), b)), [&] {
      return str(normals[i]) + ": t " + str(basis[i].v(0)) + " vs " + str(t) + ", b " + str(basis[i].v(1)) + " vs " +
             str(b);
    });
  }
  dBasis.check();

  std::vector<In> us;
  for (float a : kUEdges)
    for (float b : kUEdges) us.push_back(floats({a, b, 0, 0}));
  while (us.size() < n) us.push_back(floats(glm::vec4(r.u2(), 0, 0)));
  // llvmpipe's cos and sin of phi in [0, 2 pi) are within ~1 ULP: measured 6e-8.
  compareOutput(gpu, Fn::SampleCosineHemisphere, us, MaxDiff("sampleCosineHemisphere", 4 * kEps), Measure::Absolute,
                [](const In& x) { return sampleCosineHemisphere(glm::vec2(arg(x, 0))); });
  // A sqrt, a product and a difference: measured 0 (one ULP allowed: GLSL does not require a correctly
  // rounded sqrt). The shader writes (b1, b2, 0).
  compareOutput(gpu, Fn::SampleTriangleUniform, us, MaxDiff("sampleTriangleUniform", kEps), Measure::Absolute,
                [](const In& x) { return glm::vec3(sampleTriangleUniform(glm::vec2(arg(x, 0))), 0.0f); });

  std::vector<In> pdfs = {floats({0, 1, 0, 0}),        floats({-1, 1, 0, 0}),         floats({1, 0, 0, 0}),
                          floats({1, 1, 0, 0}),        floats({1e-30f, 1e30f, 0, 0}), floats({1e30f, 1e-30f, 0, 0}),
                          floats({1.2e-38f, 1, 0, 0}), floats({1e20f, 3e20f, 0, 0})};
  while (pdfs.size() < n) pdfs.push_back(floats({r.logUniform(1e-20f, 1e20f), r.logUniform(1e-20f, 1e20f), 0, 0}));
  // A division and a few products: measured 0 (one ULP allowed: GLSL division need not be correctly rounded).
  compareOutput(gpu, Fn::PowerHeuristic, pdfs, MaxDiff("powerHeuristic", kEps), Measure::Absolute,
                [](const In& x) { return powerHeuristic(arg(x, 0).x, arg(x, 0).y); });
}

TEST_CASE("GLSL Fresnel, refraction, ray offset and dielectric sampling equal their C++ twins") {
  GlslTwins gpu;
  Random r(3);
  const size_t n = 4096;

  // fresnelDielectric: eta = n_t / n_i on both sides of 1; cosI at normal and grazing incidence, out of
  // [0, 1] (clamped), and around the critical angle of total internal reflection (eta < 1).
  std::vector<In> fr;
  for (float eta : kEtas) {
    std::vector<float> cs = {0.0f, -0.0f, 1e-6f, 1e-3f, 0.5f, 1.0f, -0.1f, 1.1f};
    if (eta < 1.0f) {
      float crit = std::sqrt(1.0f - eta * eta);
      for (float k : {0.0f, 1e-6f, -1e-6f, 1e-4f, -1e-4f, 1e-2f, -1e-2f}) cs.push_back(crit * (1.0f + k));
      cs.push_back(std::nextafter(crit, 0.0f));
      cs.push_back(std::nextafter(crit, 1.0f));
    }
    for (float c : cs) fr.push_back(floats({c, eta, 0, 0}));
  }
  while (fr.size() < n)
    fr.push_back(
        floats({r.uniform(-0.2f, 1.2f), fr.size() % 2 ? kEtas[fr.size() % 9] : r.logUniform(0.3f, 3.3f), 0, 0}));
  std::vector<Out> fres = gpu.run(Fn::FresnelDielectric, fr);
  // Measured 0, also at the critical angle (one ULP allowed for division); beyond the spread because a
  // driver that rounds sin2T differently by one ULP moves the result that much near the critical angle.
  MaxDiff dFres("fresnelDielectric (beyond its spread under eta * (1 +- kNudge))", kEps);
  for (size_t i = 0; i < n; ++i) {
    float cosI = arg(fr[i], 0).x, eta = arg(fr[i], 0).y, c = fresnelDielectric(cosI, eta), g = fres[i].f(0);
    double spread = etaSpread([&](float e) { return fresnelDielectric(cosI, e); }, eta);
    dFres.add(absDiff(g, c) - spread, [&] { return str(fr[i]) + ": " + str(g) + " vs " + str(c); });
  }
  dFres.check();

  // refractDir and sampleDielectric: d towards the surface, n against d; random, grazing and critical
  // angles; u at the Fresnel reflectance, where sampleDielectric switches from reflection to refraction.
  std::vector<In> rays;
  auto addRay = [&](const glm::vec3& nn, float cosI, float eta) {
    float u = rays.size() % 2 ? r.uniform() : fresnelDielectric(cosI, eta);
    rays.push_back(floats(glm::vec4(incident(nn, cosI, r), eta), glm::vec4(nn, u)));
  };
  for (float eta : kEtas)
    for (float cosI : {1.0f, 0.5f, 1e-2f, 1e-4f, 1e-6f})
      for (int k = 0; k < 2; ++k) addRay(r.unit(), cosI, eta);
  for (float eta : kEtas) {  // refractDir's eta = n_i / n_t: total internal reflection when eta > 1
    if (eta <= 1.0f) continue;
    float crit = std::sqrt(1.0f - 1.0f / (eta * eta));
    for (float k : {0.0f, 1e-6f, -1e-6f, 1e-4f, -1e-4f, 1e-2f, -1e-2f}) addRay(r.unit(), crit * (1.0f + k), eta);
  }
  while (rays.size() < n) {
    glm::vec3 nn = r.unit(), d = r.unit();
    if (glm::dot(d, nn) > 0.0f) d = -d;
    float eta = rays.size() % 2 ? kEtas[rays.size() % 9] : r.logUniform(0.3f, 3.3f);
    rays.push_back(floats(glm::vec4(d, eta), glm::vec4(nn, r.uniform())));
  }
  std::vector<Out> refr = gpu.run(Fn::RefractDir, rays), diel = gpu.run(Fn::SampleDielectric, rays);
  Mismatches mRefr("refractDir: refracts (else total internal reflection)"), mDiel("sampleDielectric: transmitted");
  // Directions: dot products and normalize (GLSL: inversesqrt) differ by an ULP or two; beyond the spread
  // measured 6e-8 (refractDir) and 1.2e-7 (sampleDielectric, also reflect). Without the spread the worst
  // record, 2e-4 from the critical angle, differed by 3e-4. Factor 1 / eta^2: measured 0.
  MaxDiff dRefr("refractDir direction (beyond its spread)", 4 * kEps),
      dDiel("sampleDielectric direction (beyond its spread)", 4 * kEps),
      dDielF("sampleDielectric throughput factor (relative)", kEps);
  for (size_t i = 0; i < n; ++i) {
    glm::vec3 d(arg(rays[i], 0)), nn(arg(rays[i], 1));
    float eta = arg(rays[i], 0).w, u = arg(rays[i], 1).w;
    struct Refraction {
      bool ok;
      glm::vec3 t;
    };
    auto refract = [&](float e) {
      Refraction x;
      x.ok = refractDir(d, nn, e, x.t);
      return x;
    };
    Refraction c = refract(eta);
    mRefr.add(refr[i].b(0, 3) == c.ok, refract(eta * (1.0f - kNudge)).ok != refract(eta * (1.0f + kNudge)).ok,
              [&] { return str(rays[i]); });
    if (c.ok == refr[i].b(0, 3))
      dRefr.add(absDiff(refr[i].v(0), c.t) - etaSpread([&](float e) { return refract(e).t; }, eta),
                [&] { return str(rays[i]) + ": " + str(refr[i].v(0)) + " vs " + str(c.t); });

    struct Sample {
      float factor;
      glm::vec3 wi;
      bool transmitted;
    };
    auto dielectric = [&](float e) {
      Sample x;
      x.factor = sampleDielectric(d, nn, e, u, x.wi, x.transmitted);
      return x;
    };
    Sample cs = dielectric(eta);
    mDiel.add(diel[i].b(1) == cs.transmitted,
              dielectric(eta * (1.0f - kNudge)).transmitted != dielectric(eta * (1.0f + kNudge)).transmitted,
              [&] { return str(rays[i]); });
    if (diel[i].b(1) == cs.transmitted) {
      dDiel.add(absDiff(diel[i].v(0), cs.wi) - etaSpread([&](float e) { return dielectric(e).wi; }, eta),
                [&] { return str(rays[i]) + ": " + str(diel[i].v(0)) + " vs " + str(cs.wi); });
      dDielF.add(relDiff(diel[i].f(0, 3), cs.factor),
                 [&] { return str(rays[i]) + ": " + str(diel[i].f(0, 3)) + " vs " + str(cs.factor); });
    }
  }
  mRefr.check();
  dRefr.check();
  mDiel.check();
  dDiel.check();
  dDielF.check();

  // hitPointError and offsetRayOrigin (spawn.glsl): points near 0, near the float limits of a scene
  // (1e-8 .. 1e8), zero errors, normals along axes. GLSL may fuse the multiply-adds, so results may
  // differ by a rounding: within 4 ULP of the largest term (the bound itself has slack of 7 ULPs).
  std::vector<In> errs;
  while (errs.size() < n) {
    float b1 = r.uniform(), b2 = r.uniform() * (1.0f - b1);
    float scale = r.logUniform(1e-8f, 1e8f);
    glm::vec3 c = r.inBox(1.0f) * r.logUniform(1e-8f, 1e8f);
    errs.push_back(floats(glm::vec4(1.0f - b1 - b2, b1, b2, 0), glm::vec4(c + scale * r.inBox(1.0f), 0),
                          glm::vec4(c + scale * r.inBox(1.0f), 0), glm::vec4(c + scale * r.inBox(1.0f), 0)));
  }
  std::vector<Out> err = gpu.run(Fn::HitPointError, errs);
  MaxDiff dErr("hitPointError (relative)", 4 * kEps);
  for (size_t i = 0; i < n; ++i) {
    glm::vec4 b = arg(errs[i], 0);
    glm::vec3 c = hitPointError(b.x, b.y, b.z, glm::vec3(arg(errs[i], 1)), glm::vec3(arg(errs[i], 2)),
                                glm::vec3(arg(errs[i], 3)));
    for (int k = 0; k < 3; ++k)
      dErr.add(std::abs(double(err[i].f(0, k)) - c[k]) / std::max(double(c[k]), 1e-38),
               [&] { return str(errs[i]) + ": " + str(err[i].v(0)) + " vs " + str(c); });
  }
  dErr.check();

  std::vector<In> offs;
  for (float e : {0.0f, -0.0f, 1.0f, -1.0f, 1e4f, -1e4f, 1e-6f})
    for (const glm::vec3& nn : {glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::normalize(glm::vec3(1, -2, 3)),
                                glm::normalize(glm::vec3(1e-3f, -1e-3f, 1))})
      offs.push_back(floats(glm::vec4(e, -e, e, 0), glm::vec4(nn, 0), glm::vec4(glm::vec3(std::abs(e) * 4e-7f), 0)));
  while (offs.size() < n) {
    glm::vec3 p = r.inBox(1.0f) * r.logUniform(1e-8f, 1e8f);
    offs.push_back(floats(glm::vec4(p, 0), glm::vec4(r.unit(), 0), glm::vec4(glm::abs(p) * r.logUniform(1e-7f, 1e-5f), 0)));
  }
  std::vector<Out> off = gpu.run(Fn::OffsetRayOrigin, offs);
  MaxDiff dOff("offsetRayOrigin (in ULPs of the coordinate)", 4.0);
  for (size_t i = 0; i < n; ++i) {
    glm::vec3 p(arg(offs[i], 0)), nn(arg(offs[i], 1)), pe(arg(offs[i], 2));
    glm::vec3 c = offsetRayOrigin(p, pe, nn);
    for (int k = 0; k < 3; ++k) {
      float g = off[i].f(0, k);
      double ulp = std::max(double(std::nextafter(std::abs(c[k]), 1e38f) - std::abs(c[k])), 1e-45);
      dOff.add(std::abs(double(g) - c[k]) / ulp, [&] { return str(offs[i]) + ": " + str(off[i].v(0)) + " vs " + str(c); });
      // Whatever the rounding, both sides move the coordinate the way the normal points.
      if (nn[k] * pe[k] != 0.0f) CHECK((nn[k] > 0.0f ? g > p[k] : g < p[k]));
    }
  }
  dOff.check();
}

TEST_CASE("GLSL spectral functions equal their C++ twins: cauchyIor, channelSensitivity") {
  GlslTwins gpu;
  Random r(4);
  const size_t n = 4096;
  // cauchyIor: the three Fraunhofer lines and the range ends; no dispersion (abbe 0 or below).
  std::vector<In> ior;
  for (float lambda : {380.0f, 486.1f, 587.6f, 656.3f, 780.0f})
    for (float abbe : {0.0f, -1.0f, 20.0f, 60.0f}) ior.push_back(floats({1.5f, abbe, lambda, 0}));
  while (ior.size() < n) {
    float abbe = ior.size() % 10 == 0 ? 0.0f : r.uniform(15.0f, 90.0f);
    ior.push_back(floats({r.uniform(1.3f, 2.5f), abbe, r.uniform(380.0f, 780.0f), 0}));
  }
  // Divisions and sums only: measured 0 (one ULP allowed for division).
  compareOutput(gpu, Fn::CauchyIor, ior, MaxDiff("cauchyIor (relative)", kEps), Measure::Relative,
                [](const In& x) { return cauchyIor(arg(x, 0).x, arg(x, 0).y, arg(x, 0).z); });

  // channelSensitivity: the channel means, the range ends and beyond (tails down to underflow).
  std::vector<In> lambdas;
  for (float l : {380.0f, 460.0f, 545.0f, 610.0f, 780.0f, 300.0f, 900.0f}) lambdas.push_back(floats({l, 0, 0, 0}));
  while (lambdas.size() < n) lambdas.push_back(floats({r.uniform(300.0f, 900.0f), 0, 0, 0}));
  std::vector<Out> sens = gpu.run(Fn::ChannelSensitivity, lambdas);
  // exp(x) inherits the rounding of its argument x = -(lambda - mean)^2 / (2 sigma^2), so its relative
  // error grows with |x| (about |ln W|): the relative difference is divided by 1 + |ln W|.
  // Measured 1.3e-7 (about one ULP per unit of |x|; raw relative differences reach 9e-6 in the far tail).
  MaxDiff dSens("channelSensitivity (relative, over 1 + |ln W|)", 4 * kEps);
  for (size_t i = 0; i < n; ++i) {
    glm::vec3 c = channelSensitivity(arg(lambdas[i], 0).x), g = sens[i].v(0);
    for (int k = 0; k < 3; ++k)
      dSens.add(relDiff(g[k], c[k]) / (1.0 + std::abs(std::log(std::max(c[k], 1e-30f)))),
                [&] { return str(lambdas[i]) + ": " + str(g) + " vs " + str(c); });
  }
  dSens.check();
}

TEST_CASE("GLSL spotFalloff equals its C++ twin (KHR_lights_punctual cone falloff)") {
  GlslTwins gpu;
  Random r(7);
  std::vector<In> in;
  // The cone edges themselves, a hard edge (inner == outer) and random cones and angles.
  for (float c : {1.0f, std::cos(0.2f), std::cos(0.6f), 0.0f, -1.0f}) in.push_back(floats({c, std::cos(0.6f), std::cos(0.2f), 0}));
  in.push_back(floats({std::cos(0.29f), std::cos(0.3f), std::cos(0.3f), 0}));
  while (in.size() < 4096) {
    const float outer = r.uniform(0.01f, 1.5707963f), inner = r.uniform(0.0f, outer);
    in.push_back(floats({r.uniform(-1.0f, 1.0f), std::cos(outer), std::cos(inner), 0}));
  }
  // A subtraction, a division, a clamp and a square, values in [0, 1]: measured 0; a few ULP allowed.
  compareOutput(gpu, Fn::SpotFalloff, in, MaxDiff("spotFalloff", 4 * kEps), Measure::Absolute,
                [](const In& x) { return spotFalloff(arg(x, 0).x, arg(x, 0).y, arg(x, 0).z); });
}

TEST_CASE("GLSL octDecode equals its C++ twin (octahedral normals of the TriShade words)") {
  GlslTwins gpu;
  Random r(11);
  std::vector<In> in;
  for (std::uint32_t w : {gpu::kOctZeroNormal, 0u, 0x7fff7fffu, 0x80018001u, 0x7fff8001u, 0x00007fffu})
    in.push_back(uints({w, 0, 0, 0}));
  for (glm::vec3 v : {glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::vec3(1, 0, 0), glm::vec3(0, -1, 0)})
    in.push_back(uints({octEncode(v), 0, 0, 0}));
  while (in.size() < 4096) in.push_back(uints({octEncode(r.unit()), 0, 0, 0}));
  // unpackSnorm2x16, adds and a normalize: measured 0 difference on llvmpipe; a few ULP allowed.
  compareOutput(gpu, Fn::OctDecode, in, MaxDiff("octDecode", 4 * kEps), Measure::Absolute,
                [](const In& x) { return octDecode(x.w[0].x); });
}

TEST_CASE("GLSL floorMod and wrapCoord equal their C++ twins bit for bit (texture wrap without integer division)") {
  GlslTwins gpu;
  Random r(13);
  std::vector<In> in;
  auto add = [&](int i, int n) { in.push_back(uints({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(n), 0, 0})); };
  for (int n : {1, 2, 3, 7, 255, 256, 1023, 4096, 16384, (1 << 19) + 1, (1 << 20) - 1, 1 << 20})  // up to the claimed 2^20
    for (int i : {0, -1, 1, 10000001, -10000001, 9999999, -9999999, n - 1, n, n + 1, -n - 1, -n, -n + 1, 2 * n - 1, 2 * n,
                  -2 * n, 10000000 / n * n, -(10000000 / n * n) - 1})
      add(i, n);
  while (in.size() < 8192) add(static_cast<int>(r.g() % 20000003u) - 10000001, 1 + static_cast<int>(r.g() % 16384u));
  // Integer results of exact float steps (texture_wrap.glsl): every value must agree, and the C++ twin
  // equals the integer-division forms (tests/shading/texture_wrap_test.cpp).
  std::vector<Out> out = gpu.run(Fn::WrapCoord, in);
  Mismatches m("floorMod / wrapCoord (clamp, repeat, mirror)");
  for (size_t k = 0; k < in.size(); ++k) {
    const int i = static_cast<int>(in[k].w[0].x), n = static_cast<int>(in[k].w[0].y);
    const glm::uvec4 want(static_cast<std::uint32_t>(floorMod(i, n)), static_cast<std::uint32_t>(wrapCoord(i, n, false, false)),
                          static_cast<std::uint32_t>(wrapCoord(i, n, true, false)), static_cast<std::uint32_t>(wrapCoord(i, n, false, true)));
    m.add(out[k].w[0] == want, [&] { return "i " + std::to_string(i) + ", n " + std::to_string(n); });
  }
  m.check();
}

TEST_CASE("GLSL caster functions equal their C++ twins: inCone, casterCone, sampleUniformCone, casterFacesLights") {
  GlslTwins gpu;
  Random r(5);
  const size_t n = 4096;

  // inCone: directions sampled in cones 0.5 to 1.5 times as wide, so that about half lie inside; the
  // axis itself; directions on the rim of the cone with its 1e-4 slack.
  std::vector<In> cone;
  while (cone.size() < n) {
    glm::vec3 axis = cone.size() % 8 == 0 ? edgeNormals()[cone.size() / 8 % edgeNormals().size()] : r.unit();
    float omc = cone.size() % 16 == 1 ? kCasterMinOneMinusCos : r.logUniform(1e-5f, 1.0f);
    float scale = r.uniform(0.5f, 1.5f);
    if (cone.size() % 32 == 3) scale = 1.0001f * (1.0f + (cone.size() % 64 == 3 ? kNudge : -kNudge));
    glm::vec2 u = cone.size() % 32 == 3 ? glm::vec2(1.0f, r.uniform()) : r.u2();
    glm::vec3 w = cone.size() % 32 == 2 ? axis : sampleUniformCone(axis, std::min(2.0f, omc * scale), u);
    cone.push_back(floats(glm::vec4(w, omc), glm::vec4(axis, 0)));
  }
  std::vector<Out> inside = gpu.run(Fn::InCone, cone);
  Mismatches mIn("inCone");
  for (size_t i = 0; i < n; ++i) {
    glm::vec3 w(arg(cone[i], 0)), axis(arg(cone[i], 1));
    float omc = arg(cone[i], 0).w;
    mIn.add(inside[i].b(0) == inCone(w, axis, omc),
            inCone(w, axis, omc * (1 - kNudge)) != inCone(w, axis, omc * (1 + kNudge)), [&] { return str(cone[i]); });
  }
  mIn.check();

  // casterCone: random spheres seen from 1e-3 to 1.2 radii away (inside, far and narrower than the
  // narrowest cone aimed at), points on the sphere, cones at the narrowest 1 - cos, cones at the horizon of n.
  std::vector<In> spheres;
  while (spheres.size() < n) {
    glm::vec3 p = r.inBox(2.0f), c = r.inBox(2.0f), nn = r.unit();
    float dist = glm::length(c - p), rad = dist * r.logUniform(1e-3f, 1.2f);
    glm::vec3 axis = (c - p) / dist;
    float k = spheres.size() % 3 == 0 ? 0.0f : (spheres.size() % 3 == 1 ? 1e-6f : -1e-4f);
    switch (spheres.size() % 8) {
      case 1:  // on the sphere (with its 1e-4 slack)
        rad = dist / std::sqrt(1.0001f) * (1.0f + k);
        break;
      case 2:  // the narrowest cone aimed at
        rad = dist * std::sqrt(kCasterMinOneMinusCos * (2.0f - kCasterMinOneMinusCos)) * (1.0f + k);
        break;
      case 3: {  // the cone touches the horizon of n: dot(n, axis) = -sin(half angle)
        float s = rad / dist * (1.0f + k);
        glm::vec3 perp = glm::normalize(glm::cross(axis, r.unit()));
        nn = glm::normalize(-s * axis + std::sqrt(std::max(0.0f, 1.0f - s * s)) * perp);
        break;
      }
      default:
        break;
    }
    spheres.push_back(floats(glm::vec4(p, 0), glm::vec4(nn, 0), glm::vec4(c, rad)));
  }
  std::vector<Out> cones = gpu.run(Fn::CasterCone, spheres);
  Mismatches mCone("casterCone: usable");
  // Axis: d / sqrt(dot(d, d)), measured 1.2e-7 (one ULP of 1). 1 - cos = sin2 / (1 + sqrt(1 - sin2)) is
  // ill-conditioned next to the sphere (sin2 -> 1): compared beyond its spread under radius * (1 +- kNudge).
  MaxDiff dAxis("casterCone axis", 4 * kEps), dOmc("casterCone 1 - cos (relative, beyond its spread)", 4 * kEps);
  for (size_t i = 0; i < n; ++i) {
    glm::vec3 p(arg(spheres[i], 0)), nn(arg(spheres[i], 1)), axis;
    glm::vec4 s = arg(spheres[i], 2);
    float omc;
    bool ok = casterCone(p, nn, s, axis, omc);
    // The C++ twin with the radius scaled and n tilted by kNudge towards the axis (dot(n, axis) is
    // compared with -sin of the half angle: an absolute rounding, which a relative radius change misses).
    auto at = [&](float radiusScale, float tilt, float& o) {
      glm::vec3 a;
      return casterCone(p, glm::normalize(nn + tilt * axis), glm::vec4(glm::vec3(s), s.w * radiusScale), a, o);
    };
    float o0, o1, o2, o3;
    bool onThreshold =
        at(1.0f - kNudge, 0.0f, o0) != at(1.0f + kNudge, 0.0f, o1) || at(1.0f, -kNudge, o2) != at(1.0f, kNudge, o3);
    const Out& g = cones[i];
    bool same = g.b(1) == ok;
    mCone.add(same, onThreshold,
              [&] { return str(spheres[i]) + ": " + std::to_string(g.b(1)) + " vs " + std::to_string(ok); });
    if (!same) continue;  // also the axis and 1 - cos: a rejected sphere leaves them at their defaults
    dAxis.add(absDiff(g.v(0), axis), [&] { return str(spheres[i]) + ": " + str(g.v(0)) + " vs " + str(axis); });
    double spread = std::max(relDiff(o0, omc), relDiff(o1, omc));
    dOmc.add(relDiff(g.f(0, 3), omc) - spread,
             [&] { return str(spheres[i]) + ": " + str(g.f(0, 3)) + " vs " + str(omc); });
  }
  mCone.check();
  dAxis.check();
  dOmc.check();

  // sampleUniformCone: axes at and near the poles of orthonormalBasis, cones from the narrowest to the sphere.
  std::vector<In> uc;
  for (const glm::vec3& axis : edgeNormals())
    for (float omc : {kCasterMinOneMinusCos, 1e-3f, 1.0f, 2.0f})
      for (float u : kUEdges) uc.push_back(floats(glm::vec4(axis, omc), glm::vec4(u, 1.0f - u, 0, 0)));
  while (uc.size() < n) uc.push_back(floats(glm::vec4(r.unit(), r.logUniform(1e-5f, 2.0f)), glm::vec4(r.u2(), 0, 0)));
  // orthonormalBasis, cos and sin of phi, normalize: measured 1.8e-7 (1.5 ULP of 1). Narrow cones stay
  // sensitive: at 1 - cos = 1e-5 the direction is 4.5e-3 from the axis, 1e4 times this tolerance.
  compareOutput(gpu, Fn::SampleUniformCone, uc, MaxDiff("sampleUniformCone", 4 * kEps), Measure::Absolute,
                [](const In& x) { return sampleUniformCone(glm::vec3(arg(x, 0)), arg(x, 0).w, glm::vec2(arg(x, 1))); });

  // casterFacesLights: random caster cones and light spheres (also none: radius < 0, and p inside it),
  // and lights placed just outside the band of kAsinBand around the angle where the answer switches
  // (the cones' half angles plus the margin), a few right on it.
  std::vector<In> faces;
  const float margins[] = {0.0f, 0.05f, 0.2f};
  while (faces.size() < n) {
    glm::vec3 p = r.inBox(2.0f), axis = r.unit(), lc = r.inBox(2.0f);
    float omc = r.logUniform(1e-5f, 0.5f), lr = r.logUniform(0.01f, 1.0f), margin = margins[faces.size() % 3];
    if (faces.size() % 20 == 0) lr = -1.0f;
    if (faces.size() % 20 == 1) lr = glm::length(lc - p) * 1.01f;
    if (faces.size() % 4 == 2) {
      float dist = r.uniform(0.5f, 3.0f);
      lr = dist * r.uniform(0.01f, 0.5f);
      float angle = std::asin(lr / dist) + std::asin(std::sqrt(omc * (2.0f - omc))) + margin;
      angle += faces.size() % 64 == 2 ? 0.0f : (faces.size() % 8 == 2 ? 2.0f : -2.0f) * kAsinBand;
      glm::vec3 perp = glm::normalize(glm::cross(axis, r.unit()));
      lc = p + dist * (std::cos(angle) * axis + std::sin(angle) * perp);
    }
    faces.push_back(floats(glm::vec4(p, margin), glm::vec4(axis, omc), glm::vec4(lc, lr)));
  }
  std::vector<Out> facing = gpu.run(Fn::CasterFacesLights, faces);
  Mismatches mFaces("casterFacesLights");
  for (size_t i = 0; i < n; ++i) {
    glm::vec4 a0 = arg(faces[i], 0), a1 = arg(faces[i], 1), lights = arg(faces[i], 2);
    auto facesAt = [&](float margin) { return casterFacesLights(glm::vec3(a0), glm::vec3(a1), a1.w, lights, margin); };
    bool c = facesAt(a0.w);
    mFaces.add(facing[i].b(0) == c, facesAt(a0.w - kAsinBand) != facesAt(a0.w + kAsinBand),
               [&] { return str(faces[i]) + ": " + std::to_string(facing[i].b(0)) + " vs " + std::to_string(c); });
  }
  mFaces.check();
}

namespace {

// A CasterParams block: `count` random spheres (refractive where refractMask has the bit), the lights'
// bounding sphere, the probability of aiming at a caster and the margin.
gpu::CasterParams casterScene(Random& r, std::uint32_t count, std::uint32_t refractMask, const glm::vec4& lights,
                              float probability, float margin, std::uint32_t aimMask = 0xffu) {
  gpu::CasterParams c{};
  c.count = glm::uvec4(count, refractMask, 0, 0);
  c.guide.z = aimMask;  // the casters a bounce may aim at (aimCasterMask)
  c.params = glm::vec4(probability, margin, 0, 0);
  c.lights = lights;
  for (std::uint32_t i = 0; i < count; ++i) c.sphere[i] = glm::vec4(r.inBox(2.0f), r.logUniform(0.02f, 0.6f));
  return c;
}

// The C++ twin on the spheres of a CasterParams block, with every radius scaled and the margin shifted;
// with guide cells (kGuideClasses per caster) and the block's guide probability where guideCells is given.
CasterVertex prepareCasters(const gpu::CasterParams& c, const glm::vec3& p, const glm::vec3& n, float u,
                            float radiusScale = 1.0f, float marginShift = 0.0f,
                            const glm::uvec4* guideCells = nullptr) {
  glm::vec4 spheres[CasterVertex::kMax];
  for (int i = 0; i < CasterVertex::kMax; ++i)
    spheres[i] = glm::vec4(glm::vec3(c.sphere[i]), c.sphere[i].w * radiusScale);
  return caustica::prepareCasters(p, n, u, spheres, c.count.x, c.count.y, c.lights, c.params.y + marginShift,
                                  guideCells, c.params.z, c.guide.z);
}

// The GPU's diffuseDirectionPdf gPdf against the C++ twin's on caster state v: relative where the caster
// term dominates (pdf > 1), absolute where the cosine term does (dot(n, w) carries an absolute rounding),
// beyond its spread: the pdf jumps at the cones' rims, so how far it moves as every rim moves by kNudge.
double pdfDifference(const CasterVertex& v, float a, const glm::vec3& n, const glm::vec3& w, float gPdf) {
  auto pdfAt = [&](float rimScale) {
    CasterVertex moved = v;
    for (std::uint32_t k = 0; k < v.usable; ++k) moved.oneMinusCos[k] *= rimScale;
    return diffuseDirectionPdf(moved, a, n, w);
  };
  float cPdf = pdfAt(1.0f);
  double spread = std::max(absDiff(pdfAt(1.0f - kNudge), cPdf), absDiff(pdfAt(1.0f + kNudge), cPdf));
  return (absDiff(gPdf, cPdf) - spread) / std::max(1.0, std::abs(static_cast<double>(cPdf)));
}

}  // namespace

TEST_CASE("GLSL caster state equals its C++ twin: prepareCasters, diffuseDirectionPdf, sampleDiffuseDirection") {
  GlslTwins gpu;
  Random r(6);
  const size_t n = 4096;
  const gpu::CasterParams scenes[] = {
      casterScene(r, 8, 0xa5u, glm::vec4(0.0f, 2.5f, 0.0f, 1.0f), 0.3f, 0.1f),  // every slot, some refractive
      casterScene(r, 8, 0xa5u, glm::vec4(0.0f, 2.5f, 0.0f, 1.0f), 0.3f, 0.1f, 0xb4u),  // some not aimed at
      casterScene(r, 3, 0x3u, glm::vec4(0.0f, 0.0f, 0.0f, -1.0f), 0.5f, 0.0f),  // no lights: refractive ones never
      casterScene(r, 5, 0x0u, glm::vec4(1.0f, 1.0f, 1.0f, 0.5f), 0.9f, 0.2f),   // mirrors only
      casterScene(r, 0, 0x0u, glm::vec4(0.0f, 2.5f, 0.0f, 0.4f), 0.3f, 0.05f),  // none: cosine sampling only
  };
  for (const gpu::CasterParams& scene : scenes) {
    CAPTURE(scene.count.x);
    // Points anywhere (also inside spheres), u at the ends; w for the pdf: sampled as the shader would
    // (in some cone when a caster is picked, up to its rim), or any direction; uPick also at the caster probability.
    std::vector<In> in;
    while (in.size() < n) {
      glm::vec3 p = r.inBox(3.0f), nn = r.unit();
      float u = in.size() % 64 == 0 ? 0.0f : (in.size() % 64 == 1 ? kLastBelowOne : r.uniform());
      CasterVertex v = prepareCasters(scene, p, nn, u);
      glm::vec2 uw(in.size() % 8 == 1 ? 1.0f : r.uniform(), r.uniform());
      glm::vec3 w = in.size() % 2 ? sampleDiffuseDirection(v, scene.params.x, nn, r.uniform(), uw) : r.unit();
      float uPick = in.size() % 16 == 5 ? scene.params.x : r.uniform();  // at the probability: cosine sampling
      in.push_back(floats(glm::vec4(p, u), glm::vec4(nn, uPick), glm::vec4(w, 0), glm::vec4(r.u2(), 0, 0)));
    }
    std::vector<Out> prep = gpu.run(Fn::PrepareCasters, in, scene), pdf = gpu.run(Fn::DiffuseDirectionPdf, in, scene),
                     dir = gpu.run(Fn::SampleDiffuseDirection, in, scene);
    Mismatches mUsable("prepareCasters: usable and pick");
    // Per usable caster as casterCone (measured: axis 1.2e-7, 1 - cos 2.5e-7 relative, away from the
    // sphere); 1 / (2 pi (1 - cos)) adds a product and a division: measured 3.4e-7.
    // diffuseDirectionPdf: relative where the caster term dominates (pdf > 1), absolute where the cosine
    // term does (dot(n, w) carries an absolute rounding); beyond its spread as the rims move: measured 2.8e-7.
    // sampleDiffuseDirection: as sampleUniformCone or cosine sampling in orthonormalBasis: measured 1.8e-7.
    MaxDiff dAxis("prepareCasters axis", 4 * kEps), dOmc("prepareCasters 1 - cos (relative)", 4 * kEps),
        dInv("prepareCasters 1 / solid angle (relative)", 8 * kEps),
        dPdf("diffuseDirectionPdf (relative above 1, absolute below; beyond its spread)", 8 * kEps),
        dDir("sampleDiffuseDirection", 4 * kEps);
    int usableRecords = 0, refusedByLights = 0, acceptedByLights = 0;
    for (size_t i = 0; i < n; ++i) {
      glm::vec3 p(arg(in[i], 0)), nn(arg(in[i], 1)), w(arg(in[i], 2));
      float u = arg(in[i], 0).w, uPick = arg(in[i], 1).w;
      CasterVertex v = prepareCasters(scene, p, nn, u);
      const Out& g = prep[i];
      bool same = g.w[0].x == v.usable && g.w[0].y == v.pick;
      CasterVertex lo = prepareCasters(scene, p, nn, u, 1.0f - kNudge, -kAsinBand),
                   hi = prepareCasters(scene, p, nn, u, 1.0f + kNudge, kAsinBand);
      mUsable.add(same, lo.usable != hi.usable || lo.pick != hi.pick, [&] {
        return str(in[i]) + ": " + std::to_string(g.w[0].x) + ", " + std::to_string(g.w[0].y) + " vs " +
               std::to_string(v.usable) + ", " + std::to_string(v.pick);
      });
      if (!same) continue;
      usableRecords += v.usable > 0;
      gpu::CasterParams mirrorsOnly = scene;
      mirrorsOnly.count.y = 0;
      refusedByLights += prepareCasters(mirrorsOnly, p, nn, u).usable > v.usable;
      gpu::CasterParams noLights = scene;
      noLights.lights.w = -1.0f;  // refractive casters never usable
      acceptedByLights += prepareCasters(noLights, p, nn, u).usable < v.usable;
      for (std::uint32_t k = 0; k < v.usable; ++k) {
        auto where = [&] { return str(in[i]) + ", caster " + std::to_string(k); };
        dAxis.add(absDiff(g.v(1 + k), v.axis[k]), where);
        dOmc.add(relDiff(g.f(1 + k, 3), v.oneMinusCos[k]), where);
        dInv.add(relDiff(g.f(9 + k / 4, k % 4), v.invSolidAngle[k]), where);
      }
      float gPdf = pdf[i].f(0), cPdf = diffuseDirectionPdf(v, scene.params.x, nn, w);
      dPdf.add(pdfDifference(v, scene.params.x, nn, w, gPdf), [&] { return str(in[i]) + ": " + str(gPdf) + " vs " + str(cPdf); });
      glm::vec3 cDir = sampleDiffuseDirection(v, scene.params.x, nn, uPick, glm::vec2(arg(in[i], 3)));
      dDir.add(absDiff(dir[i].v(0), cDir), [&] { return str(in[i]) + ": " + str(dir[i].v(0)) + " vs " + str(cDir); });
    }
    mUsable.check();
    dAxis.check();
    dOmc.check();
    dInv.check();
    dPdf.check();
    dDir.check();
    // The inputs reach every outcome: points that see casters, refractive casters refused and accepted by
    // casterFacesLights.
    if (scene.count.x > 0) CHECK(usableRecords > static_cast<int>(n) / 10);
    if (scene.count.y != 0) CHECK(refusedByLights > static_cast<int>(n) / 20);
    if (scene.count.y != 0 && scene.lights.w >= 0.0f) CHECK(acceptedByLights > static_cast<int>(n) / 20);
    if (reportWanted())
      MESSAGE(usableRecords, " records see casters; in ", refusedByLights,
              " casterFacesLights refuses a refractive one, in ", acceptedByLights, " it accepts one");
  }
}

namespace {

constexpr int kCellsPerRecord = kGuideClasses * CasterVertex::kMax;

// Random guide cells at a vertex with unit normal n, kGuideClasses per caster slot: none, too few
// photons, photons from below, no mean direction, or a lobe about a direction mostly above the surface,
// from wide (mean resultant length 0.001, kappa 0.003) to the narrowest (all photons alike).
void randomGuideCells(Random& r, const glm::vec3& n, glm::uvec4* cells) {
  for (int j = 0; j < kCellsPerRecord; ++j) {
    int kind = std::min(static_cast<int>(r.uniform() * 8.0f), 7);
    std::uint32_t count = kind == 0 ? 0u : (kind == 1 ? kMinGuidePhotons - 1 : static_cast<std::uint32_t>(r.logUniform(8.0f, 1e5f)));
    glm::vec3 dir = glm::normalize(r.unit() + 1.2f * n);
    if (kind == 2) dir = -dir;
    float len = kind == 3 ? 5e-4f : (kind == 7 ? 1.0f : 1.0f - r.logUniform(1e-5f, 0.999f));
    glm::ivec3 sum(glm::round(dir * len * static_cast<float>(count) * gpu::kCellDirScale));
    cells[j] = glm::uvec4(count, glm::uvec3(sum));
  }
}

// The caster state the GPU's prepareCasters left (Fn::PrepareCasters with CAUSTICA_GUIDING), as the C++
// twin holds it: the C++ pdf and sampler run on it to compare them alone.
CasterVertex casterVertexOf(const Out& g) {
  CasterVertex v;
  v.usable = g.w[0].x;
  v.pick = g.w[0].y;
  for (std::uint32_t k = 0; k < v.usable && k < static_cast<std::uint32_t>(CasterVertex::kMax); ++k) {
    v.axis[k] = g.v(1 + k);
    v.oneMinusCos[k] = g.f(1 + k, 3);
    v.invSolidAngle[k] = g.f(9 + k / 4, k % 4);
  }
  for (std::uint32_t j = 0; j < kGuideClasses * v.usable && j < static_cast<std::uint32_t>(kCellsPerRecord); ++j) {
    v.guideAxis[j] = g.v(11 + j);
    v.guideKappa[j] = g.f(11 + j, 3);
    v.guideNorm[j] = g.f(27 + j / 4, j % 4);
    v.guideWeight[j] = g.f(31 + j / 4, j % 4);
  }
  return v;
}

// How far the guided sampler's direction (cDir) moves where it samples a guide lobe as 1 - cos theta
// moves by 8 eps / kappa + 4 eps (1 - cos theta) (the log's absolute error, twice that measured for
// vmfOneMinusCos, and its relative rounding), through u.x: d(1 - cos theta)/du = (1 - e) / (kappa x),
// e = exp(-2 kappa), x = u + (1 - u) e. 0 for the cones and cosine sampling. Large where the lobe is
// sampled next to its axis or its antipode (the direction moves as the square root of 1 - cos theta
// or of 1 + cos theta there). llvmpipe flushes e to 0 where it is a float denormal (kappa 43.7 to 51.9),
// so at u.x = 0 the shader then draws the antipode exactly.
double lobeSpread(const CasterVertex& v, float a, const glm::vec3& n, float uPick, const glm::vec2& u, const glm::vec3& cDir) {
  if (v.usable == 0 || !(uPick < a)) return 0.0;
  float pick = uPick / a, run = 0.0f;
  int lobe = -1;
  for (int c = 0; c < kGuideClasses; ++c) {
    int j = kGuideClasses * static_cast<int>(v.pick) + c;
    float w0 = run;
    run += v.guideWeight[j];
    if (pick >= w0 && pick < run) lobe = j;
  }
  if (lobe < 0) return 0.0;
  double k = v.guideKappa[lobe], e = std::exp(-2.0 * k), x = u.x + (1.0 - u.x) * e;
  double dt = 8.0 * kEps / k + 4.0 * kEps * vmfOneMinusCos(v.guideKappa[lobe], u.x);
  double du = dt * k * x / (1.0 - e), spread = 0.0;
  for (double sign : {-1.0, 1.0}) {
    float moved = static_cast<float>(std::clamp(u.x + sign * du, 0.0, static_cast<double>(kLastBelowOne)));
    spread = std::max(spread, absDiff(sampleDiffuseDirection(v, a, n, uPick, glm::vec2(moved, u.y)), cDir));
  }
  if (u.x == 0.0f && static_cast<float>(e) < std::numeric_limits<float>::min())
    spread = std::max(spread, absDiff(-v.guideAxis[lobe], cDir));
  return spread;
}

}  // namespace

TEST_CASE("GLSL caster guiding equals its C++ twin: guideLobe; prepareCasters, diffuseDirectionPdf, sampleDiffuseDirection with guide lobes") {
  GlslTwins gpu({"CAUSTICA_GUIDING"});
  Random r(7);
  const size_t n = 4096;

  // kappa = r (3 - r^2) / (1 - r^2) with r up to 0.9999: 1 - r^2 cancels (llvmpipe contracts it to an
  // fma, the C++ twin rounds r^2 first), so kappa's relative error is about eps / (1 - r^2), which lies
  // between kappa / 4 and 1 + kappa: relative differences are compared in units of 1 + kappa.
  auto kappaDiff = [](float g, float c) { return relDiff(g, c) / (1.0 + c); };

  // vmfOneMinusCos and vmfNorm: kappa over the range guideLobe gives, u also at its ends.
  std::vector<In> vmf;
  for (float kappa : {3e-3f, 0.01f, 1.0f, 200.0f, 1e4f})
    for (float u : kUEdges) vmf.push_back(floats(glm::vec4(kappa, u, 0, 0)));
  while (vmf.size() < n) vmf.push_back(floats(glm::vec4(r.logUniform(3e-3f, 1e4f), r.uniform(), 0, 0)));
  std::vector<Out> vmfOut = gpu.run(Fn::Vmf, vmf);
  // 1 - cos theta = -log(x) / kappa: the log's absolute error over kappa (llvmpipe's log and exp against
  // libm's): measured 5.5e-7 (4.6 ULP of 1). vmfNorm: 1 - exp(-2 kappa) cancels for small kappa, so its
  // relative error is eps / (1 - exp(-2 kappa)) (1e-5 at kappa 0.003): measured, in those units, 1.8e-7.
  MaxDiff dVmfT("vmfOneMinusCos times kappa (the log's absolute error)", 8 * kEps),
      dVmfNorm("vmfNorm (relative, times 1 - exp(-2 kappa))", 4 * kEps);
  for (size_t i = 0; i < vmf.size(); ++i) {
    glm::vec4 a = arg(vmf[i], 0);
    auto where = [&] { return "kappa " + str(a.x) + " u " + str(a.y) + ": " + str(vmfOut[i].f(0, 0)) + " vs " + str(vmfOneMinusCos(a.x, a.y)); };
    dVmfT.add(absDiff(vmfOut[i].f(0, 0), vmfOneMinusCos(a.x, a.y)) * a.x, where);
    dVmfNorm.add(relDiff(vmfOut[i].f(0, 1), vmfNorm(a.x)) * -std::expm1(-2.0 * a.x), where);
  }
  dVmfT.check();
  dVmfNorm.check();

  // guideLobe on random cells and normals.
  std::vector<In> lobes;
  while (lobes.size() < n) {
    glm::vec3 nn = r.unit();
    glm::uvec4 cells[kCellsPerRecord];
    randomGuideCells(r, nn, cells);
    for (const glm::uvec4& c : cells) {
      In x;
      x.w[0] = c;
      x.w[1] = sameBits<glm::uvec4>(glm::vec4(nn, 0.0f));
      lobes.push_back(x);
    }
  }
  std::vector<Out> fitted = gpu.run(Fn::GuideLobe, lobes);
  Mismatches mLobe("guideLobe: a lobe or none");
  // The axis: a division by the sum's length: measured 1.2e-7. kappa in units of 1 + kappa (above): measured 9.1e-8.
  MaxDiff dLobeAxis("guideLobe axis", 4 * kEps), dKappa("guideLobe kappa (relative, over 1 + kappa)", 4 * kEps);
  int lobeRecords = 0;
  for (size_t i = 0; i < lobes.size(); ++i) {
    glm::vec3 nn(arg(lobes[i], 1)), axis;
    float kappa;
    bool ok = guideLobe(lobes[i].w[0], nn, axis, kappa);
    auto where = [&] {
      const glm::uvec4& c = lobes[i].w[0];
      return "cell (" + std::to_string(c.x) + ", " + std::to_string(int(c.y)) + ", " + std::to_string(int(c.z)) + ", " +
             std::to_string(int(c.w)) + ") n " + str(nn);
    };
    mLobe.add(fitted[i].b(1) == ok, where);
    if (fitted[i].b(1) != ok) continue;
    lobeRecords += ok;
    dLobeAxis.add(absDiff(fitted[i].v(0), axis), where);
    if (ok) dKappa.add(kappaDiff(fitted[i].f(0, 3), kappa), where);
  }
  mLobe.check();
  dLobeAxis.check();
  dKappa.check();
  CHECK(lobeRecords > static_cast<int>(lobes.size()) / 3);

  gpu::CasterParams scenes[] = {
      casterScene(r, 8, 0xa5u, glm::vec4(0.0f, 2.5f, 0.0f, 1.0f), 0.3f, 0.1f),  // every slot, some refractive
      casterScene(r, 8, 0xa5u, glm::vec4(0.0f, 2.5f, 0.0f, 1.0f), 0.3f, 0.1f, 0x3cu),  // some cones not aimed at: lobes only
      casterScene(r, 3, 0x3u, glm::vec4(0.0f, 0.0f, 0.0f, -1.0f), 0.6f, 0.0f),  // no lights: refractive ones by lobes only
      casterScene(r, 5, 0x0u, glm::vec4(1.0f, 1.0f, 1.0f, 0.5f), 0.9f, 0.2f),   // mirrors only
  };
  const float guideProbabilities[] = {0.5f, 1.0f, 0.25f};  // 1: the cones give way to the lobes wholly
  for (int sc = 0; sc < 3; ++sc) {
    gpu::CasterParams& scene = scenes[sc];
    scene.params.z = guideProbabilities[sc];
    CAPTURE(sc);
    std::vector<In> in;
    std::vector<glm::uvec4> cells(n * kCellsPerRecord);
    while (in.size() < n) {
      glm::vec3 p = r.inBox(3.0f), nn = r.unit();
      glm::uvec4* c = &cells[in.size() * kCellsPerRecord];
      randomGuideCells(r, nn, c);
      float u = in.size() % 64 == 0 ? 0.0f : (in.size() % 64 == 1 ? kLastBelowOne : r.uniform());
      CasterVertex v = prepareCasters(scene, p, nn, u, 1.0f, 0.0f, c);
      glm::vec2 uw(in.size() % 8 == 1 ? 1.0f : r.uniform(), r.uniform());
      glm::vec3 w = in.size() % 2 ? sampleDiffuseDirection(v, scene.params.x, nn, r.uniform(), uw) : r.unit();
      float uPick = in.size() % 16 == 5 ? scene.params.x : r.uniform();
      glm::vec2 us = in.size() % 32 == 3 ? glm::vec2(0.0f, 0.5f) : (in.size() % 32 == 4 ? glm::vec2(kLastBelowOne, 0.5f) : r.u2());
      in.push_back(floats(glm::vec4(p, u), glm::vec4(nn, uPick), glm::vec4(w, 0), glm::vec4(us, 0, 0)));
    }
    std::vector<Out> prep = gpu.run(Fn::PrepareCasters, in, scene, cells),
                     pdf = gpu.run(Fn::DiffuseDirectionPdf, in, scene, cells),
                     dir = gpu.run(Fn::SampleDiffuseDirection, in, scene, cells);
    Mismatches mUsable("guided prepareCasters: usable and pick");
    // Cones as in the unguided test above (1 - cos measured 4.3e-7 here, near a sphere). Lobes: axis and kappa as guideLobe; the norm as kappa and
    // vmfNorm's cancellation (units of 1 + kappa + 1 / (1 - exp(-2 kappa))); weights are exact
    // (guideProbability over 1 or 2). The pdf on the GPU's state: as unguided, and the lobes' exp of
    // kappa t up to log(norm) = 7.4 (where the pdf passes 1) carries 7.4 eps of relative error: measured 6.1e-7.
    // The direction: as unguided, and beyond its spread as a lobe's 1 - cos theta moves by the log's
    // error (lobeSpread): measured 1.2e-7.
    MaxDiff dAxis("guided prepareCasters cone axis", 4 * kEps), dOmc("guided prepareCasters 1 - cos (relative)", 8 * kEps),
        dInv("guided prepareCasters 1 / solid angle (relative)", 8 * kEps),
        dGAxis("guided prepareCasters lobe axis", 4 * kEps), dGKappa("guided prepareCasters lobe kappa (relative, over 1 + kappa)", 4 * kEps),
        dGNorm("guided prepareCasters lobe norm (relative, in units of its condition)", 4 * kEps),
        dGWeight("guided prepareCasters lobe weight (relative)", 0.0),
        dPdf("guided diffuseDirectionPdf (relative above 1, absolute below; beyond its spread)", 16 * kEps),
        dDir("guided sampleDiffuseDirection (beyond its spread)", 4 * kEps);
    int lobeSamples = 0, lobesPrepared = 0;
    for (size_t i = 0; i < n; ++i) {
      glm::vec3 p(arg(in[i], 0)), nn(arg(in[i], 1)), w(arg(in[i], 2));
      float u = arg(in[i], 0).w, uPick = arg(in[i], 1).w;
      const glm::uvec4* c = &cells[i * kCellsPerRecord];
      CasterVertex v = prepareCasters(scene, p, nn, u, 1.0f, 0.0f, c);
      const Out& g = prep[i];
      bool same = g.w[0].x == v.usable && g.w[0].y == v.pick;
      CasterVertex lo = prepareCasters(scene, p, nn, u, 1.0f - kNudge, -kAsinBand, c),
                   hi = prepareCasters(scene, p, nn, u, 1.0f + kNudge, kAsinBand, c);
      mUsable.add(same, lo.usable != hi.usable || lo.pick != hi.pick, [&] {
        return str(in[i]) + ": " + std::to_string(g.w[0].x) + ", " + std::to_string(g.w[0].y) + " vs " +
               std::to_string(v.usable) + ", " + std::to_string(v.pick);
      });
      if (!same) continue;
      for (std::uint32_t k = 0; k < v.usable; ++k) {
        auto where = [&] { return str(in[i]) + ", caster " + std::to_string(k); };
        dAxis.add(absDiff(g.v(1 + k), v.axis[k]), where);
        dOmc.add(relDiff(g.f(1 + k, 3), v.oneMinusCos[k]), where);
        dInv.add(relDiff(g.f(9 + k / 4, k % 4), v.invSolidAngle[k]), where);
        for (std::uint32_t cl = 0; cl < static_cast<std::uint32_t>(kGuideClasses); ++cl) {
          std::uint32_t j = kGuideClasses * k + cl;
          dGWeight.add(relDiff(g.f(31 + j / 4, j % 4), v.guideWeight[j]), where);
          if (v.guideWeight[j] == 0.0f) continue;
          ++lobesPrepared;
          dGAxis.add(absDiff(g.v(11 + j), v.guideAxis[j]), where);
          double kappa = v.guideKappa[j];
          dGKappa.add(kappaDiff(g.f(11 + j, 3), v.guideKappa[j]), where);
          dGNorm.add(relDiff(g.f(27 + j / 4, j % 4), v.guideNorm[j]) / (1.0 + kappa - 1.0 / std::expm1(-2.0 * kappa)), where);
        }
      }
      // The pdf and the sampler on the GPU's state: their own arithmetic alone.
      CasterVertex gv = casterVertexOf(g);
      float gPdf = pdf[i].f(0), cPdf = diffuseDirectionPdf(gv, scene.params.x, nn, w);
      dPdf.add(pdfDifference(gv, scene.params.x, nn, w, gPdf), [&] { return str(in[i]) + ": " + str(gPdf) + " vs " + str(cPdf); });
      glm::vec2 us(arg(in[i], 3));
      glm::vec3 cDir = sampleDiffuseDirection(gv, scene.params.x, nn, uPick, us);
      dDir.add(absDiff(dir[i].v(0), cDir) - lobeSpread(gv, scene.params.x, nn, uPick, us, cDir),
               [&] { return str(in[i]) + ": " + str(dir[i].v(0)) + " vs " + str(cDir); });
      if (gv.usable > 0 && uPick < scene.params.x) {
        float pick = uPick / scene.params.x;
        std::uint32_t j = kGuideClasses * gv.pick;
        lobeSamples += pick < gv.guideWeight[j] + gv.guideWeight[j + 1];
      }
    }
    mUsable.check();
    dAxis.check();
    dOmc.check();
    dInv.check();
    dGAxis.check();
    dGKappa.check();
    dGNorm.check();
    dGWeight.check();
    dPdf.check();
    dDir.check();
    // The inputs reach the lobes: prepared, and sampled from.
    CHECK(lobesPrepared > static_cast<int>(n));
    CHECK(lobeSamples > static_cast<int>(n) / 20);
    if (reportWanted()) MESSAGE(lobesPrepared, " lobes prepared; ", lobeSamples, " records sample a lobe");
  }
}

TEST_CASE("GLSL GGX lobes equal their C++ twins: ggxD, ggxLambda, ggxG1, ggxG2, visible normals, bsdfEval, bsdfPdf, bsdfSample") {
  GlslTwins gpu;
  Random r(16);
  const size_t n = 8192;
  // Directions on the upper hemisphere (wo) down to grazing, and on the whole sphere (wi).
  auto upper = [&] {
    glm::vec3 w = r.unit();
    w.z = std::abs(w.z);
    return w.z > 1e-4f ? w : glm::normalize(w + glm::vec3(0, 0, 1e-3f));
  };
  auto relVec = [](const glm::vec3& g, const glm::vec3& c, double floor) {
    double d = 0;
    for (int k = 0; k < 3; ++k) d = std::max(d, relDiff(g[k], c[k], floor));
    return d;
  };

  std::vector<In> hs;
  while (hs.size() < n) hs.push_back(floats(glm::vec4(upper(), r.logUniform(0.01f, 1.0f)), glm::vec4(r.unit(), 0)));
  std::vector<Out> ggx = gpu.run(Fn::Ggx, hs);
  // D: a square, a sum and a division, all well conditioned for alpha >= 0.01 (no cancellation): measured 3.6e-7.
  // Lambda, G1, G2: one division by cos^2 and a sqrt: measured 2.4e-7.
  MaxDiff dD("ggxD (relative)", 8 * kEps), dG("ggxLambda, ggxG1, ggxG2 (relative)", 8 * kEps);
  for (size_t i = 0; i < n; ++i) {
    glm::vec4 a = arg(hs[i], 0);
    glm::vec3 h(a), wi(arg(hs[i], 1));
    dD.add(relDiff(ggx[i].f(0, 0), ggxD(h, a.w), 1e-20), [&] { return str(hs[i]); });
    double g = std::max({relDiff(ggx[i].f(0, 1), ggxLambda(h, a.w), 1e-6), relDiff(ggx[i].f(0, 2), ggxG1(h, a.w)),
                         relDiff(ggx[i].f(0, 3), ggxG2(h, wi, a.w))});
    dG.add(g, [&] { return str(hs[i]); });
  }
  dD.check();
  dG.check();

  std::vector<In> vn;
  for (float a : kUEdges)
    for (float b : kUEdges) vn.push_back(floats(glm::vec4(glm::normalize(glm::vec3(0.3f, -0.2f, 0.5f)), 0.3f), {a, b, 0, 0}));
  while (vn.size() < n) vn.push_back(floats(glm::vec4(upper(), r.logUniform(0.01f, 1.0f)), glm::vec4(r.u2(), 0, 0)));
  std::vector<Out> vis = gpu.run(Fn::GgxSampleVisibleNormal, vn);
  // cos and sin of phi, sqrt, two normalisations, amplified by 1 / alpha where the unstretching divides
  // a small h.z: measured 1.3e-6. The pdf at the GPU's h, relative: measured 3.7e-7.
  MaxDiff dH("ggxSampleVisibleNormal h", 32 * kEps), dHp("ggxVisibleNormalPdf (relative)", 8 * kEps);
  for (size_t i = 0; i < n; ++i) {
    glm::vec4 a = arg(vn[i], 0);
    glm::vec3 h = ggxSampleVisibleNormal(glm::vec3(a), a.w, glm::vec2(arg(vn[i], 1)));
    dH.add(absDiff(vis[i].v(0), h), [&] { return str(vn[i]) + ": " + str(vis[i].v(0)) + " vs " + str(h); });
    float pdf = ggxVisibleNormalPdf(glm::vec3(a), vis[i].v(0), a.w);  // at the GPU's h: isolates the pdf
    dHp.add(relDiff(vis[i].f(0, 3), pdf, 1e-3), [&] { return str(vn[i]); });
  }
  dH.check();
  dHp.check();

  const float lobes[] = {float(kLobeConductor), float(kLobePlastic), float(kLobeRoughGlass), float(kLobeSheen)};
  std::vector<In> ev, sm;
  while (ev.size() < n) {
    float lobe = lobes[(ev.size() / 6) % 4];  // every lobe with every eta below
    float eta = kEtas[ev.size() % 6];  // 1.5, 1/1.5, 1.33, 1/1.33, 2.4, 1/2.4 (ior 1 never takes a rough lobe)
    glm::vec4 a0(upper(), r.logUniform(0.02f, 1.0f));
    glm::vec4 a2(r.uniform(), r.uniform(), r.uniform(), lobe), a3(r.uniform(0.0f, 0.1f), r.uniform(), 0, 0);
    ev.push_back(floats(a0, glm::vec4(r.unit(), eta), a2, a3));
    sm.push_back(floats(a0, glm::vec4(r.uniform(), r.uniform(), r.uniform(), eta), a2, a3));
  }
  auto bsdfOf = [](const In& x) {
    Bsdf b;
    b.lobe = std::uint32_t(arg(x, 2).w);
    b.color = glm::vec3(arg(x, 2));
    b.alpha = arg(x, 0).w;
    b.eta = arg(x, 1).w;
    b.f0 = glm::vec3(arg(x, 3).x);
    b.f90 = arg(x, 3).y;
    return b;
  };
  std::vector<Out> evo = gpu.run(Fn::BsdfEvalPdf, ev);
  // f and pdf relative to max(value, 1e-3): measured 5.6e-4 and 4.9e-5, both at rough refraction out of a
  // dense medium (eta 1/2.4): the generalised half vector eta wi + wo nearly cancels there, and D and the
  // Jacobian amplify its few-ULP difference (dot products that llvmpipe fuses and orders differently).
  // The sheen lobe alone: its D's pow and the Lambda fit's exp (above), measured 1.1e-5.
  MaxDiff dF("bsdfEval (relative)", 2e-3), dP("bsdfPdf (relative)", 2e-3), dFs("bsdfEval, sheen (relative)", 256 * kEps);
  for (size_t i = 0; i < n; ++i) {
    Bsdf b = bsdfOf(ev[i]);
    glm::vec3 wo(arg(ev[i], 0)), wi(arg(ev[i], 1));
    glm::vec3 f = bsdfEval(b, wo, wi);
    dF.add(relVec(evo[i].v(0), f, 1e-3), [&] { return str(ev[i]) + ": " + str(evo[i].v(0)) + " vs " + str(f); });
    if (b.lobe == kLobeSheen)
      dFs.add(relVec(evo[i].v(0), f, 1e-3), [&] { return str(ev[i]) + ": " + str(evo[i].v(0)) + " vs " + str(f); });
    dP.add(relDiff(evo[i].f(0, 3), bsdfPdf(b, wo, wi), 1e-3), [&] { return str(ev[i]); });
  }
  dF.check();
  dFs.check();
  dP.check();

  std::vector<Out> smo = gpu.run(Fn::BsdfSample, sm);
  // Measured 4.1e-6 on wi (one ULP of u amplified as in h above) and 6.1e-5 on the weight.
  MaxDiff dWi("bsdfSample wi", 1e-5), dW("bsdfSample weight (relative)", 5e-4);
  Mismatches okSame("bsdfSample success and transmitted");
  for (size_t i = 0; i < n; ++i) {
    Bsdf b = bsdfOf(sm[i]);
    glm::vec3 wo(arg(sm[i], 0)), u(arg(sm[i], 1));
    BsdfSample s;
    bool ok = bsdfSample(b, wo, u, s);
    // The choice between parts compares u.x with a Fresnel value; a direction with z within 1e-5 of 0 may
    // land on either side of the surface.
    bool threshold = std::abs(s.wi.z) < 1e-5f;
    okSame.add(ok == smo[i].b(2, 1) && (!ok || s.transmitted == smo[i].b(2, 0)), threshold, [&] { return str(sm[i]); });
    if (!ok || !smo[i].b(2, 1) || s.transmitted != smo[i].b(2, 0)) continue;
    dWi.add(absDiff(smo[i].v(0), s.wi), [&] { return str(sm[i]) + ": " + str(smo[i].v(0)) + " vs " + str(s.wi); });
    dW.add(relVec(smo[i].v(1), s.weight, 1e-3), [&] { return str(sm[i]) + ": " + str(smo[i].v(1)) + " vs " + str(s.weight); });
  }
  okSame.check();
  dWi.check();
  dW.check();
}

TEST_CASE("GLSL layers equal their C++ twins: coatFresnel, sheenD, sheenL, sheenLambda, sheenVisibility, sheenAlbedo, layerWeights, layeredAlbedo, sampleUniformHemisphere") {
  GlslTwins gpu;
  Random r(29);
  const size_t n = 8192;
  std::vector<In> in;
  while (in.size() < n) {
    // Half vectors over the whole upper hemisphere, grazing included; sheen roughness 0.07..1 (and a few
    // outside, which the table clamps); cosines down to 1e-4.
    glm::vec3 h = r.unit();
    h.z = std::abs(h.z);
    float rough = in.size() % 16 == 0 ? r.uniform(0.0f, 0.07f) : r.uniform(0.07f, 1.0f);
    glm::vec4 a0(glm::normalize(h), sheenRoughnessClamped(rough) * sheenRoughnessClamped(rough));
    glm::vec4 a1(r.logUniform(1e-4f, 1.0f), r.logUniform(1e-4f, 1.0f), rough, r.uniform(-1.0f, 1.0f));
    glm::vec4 a2(r.uniform(), r.uniform(), r.uniform(), r.uniform());
    if (in.size() % 8 == 1) a2 = glm::vec4(0.0f, 0.0f, 0.0f, a2.w);  // no sheen
    glm::vec4 a3(r.u2(), r.uniform(), in.size() % 8 == 2 ? 0.0f : r.uniform());
    in.push_back(floats(a0, a1, a2, a3));
  }
  std::vector<Out> out = gpu.run(Fn::Layers, in);
  auto relVec = [](const glm::vec3& g, const glm::vec3& c, double floor) {
    double d = 0;
    for (int k = 0; k < 3; ++k) d = std::max(d, relDiff(g[k], c[k], floor));
    return d;
  };
  // coatFresnel, the layer weights and the albedo: a few multiplications (measured 5.7e-7). sheenD: a pow
  // with exponent up to 102 amplifies one ULP of sin^2 by that much (measured 1.1e-5). sheenL: a sum of
  // terms up to 25 that may cancel, so absolute (measured 3.8e-6); sheenLambda and sheenVisibility:
  // exp of it (measured 4.6e-6 and 4.1e-6). sheenAlbedo: a bilinear lookup (measured 5.3e-7). The
  // hemisphere sample: cos and sin of 2 pi u (measured 6e-8).
  MaxDiff dCoat("coatFresnel, layerWeights, layeredAlbedo (relative)", 8 * kEps);
  MaxDiff dD("sheenD (relative)", 128 * kEps), dL("sheenL (absolute; its terms are up to 25)", 64 * kEps);
  MaxDiff dLam("sheenLambda (relative)", 64 * kEps), dV("sheenVisibility (relative)", 64 * kEps);
  MaxDiff dE("sheenAlbedo (relative)", 8 * kEps), dDir("sampleUniformHemisphere", 8 * kEps);
  for (size_t i = 0; i < n; ++i) {
    glm::vec4 a0 = arg(in[i], 0), a1 = arg(in[i], 1), a2 = arg(in[i], 2), a3 = arg(in[i], 3);
    const auto where = [&] { return str(in[i]); };
    dD.add(relDiff(out[i].f(0, 0), sheenD(glm::vec3(a0), a0.w), 1e-20), where);
    dLam.add(relDiff(out[i].f(0, 1), sheenLambda(a1.x, a0.w), 1e-20), where);
    dV.add(relDiff(out[i].f(0, 2), sheenVisibility(a1.x, a1.y, a0.w), 1e-20), where);
    dL.add(absDiff(out[i].f(1, 3), sheenL(a1.y, a0.w)), where);
    dE.add(relDiff(out[i].f(0, 3), sheenAlbedo(a1.x, a1.z), 1e-6), where);
    LayerWeights w = layerWeights(a2.w, a1.w, glm::vec3(a2), a1.z, a1.x, a3.w);
    dCoat.add(std::max({relDiff(out[i].f(1, 0), coatFresnel(a1.w), 1e-6), relDiff(out[i].f(1, 1), w.coat, 1e-6),
                        relDiff(out[i].f(1, 2), w.sheen, 1e-6), relDiff(out[i].f(2, 3), w.coatPick, 1e-6),
                        relVec(out[i].v(3), layeredAlbedo(w, glm::vec3(a2), glm::vec3(a3.z)), 1e-6)}),
              where);
    dDir.add(absDiff(out[i].v(2), sampleUniformHemisphere(glm::vec2(a3))), where);
  }
  dCoat.check();
  dD.check();
  dL.check();
  dLam.check();
  dV.check();
  dE.check();
  dDir.check();
}

TEST_CASE("GLSL denoiser arithmetic equals its C++ twin: denoiseTapWeight, denoiseNormalWeight, denoiseMeanVariance, "
          "denoiseLuminanceScale, denoiseGuide") {
  GlslTwins gpu;
  Random r(31);
  std::vector<In> in;
  // No surface on either side or both, equal and opposite normals, zero differences, samples that all
  // agree (m2 = n l^2), then random taps: normals a few degrees to 90 degrees apart, distances and
  // luminance differences around their scales, albedos equal or near.
  const glm::vec3 up(0, 0, 1), none(0.0f);
  for (glm::vec3 nq : {up, none, -up, glm::normalize(glm::vec3(0.1f, 0, 1))})
    for (glm::vec3 np : {up, none}) in.push_back(floats({np, 2.0f}, {nq, 2.0f}, {0.01f, 0.0f, 1.0f, 16.0f}, {16.0f * 0.25f, 0.5f, 0.7f, 0.7f}));
  while (in.size() < 4096) {
    const glm::vec3 np = r.unit();
    const glm::vec3 nq = glm::normalize(np + r.unit() * r.uniform(0.0f, 1.0f));
    const float zp = r.uniform(0.1f, 10.0f), scale = r.uniform(1e-3f, 1.0f), lumScale = r.uniform(1e-3f, 2.0f);
    const float n = std::floor(r.uniform(2.0f, 1000.0f)), l = r.uniform(0.0f, 5.0f), m2 = n * l * l * r.uniform(1.0f, 3.0f);
    const float ap = r.uniform(0.0f, 1.0f), aq = r.uniform(0.0f, 1.0f) < 0.5f ? ap : ap + r.uniform(-0.05f, 0.05f);
    in.push_back(floats({np, zp}, {nq, zp + r.uniform(-2.0f, 2.0f) * scale}, {scale, r.uniform(-4.0f, 4.0f) * lumScale, lumScale, n},
                        {m2, l, ap, aq}));
  }
  std::vector<Out> out = gpu.run(Fn::DenoiseTapWeight, in);
  // dot^128 by seven squarings (exact in both, products rounded alike) times one exp of a sum of two
  // quotients: llvmpipe's exp differs from std::exp by a few ULP (measured 4.9e-7 relative). The
  // luminance scale: an exp and a sqrt (measured 1.1e-7). The variance (relative to the mean square), the
  // normal weight and the guide's normal and albedo: measured 0.
  MaxDiff weight("denoiseTapWeight", 8 * kEps), normal("denoiseNormalWeight", 4 * kEps), variance("denoiseMeanVariance", 4 * kEps),
      scale("denoiseLuminanceScale", 8 * kEps), guideNormal("denoiseGuideNormal", 16 * kEps), guideAlbedo("denoiseGuideAlbedo", 2 * kEps);
  for (size_t i = 0; i < in.size(); ++i) {
    const glm::vec4 a = arg(in[i], 0), b = arg(in[i], 1), c = arg(in[i], 2), d = arg(in[i], 3);
    const float np[3] = {a.x, a.y, a.z}, nq[3] = {b.x, b.y, b.z};
    const float cw = denoiseTapWeight(np, nq, a.w, b.w, c.x, c.y, c.z), cn = denoiseNormalWeight(np, nq);
    const float cv = denoiseMeanVariance(c.w, d.x, d.y), cs = denoiseLuminanceScale(2.0f, d.x, d.y, d.z, d.w);
    const glm::vec4 g = denoiseGuide(glm::vec3(a), d.z, a.w);
    const float gw = out[i].f(0, 0), gn = out[i].f(0, 1), gv = out[i].f(0, 2), gs = out[i].f(0, 3);
    auto where = [&](float x, float y) { return [&, x, y] { return str(in[i]) + ": " + str(x) + " vs " + str(y); }; };
    weight.add(relDiff(gw, cw, 1e-20), where(gw, cw));
    normal.add(absDiff(gn, cn), where(gn, cn));
    variance.add(absDiff(gv, cv) / std::max(double(d.x) / c.w, 1e-30), where(gv, cv));  // relative to the mean square
    scale.add(relDiff(gs, cs), where(gs, cs));
    guideNormal.add(absDiff(out[i].v(1), denoiseGuideNormal(g)), where(out[i].f(1, 2), denoiseGuideNormal(g).z));
    guideAlbedo.add(absDiff(out[i].f(1, 3), denoiseGuideAlbedo(g)), where(out[i].f(1, 3), denoiseGuideAlbedo(g)));
  }
  for (const MaxDiff* m : {&weight, &normal, &variance, &scale, &guideNormal, &guideAlbedo}) m->check();
}
