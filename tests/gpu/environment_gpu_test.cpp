// environment_gpu_test.cpp — the environment light on llvmpipe: the GLSL map functions against their
// C++ twins (tests/environment_test.comp), a furnace with an exact answer (a convex diffuse object of
// albedo a under a uniform sky of radiance 1 is a everywhere, the background 1), the map convention
// seen through the camera, and naive vs mis agreement under a small bright sun.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>
#include <vector>

#include "gpu/environment_textures.h"
#include "gpu/gl_objects.h"
#include "gpu/shader_library.h"
#include "shading/environment_sampling.h"
#include "gl_test_util.h"

using namespace caustica;
using namespace caustica::test;

namespace {

// A w x h map: black, a 2x2-texel patch of colour c at each (x, y) of `patches` (top-left texel).
// With `sky`, a gradient sky above the horizon (bluish, brighter upwards) and a dim ground below.
struct Patch {
  int x, y;
  glm::vec3 c;
};
Environment patchMap(int w, int h, const std::vector<Patch>& patches, bool sky, float rotationDegrees = 0.0f) {
  Environment e;
  e.kind = Environment::Kind::Map;
  e.source = "test map";
  e.width = w;
  e.height = h;
  e.rotationDegrees = rotationDegrees;
  e.rgb.assign(static_cast<size_t>(w) * h * 3, 0.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float v = (y + 0.5f) / h;
      glm::vec3 c = !sky ? glm::vec3(0.0f) : v < 0.5f ? glm::vec3(0.3f, 0.5f, 1.0f) * (1.2f - v) : glm::vec3(0.1f);
      for (const Patch& p : patches)
        if ((x == p.x || x == p.x + 1) && (y == p.y || y == p.y + 1)) c = p.c;
      for (int k = 0; k < 3; ++k) e.rgb[(static_cast<size_t>(y) * w + x) * 3 + k] = c[k];
    }
  return e;
}

}  // namespace

TEST_CASE("environment twins: GLSL sampleEnvironment, environmentPdf, environmentRadiance and the uv maps match C++") {
  GlProgram prog = compileTestShader("tests/environment_test.comp");
  GpuScene g;
  g.environment = buildEnvironmentDistribution(
      patchMap(64, 32, {{40, 9, glm::vec3(400.0f)}, {10, 20, glm::vec3(5.0f, 0.0f, 0.0f)}}, true, 30.0f));
  g.environmentParams.size = glm::uvec4(64, 32, 0, 0);
  g.environmentParams.rotation = glm::vec4(g.environment.cosRotation, g.environment.sinRotation, 0, 0);
  EnvironmentTextures tex;
  tex.upload(g, queryGlLimits(), "test");

  const int n = 20000;
  std::mt19937 gen(5);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  std::vector<glm::uvec4> in(static_cast<size_t>(n) * 2);
  std::vector<glm::vec2> us(n);
  std::vector<glm::vec3> ds(n);
  for (int i = 0; i < n; ++i) {
    us[i] = glm::vec2(U(gen), U(gen));
    if (i < 16) us[i] = glm::vec2(i < 8 ? 0.0f : 0.99999994f, (i % 8) / 8.0f);  // edges of the unit square
    float z = 2.0f * U(gen) - 1.0f, phi = 6.2831853f * U(gen), r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    ds[i] = glm::vec3(r * std::cos(phi), z, r * std::sin(phi));
    in[i * 2] = glm::uvec4(sameBits<glm::uvec2>(us[i]), 0u, 0u);
    in[i * 2 + 1] = glm::uvec4(sameBits<glm::uvec3>(ds[i]), 0u);
  }
  GlBuffer inBuf = GlBuffer::fromVector(in);
  GlBuffer outBuf = GlBuffer::create(sizeof(glm::uvec4) * 4 * n, nullptr);
  prog.use();
  inBuf.bindBase(GL_SHADER_STORAGE_BUFFER, 0);
  outBuf.bindBase(GL_SHADER_STORAGE_BUFFER, 1);
  tex.bind();
  glUniform1ui(0, static_cast<GLuint>(n));
  glDispatchCompute(static_cast<GLuint>((n + 63) / 64), 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  checkGlError("environment twins dispatch");
  std::vector<glm::uvec4> out(static_cast<size_t>(n) * 4);
  outBuf.read(0, out.size() * sizeof(glm::uvec4), out.data());

  // Measured on llvmpipe (20000 records): directions differ by at most 1.9e-7, uv by 1.1e-6 (v is
  // computed with atan2: llvmpipe's acos was off by 3e-5 in v, which moved 8 lookups into the
  // neighbouring texel), pdfs by 6.8e-7 relative, no texel chosen differently. Tolerances ~10x those;
  // a lookup at a texel edge may still round to the neighbour in one of the two (2 allowed).
  double maxDir = 0, maxPdf = 0, maxUv = 0, maxBack = 0;
  int sampleMismatch = 0, lookupMismatch = 0;
  const EnvironmentDistribution& d = g.environment;
  for (int i = 0; i < n; ++i) {
    const glm::uvec4* o = &out[static_cast<size_t>(i) * 4];
    glm::vec3 dir, le;
    float pdf;
    bool ok = sampleEnvironment(d, us[i], dir, le, pdf);
    glm::vec3 gDir = sameBits<glm::vec3>(glm::uvec3(o[0]));
    glm::vec4 gLePdf = sameBits<glm::vec4>(o[1]);
    if (ok != (o[0].w != 0u) || glm::vec3(gLePdf) != le) ++sampleMismatch;
    if (ok) {
      maxDir = std::max<double>(maxDir, glm::length(gDir - dir));
      maxPdf = std::max<double>(maxPdf, std::abs(gLePdf.w - pdf) / pdf);
    }
    glm::vec4 gLook = sameBits<glm::vec4>(o[2]);
    float p = environmentPdf(d, ds[i]);
    if (glm::vec3(gLook) != environmentRadiance(d, ds[i])) ++lookupMismatch;
    else if (p > 0.0f) maxPdf = std::max<double>(maxPdf, std::abs(gLook.w - p) / p);
    glm::vec4 gUv = sameBits<glm::vec4>(o[3]);
    glm::vec2 uv = envDirectionToUv(ds[i], d.cosRotation, d.sinRotation);
    maxUv = std::max<double>(maxUv, std::max(std::abs(gUv.x - uv.x), std::abs(gUv.y - uv.y)));
    glm::vec3 back = envUvToDirection(us[i], d.cosRotation, d.sinRotation);
    maxBack = std::max<double>(maxBack, std::max(std::abs(gUv.z - back.x), std::abs(gUv.w - back.y)));
  }
  MESSAGE("environment twins: max |dir| ", maxDir, ", max pdf rel ", maxPdf, ", max uv ", maxUv, ", max back ", maxBack,
          ", sample mismatches ", sampleMismatch, ", lookup mismatches ", lookupMismatch);
  CHECK(sampleMismatch == 0);
  CHECK(lookupMismatch <= 2);
  CHECK(maxDir < 2e-6);
  CHECK(maxPdf < 1e-5);
  CHECK(maxUv < 1e-5);
  CHECK(maxBack < 2e-6);
}

TEST_CASE("environment furnace: a diffuse box of albedo 0.5 under a uniform sky of radiance 1 is 0.5, the sky 1") {
  Scene s;
  s.path = "furnace";
  std::uint32_t mat = addMaterial(s, diffuseMaterial(0.5f));
  addBox(s, glm::vec3(-0.6f, -0.5f, -0.4f), glm::vec3(0.5f, 0.6f, 0.4f), mat);
  finishBounds(s);
  s.environment = uniformEnvironment(glm::vec3(1.0f));
  Camera cam = cameraAt(glm::vec3(0.8f, 0.9f, 3.0f), glm::vec3(0, 0, -1), glm::vec3(0, 1, 0), 0.6f);
  cam.forward = glm::normalize(glm::vec3(0.0f) - cam.position);
  cam.up = glm::normalize(glm::cross(glm::cross(cam.forward, glm::vec3(0, 1, 0)), cam.forward));
  const int w = 48, h = 48;
  // Naive: every sample of an object pixel is exactly 0.5 (its one bounce sees the sky, a convex
  // object never itself), of a background pixel exactly 1.
  RenderResult naive = renderScene(s, cam, smallSettings(w, h, Integrator::Naive), 8);
  std::vector<int> cls(static_cast<size_t>(w) * h, -1);  // 0: object, 1: sky, -1: silhouette
  int objects = 0, skies = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      bool obj = true, sky = true;
      for (int c = 0; c < 3; ++c) {
        obj &= naive.image.at(x, y, c) == 0.5f;
        sky &= naive.image.at(x, y, c) == 1.0f;
      }
      cls[static_cast<size_t>(y) * w + x] = obj ? 0 : sky ? 1 : -1;
      objects += obj;
      skies += sky;
    }
  // Only pixels whose 3 x 3 neighbourhood is all object or all sky: the other renders' samples fall
  // elsewhere in a pixel, so a pixel beside the silhouette may see both.
  std::vector<int> inner(cls.size(), -1);
  for (int y = 1; y + 1 < h; ++y)
    for (int x = 1; x + 1 < w; ++x) {
      int k = cls[static_cast<size_t>(y) * w + x];
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          if (cls[static_cast<size_t>(y + dy) * w + x + dx] != k) k = -1;
      inner[static_cast<size_t>(y) * w + x] = k;
    }
  INFO("object pixels ", objects, ", sky pixels ", skies);
  CHECK(objects > w * h / 5);
  CHECK(skies > w * h / 5);
  CHECK(objects + skies + 4 * (w + h) > w * h);  // everything else is on the silhouette
  // mis: environment sampling and BSDF sampling, MIS-weighted; the same answer with noise. The
  // standard error of the object mean comes from the spread of 8 renders of 16 spp (measured: about
  // 0.05 % of 0.5); the tolerance 0.5 % must be at least 4.5 standard errors (asserted), so a 0.5 %
  // bias fails and noise alone does not.
  const int renders = 8;
  std::vector<double> means;
  for (std::uint32_t seed = 1; seed <= renders; ++seed) {
    RenderResult mis = renderScene(s, cam, smallSettings(w, h, Integrator::Mis, seed), 16);
    CHECK(mis.stats.nonFinite == 0);
    bool hasEnv = false;
    for (const auto& def : mis.defines) hasEnv |= def == "CAUSTICA_ENV";
    CHECK(hasEnv);
    double sumObj = 0;
    int nObj = 0, skyOff = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        int k = inner[static_cast<size_t>(y) * w + x];
        for (int c = 0; c < 3; ++c) {
          float v = mis.image.at(x, y, c);
          if (k == 1) skyOff += v != 1.0f;
          if (k == 0) {
            sumObj += v;
            ++nObj;
          }
        }
      }
    CHECK(skyOff == 0);
    means.push_back(sumObj / nObj);
  }
  double mean = 0, var = 0;
  for (double m : means) mean += m / renders;
  for (double m : means) var += (m - mean) * (m - mean) / (renders - 1);
  double se = std::sqrt(var / renders);
  MESSAGE("environment furnace, mis: mean over object pixels ", mean, " (exact 0.5), standard error ", se, " (",
          100.0 * se / 0.5, " %)");
  CHECK(4.5 * se <= 0.005 * 0.5);
  CHECK(mean == Rel(0.5, 0.005));

  // --background 0.25: camera rays that leave see the colour; the object is still lit by the sky.
  s.background.kind = Background::Kind::Color;
  s.background.color = glm::vec3(0.25f);
  RenderResult bg = renderScene(s, cam, smallSettings(w, h, Integrator::Naive), 4);
  int off = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      int k = inner[static_cast<size_t>(y) * w + x];
      for (int c = 0; c < 3; ++c)
        if (k >= 0) off += bg.image.at(x, y, c) != (k == 1 ? 0.25f : 0.5f);
    }
  CHECK(off == 0);
}

TEST_CASE("environment convention: a camera looking down -Z sees u = 0.25 in the middle, u grows to the right; rotation") {
  // One tiny triangle behind the camera (the scene needs one); everything seen is the environment.
  Scene s;
  s.path = "convention";
  std::uint32_t mat = addMaterial(s, diffuseMaterial(0.5f));
  s.triangles.push_back(makeTriangle({0, 0, 50}, {0.1f, 0, 50}, {0, 0.1f, 50}, mat));
  finishBounds(s);
  const int mw = 64, mh = 32;
  // White at u = 0.25 (texels 15-16), red at u = 18/64 (texels 17-18) right of it, green at u = 0.5 (+X).
  std::vector<Patch> patches = {{15, 15, glm::vec3(10, 10, 10)}, {17, 15, glm::vec3(10, 0, 0)}, {31, 15, glm::vec3(0, 10, 0)}};
  const int w = 64, h = 64;
  Camera cam = cameraAt(glm::vec3(0.0f), glm::vec3(0, 0, -1), glm::vec3(0, 1, 0), 0.7f);
  auto centroid = [&](const Image& img, int channelOnly, int& count) {
    glm::dvec2 sum(0.0);
    double wsum = 0.0;
    count = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        glm::vec3 v(img.at(x, y, 0), img.at(x, y, 1), img.at(x, y, 2));
        bool hit = channelOnly == 0 ? (v.r > 1.0f && v.g < 0.1f) : (v.g > 1.0f && v.r < 0.1f);
        if (!hit) continue;
        ++count;
        sum += glm::dvec2(x + 0.5, y + 0.5);
        wsum += 1.0;
      }
    return wsum > 0 ? sum / wsum : glm::dvec2(-1.0);
  };
  // Where the patch centre's direction projects in the image.
  auto expectedPixel = [&](glm::vec2 uv, float rotationDegrees) {
    float r = rotationDegrees * kPi / 180.0f;
    glm::vec3 d = envUvToDirection(uv, std::cos(r), std::sin(r));
    float t = std::tan(0.5f * cam.yfov);
    return glm::dvec2((0.5 + 0.5 * (d.x / -d.z) / t) * w, (0.5 - 0.5 * (d.y / -d.z) / t) * h);
  };
  for (float rotation : {0.0f, 90.0f}) {
    CAPTURE(rotation);
    s.environment = patchMap(mw, mh, patches, false, rotation);
    RenderResult r = renderScene(s, cam, smallSettings(w, h, Integrator::Mis), 4);
    int nRed = 0, nGreen = 0;
    glm::dvec2 red = centroid(r.image, 0, nRed), green = centroid(r.image, 1, nGreen);
    if (rotation == 0.0f) {
      // White in the middle, red right of it where the formula puts it; green (+X) out of view.
      CHECK(r.image.at(w / 2, h / 2, 0) > 1.0f);
      CHECK(r.image.at(w / 2, h / 2, 2) > 1.0f);
      REQUIRE(nRed > 4);
      glm::dvec2 e = expectedPixel({18.0f / 64.0f, 0.5f}, rotation);
      INFO("red centroid ", red.x, ", ", red.y, " expected ", e.x, ", ", e.y);
      CHECK(red.x > w / 2);
      CHECK(std::abs(red.x - e.x) < 1.5);
      CHECK(std::abs(red.y - e.y) < 1.5);
      CHECK(nGreen == 0);
    } else {
      // Turned by +90 degrees about +Y: what was at +X (green) is now at -Z, in the middle.
      REQUIRE(nGreen > 4);
      INFO("green centroid ", green.x, ", ", green.y);
      CHECK(std::abs(green.x - w / 2.0) < 1.5);
      CHECK(std::abs(green.y - h / 2.0) < 1.5);
      CHECK(nRed == 0);
    }
  }
}

TEST_CASE("environment: naive and mis agree under a small bright sun (floor, box, glass ball)") {
  Scene s;
  s.path = "sun";
  std::uint32_t floorMat = addMaterial(s, diffuseMaterial(0.8f));
  std::uint32_t boxMat = addMaterial(s, diffuseMaterial(glm::vec3(0.7f, 0.4f, 0.3f)));
  std::uint32_t glass = addMaterial(s, glassMaterial());
  addQuad(s, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, {-3, 0, -3}, floorMat);
  addBox(s, glm::vec3(-1.2f, 0.0f, -0.6f), glm::vec3(-0.4f, 0.8f, 0.2f), boxMat);
  addSphere(s, glm::vec3(0.7f, 0.5f, 0.0f), 0.5f, 12, glass);
  finishBounds(s);
  // Sun 2x2 texels of radiance 300 at about 40 degrees elevation, sky gradient, dim ground. (The test
  // "environment sun on a floor" checks mis against the exact answer under this map to 0.5 %.)
  s.environment = patchMap(64, 32, {{40, 6, glm::vec3(300.0f, 280.0f, 250.0f)}}, true, 0.0f);
  Camera cam = lookAt(glm::vec3(0.0f, 2.2f, 3.6f), glm::vec3(0.0f, 0.3f, 0.0f), 0.8f);
  // Measured (llvmpipe, 8 renders): standard error of the image mean ~0.45 % for naive at 512 spp,
  // ~0.14 % for mis at 64 spp, so this run detects a ~2.1 % bias of the image mean (printed).
  // CAUSTICA_LONG_TESTS=1 must detect 0.5 % (asserted). Measured: at 16x both, naive 0.115 % and mis
  // 0.036 % resolved 0.54 %; naive at 24x came out at 0.132 % (the spread of 8 renders is itself
  // noisy), resolving 0.62 %; naive 1.1576 vs mis 1.1591. So naive takes 48x and mis 16x: measured
  // naive 0.065 %, mis 0.036 %, resolving 0.34 %; naive 1.15852 vs mis 1.15905 (about 25 min).
  const bool longRun = std::getenv("CAUSTICA_LONG_TESTS") != nullptr;
  const int w = 32, h = 32, renders = 8, factorNaive = longRun ? 48 : 1, factorMis = longRun ? 16 : 1;
  auto regions = [&](Integrator integ, int spp, std::uint32_t seedBase) {
    std::vector<std::array<double, 5>> out;
    for (int r = 0; r < renders; ++r) {
      RenderSettings st = smallSettings(w, h, integ, seedBase + r);
      st.maxDepth = 8;
      RenderResult res = renderScene(s, cam, st, spp);
      CHECK(res.stats.nonFinite == 0);
      std::array<double, 5> reg{};
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          double grey = (res.image.at(x, y, 0) + res.image.at(x, y, 1) + res.image.at(x, y, 2)) / 3.0;
          reg[0] += grey / (w * h);
          reg[1 + (y >= h / 2 ? 2 : 0) + (x >= w / 2 ? 1 : 0)] += grey / (w * h / 4.0);
        }
      out.push_back(reg);
    }
    return out;
  };
  auto a = regions(Integrator::Naive, 512 * factorNaive, 100);
  auto b = regions(Integrator::Mis, 64 * factorMis, 200);
  static const char* kRegion[] = {"image", "top left", "top right", "bottom left", "bottom right"};
  for (int k = 0; k < 5; ++k) {
    auto stats = [&](const std::vector<std::array<double, 5>>& v) {
      double m = 0, var = 0;
      for (const auto& r : v) m += r[k] / renders;
      for (const auto& r : v) var += (r[k] - m) * (r[k] - m) / (renders - 1);
      return std::pair<double, double>(m, var / renders);
    };
    auto [ma, va] = stats(a);
    auto [mb, vb] = stats(b);
    double se = std::sqrt(va + vb);
    INFO(std::string(kRegion[k]), ": naive ", ma, " mis ", mb, ", standard error of the difference ", se, " (",
         100.0 * se / (0.5 * (ma + mb)), " %)");
    CHECK(std::abs(ma - mb) <= 4.5 * se);
    if (k == 0 && longRun) CHECK(4.5 * se <= 0.005 * 0.5 * (ma + mb));
    if (k == 0)
      MESSAGE("environment sun: naive ", ma, ", mis ", mb, "; smallest image-mean bias this run detects ",
              100.0 * 4.5 * se / (0.5 * (ma + mb)), " %; mis standard error ", 100.0 * std::sqrt(vb) / mb,
              " %, naive ", 100.0 * std::sqrt(va) / ma, " %");
  }
}

TEST_CASE("environment caustic: a glass ball focuses the sun into a bright spot where optics puts it") {
  // Sun (2 x 2 texels of a 128 x 64 map, radiance 500) 45 degrees high towards -Z, dim uniform sky
  // 0.2. A ball lens of radius 0.5 (ior 1.5; paraxial focus 0.75 from its centre) on the floor: the
  // ray through its centre reaches the floor 0.71 from the centre, just before the focus, at (0, 0, 0.5).
  Scene s;
  s.path = "caustic";
  std::uint32_t floorMat = addMaterial(s, diffuseMaterial(0.8f));
  std::uint32_t glass = addMaterial(s, glassMaterial());
  addQuad(s, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, {-3, 0, -3}, floorMat);
  addSphere(s, glm::vec3(0.0f, 0.5f, 0.0f), 0.5f, 24, glass);
  finishBounds(s);
  Environment env = patchMap(128, 64, {{31, 15, glm::vec3(500.0f)}}, false);
  for (size_t i = 0; i < env.rgb.size(); ++i) env.rgb[i] = std::max(env.rgb[i], 0.2f);
  s.environment = env;
  Camera cam = lookAt(glm::vec3(0.0f, 2.5f, 2.0f), glm::vec3(0.0f, 0.0f, 0.5f), 0.7f);
  const int w = 64, h = 64;
  RenderResult r = renderScene(s, cam, smallSettings(w, h, Integrator::Mis), 128);
  CHECK(r.stats.nonFinite == 0);
  auto project = [&](glm::vec3 p) {  // pixel coordinates of world point p
    glm::vec3 d = p - cam.position;
    glm::vec3 right = glm::normalize(glm::cross(cam.forward, cam.up)), up = glm::cross(right, cam.forward);
    float t = std::tan(0.5f * cam.yfov), z = glm::dot(d, cam.forward);
    return glm::vec2((0.5f + 0.5f * glm::dot(d, right) / z / t) * w, (0.5f - 0.5f * glm::dot(d, up) / z / t) * h);
  };
  auto block = [&](int cx, int cy) {  // grey mean of the 3 x 3 pixels around (cx, cy)
    double sum = 0;
    for (int y = cy - 1; y <= cy + 1; ++y)
      for (int x = cx - 1; x <= cx + 1; ++x)
        for (int c = 0; c < 3; ++c) sum += r.image.at(std::clamp(x, 0, w - 1), std::clamp(y, 0, h - 1), c) / 27.0;
    return sum;
  };
  // Sunlit floor away from the ball.
  glm::vec2 lit = project({1.2f, 0.0f, 1.0f});
  double litLevel = block(int(lit.x), int(lit.y));
  int bx = 0, by = 0;
  double best = 0;
  for (int y = 1; y < h - 1; ++y)
    for (int x = 1; x < w - 1; ++x)
      if (double b = block(x, y); b > best) {
        best = b;
        bx = x;
        by = y;
      }
  glm::vec2 expected = project({0.0f, 0.0f, 0.5f});
  MESSAGE("environment caustic: brightest 3x3 block ", best, " at (", bx, ", ", by, "), expected near (", expected.x,
          ", ", expected.y, "); sunlit floor ", litLevel);
  CHECK(best > 3.0 * litLevel);
  CHECK(std::abs(bx + 0.5f - expected.x) < 4.0f);
  CHECK(std::abs(by + 0.5f - expected.y) < 4.0f);
  // The sunlit floor itself: albedo / pi * (E_sun + E_sky), E_sun = 500 * 2pi (2/128) * (sin^2(17pi/64)
  // - sin^2(15pi/64)) / 2 = 2.405, E_sky = 0.2 pi less the patch = 0.628: 0.772. The ball adds a little
  // (sun light it reflects; measured 0.80 at 128 spp over 3 x 3 pixels, noise about 3 %): within 10 %.
  CHECK(litLevel == Rel(0.772, 0.10));
}

TEST_CASE("environment sun on a floor: mis matches the exact irradiance of the map within 0.5 % (regions)") {
  // A diffuse floor alone under the sun map of the naive-vs-mis test (2 x 2 texels of radiance ~300, 40
  // degrees high, over a sky gradient): a plane sees only the sky above it, so every floor pixel is
  // exactly albedo / pi * E, E = sum over the texels above the horizon of L * dphi * (sin^2 theta1 -
  // sin^2 theta0) / 2 (the map is piecewise constant per texel, the exact function the shader looks up).
  // This resolves a bias of mis (environment sampling, BSDF sampling, their MIS weights) that the
  // naive-vs-mis comparison cannot afford to: naive under a 0.03 sr sun needs ~10^7 samples for 0.1 %.
  Scene s;
  s.path = "sun floor";
  const float albedo = 0.8f;
  addQuad(s, {-20, 0, 20}, {20, 0, 20}, {20, 0, -20}, {-20, 0, -20}, addMaterial(s, diffuseMaterial(albedo)));
  finishBounds(s);
  s.environment = patchMap(64, 32, {{40, 6, glm::vec3(300.0f, 280.0f, 250.0f)}}, true, 0.0f);
  const Environment& e = s.environment;
  glm::dvec3 irradiance(0.0);
  for (int y = 0; y < e.height / 2; ++y) {  // rows of the upper hemisphere (theta <= pi / 2 exactly)
    const double t0 = kPiD * y / e.height, t1 = kPiD * (y + 1) / e.height;
    const double w = 2.0 * kPiD / e.width * 0.5 * (std::sin(t1) * std::sin(t1) - std::sin(t0) * std::sin(t0));
    for (int x = 0; x < e.width; ++x)
      for (int c = 0; c < 3; ++c) irradiance[c] += w * e.rgb[(static_cast<size_t>(y) * e.width + x) * 3 + c];
  }
  const glm::dvec3 expected = double(albedo) / kPiD * irradiance;
  // Looking straight down from 1 above the floor: every pixel sees the floor.
  Camera cam = cameraAt(glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(0, -1, 0), glm::vec3(0, 0, -1), 0.8f);
  // Four renders of 16 x 16 at 256 spp (other seeds, ~5 s on llvmpipe); regions: the image and its four
  // quadrants, grey. Measured: standard error of the image mean 0.057 %, of a quadrant's 0.06-0.20 %
  // (from 4 renders; ~0.11 % expected, twice the image's); errors -0.19 % to +0.14 %. Tolerances: the
  // image 0.25 % (4.4 se), a quadrant 0.5 % (4.5 se): a 0.5 % bias of the image mean fails, and of
  // a quadrant's fails about half the time, 1 % always (seen: E scaled by 1.007 failed every region).
  const int w = 16, h = 16, renders = 4, spp = 256;
  std::array<double, 5> sum{}, sumSq{};
  for (int r = 0; r < renders; ++r) {
    RenderSettings st = smallSettings(w, h, Integrator::Mis, 300 + r);
    st.maxDepth = 2;
    RenderResult res = renderScene(s, cam, st, spp, 64);
    CHECK(res.stats.nonFinite == 0);
    const std::array<double, 5> reg = quadrantMeans(res.image);
    for (int k = 0; k < 5; ++k) {
      sum[k] += reg[k];
      sumSq[k] += reg[k] * reg[k];
    }
  }
  const double exact = (expected.x + expected.y + expected.z) / 3.0;
  static const char* kRegion[] = {"image", "top left", "top right", "bottom left", "bottom right"};
  for (int k = 0; k < 5; ++k) {
    const double mean = sum[k] / renders, var = (sumSq[k] - renders * mean * mean) / (renders - 1);
    const double se = std::sqrt(std::max(var, 0.0) / renders);
    MESSAGE("sun floor, ", std::string(kRegion[k]), ": mis ", mean, ", exact ", exact, ", error ",
            100.0 * (mean / exact - 1.0), " %, standard error ", 100.0 * se / exact, " %");
    CHECK(mean == Rel(exact, k == 0 ? 0.0025 : 0.005));
  }
}

// Beside light tracing (a caster and an emissive triangle compile it), eye paths still aim at casters from
// the vertices the camera sees directly when the environment lights the scene: the light tracer leaves the
// sun's caustics to them (path_scatter.glsl). A small mirror ball high over a floor reflects the sun onto it,
// with a small lamp added far off; per pixel of a crop of the floor beside the ball, the variance over 16
// renders of 1,024 spp, summed: with light tracing (the default) within 1.5x of that without it (both aim
// at the ball). Measured: 0.998-1.002 over three sets of seeds. Aiming only outside the light tracer's
// family, as with emissive triangles alone, left the sun's reflection to cosine sampling there: 3.0-5.3x
// (at 256 spp a set of seeds without a sun hit read 0.76, hence 1,024).
TEST_CASE("environment caustic beside light tracing: eye paths still aim at a mirror for the sun") {
  Scene s;
  s.path = "sun-mirror-lamp";
  Material mirror = diffuseMaterial(0.9f);
  mirror.metallic = 1.0f;
  const std::uint32_t floorMat = addMaterial(s, diffuseMaterial(0.8f)), ball = addMaterial(s, mirror),
                      lamp = addMaterial(s, emitterMaterial(20.0f));
  addQuad(s, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, {-3, 0, -3}, floorMat);
  addSphere(s, glm::vec3(0.0f, 1.5f, 0.0f), 0.3f, 24, ball);
  const float half = 0.05f;
  addQuad(s, {2.0f - half, 3.0f, -2.0f - half}, {2.0f + half, 3.0f, -2.0f - half}, {2.0f + half, 3.0f, -2.0f + half},
          {2.0f - half, 3.0f, -2.0f + half}, lamp);  // facing down
  finishBounds(s);
  Environment env = patchMap(128, 64, {{31, 15, glm::vec3(500.0f)}}, false);
  for (size_t i = 0; i < env.rgb.size(); ++i) env.rgb[i] = std::max(env.rgb[i], 0.2f);
  s.environment = env;
  const Camera cam = lookAt(glm::vec3(0.0f, 2.5f, 1.2f), glm::vec3(0.0f, 0.0f, 0.6f), 0.25f);
  const int side = 8, renders = 16;
  auto summedVariance = [&](bool lightTracing, std::vector<std::string>& defines) {
    std::vector<double> sum(side * side * 3, 0.0), sum2(side * side * 3, 0.0);
    for (int k = 0; k < renders; ++k) {
      RenderSettings rs = smallSettings(side, side, Integrator::Mis, 300 + k);
      rs.lightTracing = lightTracing;
      const RenderResult r = renderScene(s, cam, rs, 1024);
      CHECK(r.stats.nonFinite == 0);
      defines = r.defines;
      for (size_t i = 0; i < sum.size(); ++i) {
        sum[i] += r.image.rgb[i];
        sum2[i] += double(r.image.rgb[i]) * r.image.rgb[i];
      }
    }
    double mean = 0.0, variance = 0.0;
    for (size_t i = 0; i < sum.size(); ++i) {
      const double m = sum[i] / renders;
      mean += m / sum.size();
      variance += (sum2[i] / renders - m * m) * renders / (renders - 1);
    }
    return std::make_pair(mean, variance);
  };
  std::vector<std::string> ltDefines, eyeDefines;
  const auto [ltMean, lt] = summedVariance(true, ltDefines);
  const auto [eyeMean, eye] = summedVariance(false, eyeDefines);
  REQUIRE(hasDefine(ltDefines, "CAUSTICA_LIGHT_TRACE"));
  REQUIRE(hasDefine(ltDefines, "CAUSTICA_ENV"));
  REQUIRE(hasDefine(ltDefines, "CAUSTICA_CASTERS"));
  REQUIRE_FALSE(hasDefine(eyeDefines, "CAUSTICA_LIGHT_TRACE"));
  MESSAGE("floor beside a mirror ball under the sun: mean ", ltMean, " (light tracing) / ", eyeMean,
          " (without); summed per-pixel variance over ", renders, " renders ", lt, " / ", eye, " = ", lt / eye);
  CHECK(lt < 1.5 * eye);
}
