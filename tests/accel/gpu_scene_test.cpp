// gpu_scene_test.cpp — packing for the GPU: the emitters' count and light-tree powers, material
// conversion, used materials, the TriShade words from the scene model's compact triangles. (Feature
// detection: tests/gpu/shader_features_test.cpp.)
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "accel/gpu_scene.h"
#include "shading/oct_normal.h"
#include "shading/sampling.h"
#include "util/error.h"

using namespace caustica;

namespace {
Triangle quadTri(float size, float y, std::uint32_t material, bool second) {
  Triangle t{};
  glm::vec3 a(-size, y, -size), b(size, y, -size), c(size, y, size), d(-size, y, size);
  if (!second) {
    t.p[0] = a; t.p[1] = c; t.p[2] = b;
  } else {
    t.p[0] = a; t.p[1] = d; t.p[2] = c;
  }
  for (int k = 0; k < 3; ++k) t.setNormal(k, glm::vec3(0, -1, 0));
  t.material = material;
  return t;
}
}  // namespace

TEST_CASE("emitters: one light-tree leaf per emissive triangle, power luminance x area x sides") {
  Scene s;
  Material white;
  white.baseColor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
  Material light;
  light.emission = glm::vec3(10.0f, 5.0f, 2.0f);
  Material light2 = light;
  light2.doubleSided = true;
  s.materials = {white, light, light2};
  s.triangles = {quadTri(1, 0, 0, false), quadTri(1, 0, 0, true), quadTri(0.5f, 1, 1, false), quadTri(0.5f, 1, 1, true),
                 quadTri(0.25f, 1.5f, 2, false)};
  Bvh bvh = buildBvh(s.triangles);
  GpuScene g = packScene(s, bvh);
  CHECK(g.emitterCount == 3);
  float lum = luminance(light.emission);
  double expected = lum * (0.5 * 0.5 * 4) + lum * (0.25 * 0.25 * 4 / 2) * 2;  // two halves of a 1x1 quad + double-sided half
  CHECK(g.totalEmitterWeight == doctest::Approx(expected).epsilon(1e-5));
  CHECK(g.totalPower == doctest::Approx(kPi * expected).epsilon(1e-5));
  // Each leaf's power (what the shaders choose it by) is luminance x area x sides of its triangle.
  std::size_t leaves = 0;
  for (const gpu::LightNode& node : g.lightTree.nodes) {
    if ((node.link.y & gpu::kLightNodeLeaf) == 0u) continue;
    ++leaves;
    const auto& t = g.triGeom[node.link.x];
    float area = 0.5f * glm::length(glm::cross(glm::vec3(t.v1 - t.v0), glm::vec3(t.v2 - t.v0)));
    std::uint32_t mi = glm::floatBitsToUint(t.v0.w);
    float sides = s.materials[mi].doubleSided ? 2.0f : 1.0f;
    CHECK(node.boundsMin.w / area == doctest::Approx(lum * sides).epsilon(1e-4));
  }
  CHECK(leaves == g.emitterCount);
}

TEST_CASE("materials: absorption from attenuation, Abbe number from dispersion, flags") {
  Scene s;
  Material glass;
  glass.transmission = 1.0f;
  glass.ior = 1.5f;
  glass.dispersion = 0.5f;
  glass.attenuationColor = glm::vec3(0.5f, 1.0f, 0.25f);
  glass.attenuationDistance = 2.0f;
  s.materials = {glass};
  s.triangles = {quadTri(1, 0, 0, false)};
  GpuScene g = packScene(s, buildBvh(s.triangles));
  const gpu::Material& m = g.materials[0];
  CHECK(m.absorption.x == doctest::Approx(std::log(2.0) / 2.0));
  CHECK(m.absorption.y == doctest::Approx(0.0));
  CHECK(m.absorption.z == doctest::Approx(std::log(4.0) / 2.0));
  CHECK(m.absorption.w == doctest::Approx(40.0));  // V = 20 / dispersion
  CHECK((m.tex.z & gpu::kMatHasVolume) != 0u);
  CHECK((m.tex.z & gpu::kMatDispersive) != 0u);
}

TEST_CASE("a material no triangle uses is not used, and its textures add no texcoords to the TriShade words") {
  Scene s;
  Material white, textured;
  textured.baseColorTexture = 0;
  s.materials = {white, textured};
  s.triangles = {quadTri(1, 0, 0, false)};
  CHECK(usedMaterials(s) == std::vector<bool>{true, false});
  CHECK(packScene(s, buildBvh(s.triangles)).triShadeStride == gpu::kTriShadeWords);
  s.triangles.push_back(quadTri(1, 0, 1, true));
  CHECK(usedMaterials(s) == std::vector<bool>{true, true});
  CHECK(packScene(s, buildBvh(s.triangles)).triShadeStride == gpu::kTriShadeWordsTextured);
}

TEST_CASE("GGX materials: rough lobes (hasRoughLobe); specular layer, data textures and shared texels are packed") {
  Scene s;
  Material smoothMirror;
  smoothMirror.metallic = 1.0f;
  smoothMirror.roughness = 0.03f;  // alpha 9e-4 < kDeltaAlpha: still the delta mirror
  s.materials = {smoothMirror};
  s.triangles = {quadTri(1, 0, 0, false)};
  CHECK_FALSE(hasRoughLobe(s.materials[0]));
  s.materials[0].roughness = 0.04f;  // alpha 1.6e-3: GGX
  CHECK(hasRoughLobe(s.materials[0]));

  Material plastic;
  plastic.specularF0 = glm::vec3(0.04f, 0.03f, 0.02f);
  plastic.specularF90 = 0.5f;
  plastic.metallicRoughnessTexture = 1;
  plastic.normalTexture = 0;
  plastic.normalScale = 0.25f;
  plastic.baseColorTexture = 0;
  plastic.alphaFromTexture = true;
  plastic.alphaCutoff = 0.3f;
  Texture t;
  t.width = 1;
  t.height = 1;
  t.rgba = {1, 2, 3, 4};
  Texture shared = t;
  shared.rgba.clear();
  shared.pixelSource = 0;
  shared.uvRow0 = glm::vec3(2.0f, 0.0f, 0.5f);
  s.textures = {t, shared};
  s.materials = {plastic};
  GpuScene g = packScene(s, buildBvh(s.triangles));
  CHECK(hasRoughLobe(plastic));  // a diffuse base with a specular layer is GGX
  CHECK(g.triShadeStride == gpu::kTriShadeWordsTextured);
  const gpu::Material& m = g.materials[0];
  CHECK(m.specular == glm::vec4(0.04f, 0.03f, 0.02f, 0.5f));
  CHECK(m.tex2.x == 1u);
  CHECK(m.tex2.y == 0u);
  float scale, cutoff;
  std::memcpy(&scale, &m.tex2.z, 4);
  std::memcpy(&cutoff, &m.tex2.w, 4);
  CHECK(scale == 0.25f);
  CHECK(cutoff == 0.3f);
  CHECK((m.tex.z & gpu::kMatAlphaTexture) != 0u);
  CHECK((m.tex.z & gpu::kMatAlphaMask) != 0u);
  REQUIRE(g.texInfo.size() == 2);
  CHECK(g.texels.size() == 1);  // the transformed entry shares the texel
  CHECK(g.texInfo[1].offset == g.texInfo[0].offset);
  CHECK(g.texInfo[1].uvRow0 == glm::vec4(2.0f, 0.0f, 0.5f, 0.0f));
  CHECK(g.texInfo[0].uvRow1 == glm::vec4(0.0f, 1.0f, 0.0f, 0.0f));
}

TEST_CASE("the scene model's compact triangle: normal words round trip, no normal by default, 52 bytes") {
  static_assert(sizeof(Triangle) == 52, "3 positions, 3 octahedral normal words, material");
  Triangle t = makeTriangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  for (int k = 0; k < 3; ++k) {
    CHECK(t.normalWord[k] == gpu::kOctZeroNormal);  // makeTriangle: no normal (the geometric one is used)
    CHECK(t.normal(k) == glm::vec3(0.0f));
  }
  std::mt19937 rng(7);
  std::normal_distribution<float> g(0.0f, 1.0f);
  for (int i = 0; i < 1000; ++i) {
    const glm::vec3 n = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
    t.setNormal(i % 3, n);
    CHECK(t.normalWord[i % 3] == octEncode(n));  // the word the GPU read before the scene model kept words
    const glm::vec3 d = t.normal(i % 3);
    CHECK(glm::length(glm::cross(d, n)) < 5e-5f);  // oct_normal_test: within 4.3e-5 rad
    CHECK(glm::dot(d, n) > 0.0f);
  }
  t.setNormal(1, glm::vec3(0.0f));
  CHECK(t.normalWord[1] == gpu::kOctZeroNormal);
}

TEST_CASE("packing: TriShade words are the triangles' normal words, then their texcoords where textures read them") {
  // The image depends on the scene model only through these words: the same words as octEncode of the
  // float normals and the same float texcoords as before the 52-byte Triangle means the same image.
  Scene s;
  Material plain;
  Material textured;
  textured.baseColorTexture = 0;
  Texture tex;
  tex.width = tex.height = 1;
  tex.rgba = {255, 255, 255, 255};
  s.textures.push_back(tex);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<glm::vec3> normals;
  std::vector<glm::vec2> uvs;
  for (int i = 0; i < 50; ++i) {
    const glm::vec3 c(u(rng) * 5.0f, u(rng) * 5.0f, u(rng) * 5.0f);
    Triangle t = makeTriangle(c, c + glm::vec3(0.3f, 0.0f, 0.0f), c + glm::vec3(0.0f, 0.3f, u(rng) * 0.1f));
    TriangleUv tuv;
    for (int k = 0; k < 3; ++k) {
      normals.push_back(glm::normalize(glm::vec3(u(rng), u(rng), 1.0f)));
      t.setNormal(k, normals.back());
      uvs.push_back(glm::vec2(u(rng), u(rng)));
      tuv.uv[k] = uvs.back();
    }
    s.triangles.push_back(t);
    s.texcoords.push_back(tuv);
  }
  for (const bool withTexture : {false, true}) {
    CAPTURE(withTexture);
    s.materials = {withTexture ? textured : plain};
    const Bvh bvh = buildBvh(s.triangles);
    const GpuScene p = packScene(s, bvh);
    REQUIRE(p.triShadeStride == (withTexture ? gpu::kTriShadeWordsTextured : gpu::kTriShadeWords));
    REQUIRE(p.triShade.size() == s.triangles.size() * p.triShadeStride);
    for (std::size_t j = 0; j < s.triangles.size(); ++j) {
      const std::size_t i = bvh.order[j];
      const std::uint32_t* w = p.triShade.data() + j * p.triShadeStride;
      for (int k = 0; k < 3; ++k) {
        CHECK(w[k] == octEncode(normals[3 * i + std::size_t(k)]));
        if (!withTexture) continue;
        float x, y;
        std::memcpy(&x, &w[3 + 2 * k], 4);
        std::memcpy(&y, &w[4 + 2 * k], 4);
        CHECK(x == uvs[3 * i + std::size_t(k)].x);
        CHECK(y == uvs[3 * i + std::size_t(k)].y);
      }
    }
  }
  s.texcoords.pop_back();  // neither empty nor one per triangle: refused
  CHECK_THROWS_AS(packScene(s, buildBvh(s.triangles)), Error);
}
