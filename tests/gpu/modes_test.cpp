// modes_test.cpp — the render modes (docs/render-modes.md) on llvmpipe: every mode renders every
// bundled scene; the raster shadow falls where the path tracer's does; Whitted and the path tracer
// agree on direct light; a planar mirror shows the same reflected object in all three.
#include <doctest/doctest.h>

#include <cmath>

#include <random>

#include "gl_test_util.h"
#include "gpu/gl_objects.h"
#include "gpu/raster_renderer.h"
#include "scene/assets.h"
#include "shading/phong.h"

using namespace caustica;
using namespace caustica::test;

namespace {

RenderSettings modeSettings(RenderMode mode, int size) {
  RenderSettings s;
  s.width = s.height = size;
  s.mode = mode;
  return s;
}

// Floor (white diffuse), a small light high above and to the side, optionally a box on the floor.
Scene shadowScene(bool withBox) {
  Scene s;
  s.materials = {diffuseMaterial(0.8f), emitterMaterial(2000.0f)};
  addQuad(s, {-2.5f, 0, 2}, {2, 0, 2}, {2, 0, -2}, {-2.5f, 0, -2}, 0);
  // A 4 cm light 1.2 m up and 1.6 m to the side: the box's shadow reaches 1.9 m across the floor,
  // its penumbra at most 8 cm wide (the 50 % edge, where the masks are cut, is the point light's).
  const float h = 0.02f;
  addQuad(s, {1.6f - h, 1.2f, -h}, {1.6f + h, 1.2f, -h}, {1.6f + h, 1.2f, h}, {1.6f - h, 1.2f, h}, 1);
  if (withBox) addBox(s, {-0.3f, 0.0f, -0.3f}, {0.3f, 0.6f, 0.3f}, 0);
  finishBounds(s);
  return s;
}

// Pixel mask: radiance of `with` below half of `without` (the box's shadow and its dark sides).
std::vector<int> shadowMask(const Image& with, const Image& without) {
  std::vector<int> m(static_cast<size_t>(with.width) * with.height);
  for (int y = 0; y < with.height; ++y)
    for (int x = 0; x < with.width; ++x) {
      double a = with.at(x, y, 1), b = without.at(x, y, 1);
      m[static_cast<size_t>(y) * with.width + x] = b > 0.0 && a < 0.5 * b;
    }
  return m;
}

double intersectionOverUnion(const std::vector<int>& a, const std::vector<int>& b, int* countA = nullptr) {
  int both = 0, either = 0, na = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    both += a[i] && b[i];
    either += a[i] || b[i];
    na += a[i];
  }
  if (countA) *countA = na;
  return either ? static_cast<double>(both) / either : 1.0;
}

}  // namespace

TEST_CASE("render modes: every mode renders every bundled scene") {
  for (const std::string& name : assetSceneNames()) {
    Scene scene = loadScene(resolveScenePath(name));
    // A scene without emitters (sun-glass) gets the default environment, as the command line gives
    // it; only the path tracer sees an environment so far (docs/lighting.md), so the raster and
    // Whitted images of such a scene are black and only checked for finite values.
    // The same holds for punctual lights (punctual-lights): raster and Whitted light with emissive triangles only.
    if (!sceneHasLights(scene)) scene.environment = uniformEnvironment(glm::vec3(kDefaultEnvironmentRadiance));
    bool envOnly = true;  // no emissive triangle: nothing the raster and Whitted modes light with
    for (const Triangle& t : scene.triangles) envOnly = envOnly && !scene.materials[t.material].isEmissive();
    Camera cam = sceneCamera(scene);
    for (const RenderModeSpec& spec : renderModes()) {
      const RenderMode mode = spec.mode;
      INFO(name, " in mode ", spec.name);
      RenderResult r = renderScene(scene, cam, modeSettings(mode, 40), spec.samples == SampleRule::Regeneration ? 2 : 1);
      double sum = 0.0;
      bool finite = true;
      for (float v : r.image.rgb) {
        finite = finite && std::isfinite(v) && v >= 0.0f;
        sum += v;
      }
      CHECK(finite);
      CHECK(r.stats.nonFinite == 0);
      if (!envOnly || spec.seesEnvironment) CHECK(sum / static_cast<double>(r.image.rgb.size()) > 1e-3);  // not black
    }
  }
}

TEST_CASE("render modes: the raster shadow of a box falls where the path tracer's shadow is") {
  const int n = 96;
  Scene with = shadowScene(true), without = shadowScene(false);
  Camera cam = lookAt({-0.8f, 4.0f, 0.0f}, {-0.8f, 0, 0}, 0.9f);
  RenderSettings path = modeSettings(RenderMode::Path, n);
  auto pathMask = shadowMask(renderScene(with, cam, path, 32).image, renderScene(without, cam, path, 32).image);
  RenderSettings raster = modeSettings(RenderMode::Raster, n);
  auto rasterMask = shadowMask(renderScene(with, cam, raster, 1).image, renderScene(without, cam, raster, 1).image);
  RenderSettings whitted = modeSettings(RenderMode::Whitted, n);
  auto whittedMask = shadowMask(renderScene(with, cam, whitted, 4).image, renderScene(without, cam, whitted, 4).image);
  int pathCount = 0;
  double iouRaster = intersectionOverUnion(pathMask, rasterMask, &pathCount);
  double iouWhitted = intersectionOverUnion(pathMask, whittedMask);
  MESSAGE("shadow pixels (path): ", pathCount, ", IoU raster/path ", iouRaster, ", Whitted/path ", iouWhitted);
  // The shadow covers ~1700 pixels (47 x 15 plus the box's dark sides) with ~130 on its outline: one
  // pixel of shift along the whole outline costs ~0.15 of IoU. Measured: raster 0.953 (shadow-map
  // texels and bias), Whitted 0.988 (4 jittered samples against 32 path samples at the 50 % edge).
  REQUIRE(pathCount > 1000);
  CHECK(iouRaster > 0.9);
  CHECK(iouWhitted > 0.95);
}

TEST_CASE("render modes: Whitted and the path tracer agree on direct light from a small light on a diffuse plane") {
  Scene s;
  s.materials = {diffuseMaterial(0.7f), emitterMaterial(250.0f)};
  addQuad(s, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}, 0);
  const float h = 0.02f;  // 4 cm square 1 m up: a point light to 1e-4 of the irradiance
  addQuad(s, {0.3f - h, 1, -h}, {0.3f + h, 1, -h}, {0.3f + h, 1, h}, {0.3f - h, 1, h}, 1);
  finishBounds(s);
  Camera cam = lookAt({-0.2f, 1.6f, 1.6f}, {0, 0, 0}, 0.8f);
  const int n = 64;
  Image whitted = renderScene(s, cam, modeSettings(RenderMode::Whitted, n), 4).image;
  RenderSettings ps = modeSettings(RenderMode::Path, n);
  Image path = renderScene(s, cam, ps, 64).image;
  ps.seed = 2;
  Image path2 = renderScene(s, cam, ps, 64).image;
  // 4 x 4 blocks of 16 x 16 pixels: the relative difference of each block's mean.
  const int b = 16;
  double worstWhitted = 0.0, worstNoise = 0.0;
  int blocks = 0;
  for (int by = 0; by < n / b; ++by)
    for (int bx = 0; bx < n / b; ++bx) {
      double w = 0, p = 0, p2 = 0;
      bool onPlane = true;  // blocks across the plane's edge: coverage, not light, would differ
      for (int y = by * b; y < (by + 1) * b; ++y)
        for (int x = bx * b; x < (bx + 1) * b; ++x) {
          w += whitted.at(x, y, 1), p += path.at(x, y, 1), p2 += path2.at(x, y, 1);
          onPlane = onPlane && whitted.at(x, y, 1) > 1e-4f;
        }
      if (!onPlane) continue;
      ++blocks;
      worstWhitted = std::max(worstWhitted, std::abs(w - p) / p);
      worstNoise = std::max(worstNoise, std::abs(p2 - p) / p);
    }
  MESSAGE("blocks ", blocks, ": worst |Whitted - path| / path ", worstWhitted, ", worst |path(seed 2) - path| / path ",
          worstNoise);
  REQUIRE(blocks >= 8);
  // Measured: two path seeds differ by at most 0.078 % per block (64 spp); Whitted differs from the
  // path tracer by at most 0.053 % (9 blocks wholly on the plane). The tolerance, 0.3 %, fails a
  // 0.5 % bias of a block's mean (which would show as at least 0.5 - 0.08 = 0.42 %).
  CHECK(worstWhitted < 0.003);
}

TEST_CASE("render modes: a planar mirror shows the same reflected object in all three modes") {
  Scene s;
  s.materials = {diffuseMaterial(0.5f), emitterMaterial(60.0f), metalMaterial(glm::vec3(0.9f)),
                 diffuseMaterial(glm::vec3(0.8f, 0.03f, 0.03f))};
  addQuad(s, {-3, 0, 4}, {3, 0, 4}, {3, 0, -2}, {-3, 0, -2}, 0);
  addQuad(s, {-0.1f, 2.5f, 0.9f}, {0.1f, 2.5f, 0.9f}, {0.1f, 2.5f, 1.1f}, {-0.1f, 2.5f, 1.1f}, 1);
  addQuad(s, {-1.5f, 0.01f, -1}, {1.5f, 0.01f, -1}, {1.5f, 2, -1}, {-1.5f, 2, -1}, 2);  // facing +z
  // A red box beside and in front of the camera: outside its view, inside the mirror's.
  addBox(s, {0.4f, 0.0f, 1.8f}, {0.8f, 0.8f, 2.2f}, 3);
  finishBounds(s);
  Camera cam = lookAt({0, 1, 3}, {0, 0.8f, -1}, 0.7f);
  const int n = 80;
  auto redMask = [&](const Image& img) {
    std::vector<int> m(static_cast<size_t>(n) * n);
    for (int i = 0; i < n * n; ++i) {
      float r = img.rgb[i * 3], g = img.rgb[i * 3 + 1];
      m[i] = r > 0.01f && r > 4.0f * g;
    }
    return m;
  };
  auto path = redMask(renderScene(s, cam, modeSettings(RenderMode::Path, n), 32).image);
  auto whitted = redMask(renderScene(s, cam, modeSettings(RenderMode::Whitted, n), 4).image);
  auto raster = redMask(renderScene(s, cam, modeSettings(RenderMode::Raster, n), 1).image);
  int count = 0;
  double iouWhitted = intersectionOverUnion(path, whitted, &count);
  double iouRaster = intersectionOverUnion(path, raster);
  MESSAGE("reflected red pixels (path): ", count, ", IoU Whitted/path ", iouWhitted, ", raster/path ", iouRaster);
  // Measured: 200 red pixels, IoU Whitted/path 0.985, raster/path 0.918 (the raster's reflected box
  // is shaded by shadow-mapped Blinn-Phong, its edges rasterised without anti-aliasing).
  REQUIRE(count > 100);
  CHECK(iouWhitted > 0.9);
  CHECK(iouRaster > 0.85);
}

TEST_CASE("render modes: the raster mesh finds planar mirrors and leaves a mirror ball to highlights") {
  Scene s;
  const Material diffuse, mirror = metalMaterial(glm::vec3(1.0f));
  s.materials = {diffuse, mirror};
  addQuad(s, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}, 1);            // a planar mirror floor
  addQuad(s, {-1, 0, -1}, {1, 0, -1}, {1, 1, -1}, {-1, 1, -1}, 0);          // a diffuse wall
  addSphere(s, {0, 0.5f, 0}, 0.3f, 8, 1);                                    // the same material, curved
  finishBounds(s);
  GpuScene g = packScene(s, buildBvh(s.triangles));
  RasterMesh m = buildRasterMesh(g);
  // The material spans the floor plane and the sphere's many planes: too many, so all of it is curved.
  CHECK(m.mirrors.empty());
  Scene flat;
  flat.materials = {diffuse, mirror};
  addQuad(flat, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}, 1);
  addQuad(flat, {-1, 0, -1}, {1, 0, -1}, {1, 1, -1}, {-1, 1, -1}, 0);
  finishBounds(flat);
  RasterMesh mf = buildRasterMesh(packScene(flat, buildBvh(flat.triangles)));
  REQUIRE(mf.mirrors.size() == 1);
  CHECK(std::abs(mf.mirrors[0].normal.y) == doctest::Approx(1.0f));
  CHECK(mf.mirrors[0].count == 6);
  CHECK(mf.vertices.size() == 12);
}

TEST_CASE("render modes: pointLightIntensity and phongBrdf agree with their C++ twins (GLSL on llvmpipe)") {
  std::mt19937 gen(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  auto unit = [&] {
    glm::vec3 v;
    do v = glm::vec3(u(gen), u(gen), u(gen)) * 2.0f - 1.0f;
    while (glm::dot(v, v) > 1.0f || glm::dot(v, v) < 1e-4f);
    return glm::normalize(v);
  };
  const int n = 4096;
  std::vector<glm::vec4> in;
  std::vector<gpu::PointLight> lights;
  struct Args { glm::vec3 w, base, nrm, wv; float rough; };
  std::vector<Args> args;
  for (int i = 0; i < n; ++i) {
    gpu::PointLight l{};
    float flat = u(gen);
    l.position = glm::vec4(u(gen), u(gen), u(gen), (1.0f - flat) / 4.0f);
    l.intensity = glm::vec4(10.0f * u(gen), u(gen), 0.1f * u(gen), 5.0f);
    l.axis = glm::vec4(unit() * flat, 0.0f);
    if (i % 3 == 2) {  // a spot light: unit axis, cone cosines (outer < inner)
      l.axis = glm::vec4(unit(), 0.0f);
      float outer = 0.1f + 1.4f * u(gen), inner = outer * u(gen);
      l.cone = glm::vec4(std::cos(outer), std::cos(inner), 1.0f, 0.0f);
    }
    Args a{unit(), glm::vec3(u(gen), u(gen), u(gen)), unit(), unit(), i % 4 == 0 ? 1.0f : u(gen)};
    if (glm::dot(a.nrm, a.w) < 0.0f) a.nrm = -a.nrm;
    if (glm::dot(a.nrm, a.wv) < 0.0f) a.wv = -a.wv;
    if (i % 16 == 1) a.wv = glm::reflect(-a.w, a.nrm);  // the highlight's peak
    in.insert(in.end(), {l.position, l.intensity, l.axis, glm::vec4(a.w, a.rough), glm::vec4(a.base, 0.0f),
                         glm::vec4(a.nrm, 0.0f), glm::vec4(a.wv, 0.0f), l.cone});
    lights.push_back(l);
    args.push_back(a);
  }
  GlProgram prog = compileTestShader("tests/modes_twins_test.comp");
  GlBuffer inBuf = GlBuffer::fromVector(in);
  GlBuffer outBuf = GlBuffer::create(sizeof(glm::vec4) * 2 * n, nullptr, GL_DYNAMIC_READ);
  prog.use();
  inBuf.bindBase(GL_SHADER_STORAGE_BUFFER, 0);
  outBuf.bindBase(GL_SHADER_STORAGE_BUFFER, 1);
  glUniform1ui(0, static_cast<GLuint>(n));
  glDispatchCompute((n + 63) / 64, 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<glm::vec4> out(2 * n);
  outBuf.read(0, sizeof(glm::vec4) * out.size(), out.data());
  double worstIntensity = 0.0, worstBrdf = 0.0;
  for (int i = 0; i < n; ++i) {
    glm::vec3 ci = pointLightIntensity(lights[i], args[i].w);
    glm::vec3 cb = phongBrdf(args[i].base, args[i].rough, args[i].nrm, args[i].w, args[i].wv);
    for (int c = 0; c < 3; ++c) {
      // A spot's falloff is a squared ramp that goes to 0 at the outer cone: measured against the
      // light's peak intensity there (a relative error of a near-zero value means nothing).
      double scale = lights[i].cone.z > 0.5f ? std::abs(lights[i].intensity[c]) : std::abs(ci[c]);
      worstIntensity = std::max(worstIntensity, std::abs(out[2 * i][c] - ci[c]) / (scale + 1e-6));
      worstBrdf = std::max(worstBrdf, std::abs(out[2 * i + 1][c] - cb[c]) / (std::abs(cb[c]) + 1e-6));
    }
  }
  MESSAGE("worst relative difference: pointLightIntensity ", worstIntensity, ", phongBrdf ", worstBrdf);
  // Measured: pointLightIntensity 5.7e-7 (the same float operations; spots relative to their peak),
  // phongBrdf 4.2e-4 (pow with
  // exponents up to 4096 amplifies the last-bit differences of the half vector).
  CHECK(worstIntensity < 1e-5);
  CHECK(worstBrdf < 2e-3);
}
