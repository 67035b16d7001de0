// wild_files_test.cpp — files as other tools write them (tests/data/wild/, scripts/make-test-data)
// render the image of their uncompressed source (Draco, meshopt with filters and fallback buffers,
// KHR_mesh_quantization, WebP textures); vertex colours (COLOR_0) multiply the base colour and opacity
// in every render mode; the file's TANGENT orients normal maps; orthographic cameras.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "gl_test_util.h"

using namespace caustica;
using namespace caustica::test;

namespace {

RenderSettings tiny(std::uint32_t seed) {
  RenderSettings s;
  s.width = s.height = 40;
  s.seed = seed;
  return s;
}

Image renderWild(const std::string& file, std::uint32_t seed, int spp) {
  const Scene scene = loadScene(sourcePath("tests/data/wild/" + file));
  return renderScene(scene, sceneCamera(scene), tiny(seed), spp).image;
}

// relMSE = mean((x - ref)^2 / (ref^2 + 0.01)) over every channel (docs/benchmarks.md).
double relMse(const Image& x, const Image& ref) {
  double sum = 0.0;
  for (std::size_t i = 0; i < x.rgb.size(); ++i) {
    const double d = double(x.rgb[i]) - ref.rgb[i];
    sum += d * d / (double(ref.rgb[i]) * ref.rgb[i] + 0.01);
  }
  return sum / double(x.rgb.size());
}

}  // namespace

TEST_CASE("compressed files render the image of their uncompressed source") {
  // The same seed gives the same random numbers, so a variant whose geometry is the source's within
  // the quantization step gives nearly the source's image: measured relMSE 1.3e-5 (quantized,
  // meshopt), 1.6e-4 (gltfpack), 1.5e-3 (Draco, whose 10-bit normals send a few paths elsewhere) and
  // 0 (WebP, lossless), against 3.5e-2 between two seeds of the source; means within 0.06 %. A texture
  // read through the wrong coordinates, a normal decoded wrong or a missing vertex colour moves the
  // image far more; a 0.5 % bias in brightness fails the mean.
  const int spp = 16;
  const Image source = renderWild("compress-source.gltf", 7, spp);
  const Image otherSeed = renderWild("compress-source.gltf", 8, spp);
  const double noise = relMse(otherSeed, source);
  MESSAGE("source against another seed: relMSE " << noise);
  for (const char* file : {"compress-draco.glb", "compress-draco-sequential.glb", "compress-quantized.glb",
                           "compress-meshopt.glb", "compress-gltfpack.glb", "compress-gltfpack-filters.glb",
                           "compress-gltfpack-filters.gltf", "compress-webp.glb"}) {
    CAPTURE(std::string(file));
    const Image img = renderWild(file, 7, spp);
    const double e = relMse(img, source);
    const double bias = meanOf(img) / meanOf(source) - 1.0;
    MESSAGE(std::string(file) << ": relMSE " << e << ", mean " << 100.0 * bias << " %");
    CHECK(e < 5e-3);
    CHECK(e < 0.1 * noise);
    CHECK(std::abs(bias) < 0.003);
  }
}

namespace {

// A unit square in the z = 0 plane facing +z, corners (0,0) (1,0) (1,1) (0,1), two triangles.
void addUnitSquare(Scene& s, std::uint32_t material, const glm::vec4 color[4]) {
  addQuad(s, {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, material);
  if (!color) return;
  s.colors.resize(s.triangles.size() - 2);
  s.colors.push_back({{color[0], color[1], color[2]}});
  s.colors.push_back({{color[0], color[2], color[3]}});
}

// An orthographic camera looking down -z at the unit square, which fills the image exactly.
Camera squareView() {
  Camera c;
  c.position = {0.5f, 0.5f, 1.0f};
  c.orthoHeight = 0.5f;
  return c;
}

Material diffuse(glm::vec3 albedo, float alpha = 1.0f) {
  Material m;
  m.baseColor = glm::vec4(albedo, alpha);
  return m;
}

RenderSettings modeSettings(RenderMode mode, int size, Integrator integrator = Integrator::Naive) {
  RenderSettings r;
  r.width = r.height = size;
  r.mode = mode;
  r.integrator = integrator;
  return r;
}

}  // namespace

TEST_CASE("vertex colours: an orthographic view of a colour ramp under a uniform sky is the ramp") {
  // Under a uniform sky of radiance 1 a lone diffuse square reflects its albedo (one bounce, then the
  // sky; the naive integrator's cosine sampling, noisy only through Russian roulette: measured 0.2 %
  // mean, 2.4 % worst at 16 spp). The corners carry a linear ramp, so each pixel's expected value is the
  // ramp at the pixel's centre: wrong barycentric weights, swapped corners or a missing multiply move
  // pixels by up to 300 % (the ramp runs from 0.2 to 0.8).
  Scene s;
  s.materials.push_back(diffuse({0.8f, 0.9f, 1.0f}));
  const glm::vec4 ramp[4] = {{0.2f, 0.8f, 0.5f, 1}, {0.8f, 0.8f, 0.5f, 1}, {0.8f, 0.2f, 0.5f, 1}, {0.2f, 0.2f, 0.5f, 1}};
  addUnitSquare(s, 0, ramp);
  s.environment = uniformEnvironment(glm::vec3(1.0f));
  const int n = 24;
  const RenderResult r = renderScene(s, squareView(), modeSettings(RenderMode::Path, n), 16);
  CHECK(hasDefine(r.defines, "CAUSTICA_VERTEX_COLORS"));
  double worst = 0.0, mean = 0.0;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const float u = (float(x) + 0.5f) / float(n), v = 1.0f - (float(y) + 0.5f) / float(n);  // row 0 at the top
      const glm::vec3 expected = glm::vec3(0.8f, 0.9f, 1.0f) * glm::vec3(0.2f + 0.6f * u, 0.8f - 0.6f * v, 0.5f);
      for (int c = 0; c < 3; ++c) {
        const double e = std::abs(double(r.image.at(x, y, c)) / expected[c] - 1.0);
        worst = std::max(worst, e);
        mean += e / (3.0 * n * n);
      }
    }
  MESSAGE("relative difference from the ramp: mean " << mean << ", worst " << worst);
  CHECK(mean < 0.01);
  CHECK(worst < 0.06);
}

TEST_CASE("vertex colours: a constant colour equals the base colour it multiplies, in every render mode") {
  // Colours exact in half floats: the product with the base colour is the same float in both scenes.
  const glm::vec4 c(0.5f, 0.25f, 0.75f, 1.0f);
  const glm::vec4 corners[4] = {c, c, c, c};
  Scene colored, plain;
  colored.materials.push_back(diffuse({0.8f, 0.6f, 0.4f}));
  plain.materials.push_back(diffuse(glm::vec3(0.8f, 0.6f, 0.4f) * glm::vec3(c)));
  addUnitSquare(colored, 0, corners);
  addUnitSquare(plain, 0, nullptr);
  for (Scene* s : {&colored, &plain}) {
    Material light;
    light.emission = glm::vec3(4.0f);
    s->materials.push_back(light);
    addQuad(*s, {0.2f, 0.2f, 2}, {0.2f, 0.8f, 2}, {0.8f, 0.8f, 2}, {0.8f, 0.2f, 2}, 1);  // facing -z, down at the square
    if (!s->colors.empty()) s->colors.resize(s->triangles.size());
  }
  Camera cam;
  cam.position = {0.5f, 0.5f, 1.5f};
  cam.yfov = 1.2f;
  for (RenderMode mode : {RenderMode::Path, RenderMode::Whitted, RenderMode::Raster}) {
    CAPTURE(int(mode));
    const RenderResult a = renderScene(colored, cam, modeSettings(mode, 24, Integrator::Mis), mode == RenderMode::Path ? 8 : 1);
    const RenderResult b = renderScene(plain, cam, modeSettings(mode, 24, Integrator::Mis), mode == RenderMode::Path ? 8 : 1);
    CHECK(meanOf(a.image) > 1e-3);
    double worst = 0.0;
    for (std::size_t i = 0; i < a.image.rgb.size(); ++i)
      worst = std::max(worst, std::abs(double(a.image.rgb[i]) - b.image.rgb[i]) / (std::abs(b.image.rgb[i]) + 1e-3));
    CHECK(worst < 1e-5);
  }
}

TEST_CASE("vertex colours: COLOR_0's alpha is the opacity of BLEND and MASK materials, not of OPAQUE ones") {
  // Against the same square whose material factor holds the alpha instead: the same random numbers
  // (the pass-through draws one whenever alpha < 1), so the same image.
  struct Case {
    const char* name;
    float factorAlpha, vertexAlpha, cutoff;  // cutoff < 0: BLEND; > 1: OPAQUE
    float referenceAlpha;                    // the factor alpha of the reference without colours
  };
  const Case cases[] = {{"BLEND", 0.8f, 0.5f, -1.0f, 0.4f},
                        {"MASK below the cutoff: absent", 0.8f, 0.5f, 0.5f, 0.0f},
                        {"MASK above the cutoff: opaque", 0.8f, 0.75f, 0.5f, 1.0f},
                        {"OPAQUE ignores alpha", 0.8f, 0.25f, 2.0f, 1.0f}};
  for (const Case& k : cases) {
    CAPTURE(std::string(k.name));
    Scene colored, plain;
    Material m = diffuse({0.5f, 0.5f, 0.5f}, k.cutoff > 1.0f ? 1.0f : k.factorAlpha);
    m.alphaFromVertices = k.cutoff <= 1.0f;
    if (k.cutoff >= 0.0f && k.cutoff <= 1.0f) {  // MASK as the loader makes it: factor thresholded, maskAlpha kept
      m.alphaCutoff = k.cutoff;
      m.maskAlpha = k.factorAlpha;
      m.baseColor.a = k.factorAlpha >= k.cutoff ? 1.0f : 0.0f;
    }
    colored.materials.push_back(m);
    plain.materials.push_back(diffuse({0.5f, 0.5f, 0.5f}, k.referenceAlpha));
    const glm::vec4 a(1.0f, 1.0f, 1.0f, k.vertexAlpha);
    const glm::vec4 corners[4] = {a, a, a, a};
    addUnitSquare(colored, 0, corners);
    addUnitSquare(plain, 0, nullptr);
    for (Scene* s : {&colored, &plain}) {
      s->environment = uniformEnvironment(glm::vec3(1.0f));
      s->background.kind = Background::Kind::Color;
      s->background.color = glm::vec3(2.0f);  // what shows through
    }
    const Image x = renderScene(colored, squareView(), modeSettings(RenderMode::Path, 16), 8).image;
    const Image y = renderScene(plain, squareView(), modeSettings(RenderMode::Path, 16), 8).image;
    CHECK(differing(x.rgb, y.rgb) == 0);
  }
}

TEST_CASE("TANGENT orients normal maps: a map turned with its tangents gives the same image") {
  // tangent-source.gltf: bumps on a sphere whose TANGENT is its own dp/du, so the triangle's dp/du
  // (used without TANGENT) gives nearly the same image. tangent-rotated.gltf: TANGENT turned 90
  // degrees about the normal and the map's normals turned with it: the source's image only when the
  // file's TANGENT is used.
  const Scene source = loadScene(sourcePath("tests/data/wild/tangent-source.gltf"));
  const Scene rotated = loadScene(sourcePath("tests/data/wild/tangent-rotated.gltf"));
  REQUIRE(!source.tangents.empty());
  Scene sourceNoTangents = source, rotatedNoTangents = rotated;
  sourceNoTangents.tangents.clear();
  rotatedNoTangents.tangents.clear();
  RenderSettings rs = tiny(3);
  rs.width = rs.height = 48;
  const Camera cam = sceneCamera(source);
  const Image a = renderScene(source, cam, rs, 16).image;
  const double withFallback = relMse(renderScene(sourceNoTangents, cam, rs, 16).image, a);
  const double turned = relMse(renderScene(rotated, cam, rs, 16).image, a);
  const double turnedIgnored = relMse(renderScene(rotatedNoTangents, cam, rs, 16).image, a);
  MESSAGE("relMSE against the source: without TANGENT " << withFallback << ", rotated " << turned
                                                        << ", rotated without TANGENT " << turnedIgnored);
  CHECK(withFallback < 2e-3);
  CHECK(turned < 2e-3);
  CHECK(turnedIgnored > 10.0 * std::max(turned, withFallback));
}

TEST_CASE("instanced scenes keep vertex colours and tangents") {
  for (const char* file : {"compress-source.gltf", "tangent-rotated.gltf"}) {
    CAPTURE(std::string(file));
    LoadOptions instanced;
    instanced.keepInstances = true;
    const Scene flat = loadScene(sourcePath(std::string("tests/data/wild/") + file));
    const Scene inst = loadScene(sourcePath(std::string("tests/data/wild/") + file), instanced);
    REQUIRE(!inst.instances.empty());
    const RenderResult a = renderScene(flat, sceneCamera(flat), tiny(5), 8);
    const RenderResult b = renderScene(inst, sceneCamera(inst), tiny(5), 8);
    CHECK(hasDefine(b.defines, "CAUSTICA_INSTANCED"));
    const double e = relMse(b.image, a.image);
    MESSAGE(std::string(file) << ": instanced against flat relMSE " << e);
    CHECK(e < 1e-3);
  }
}

TEST_CASE("orthographic cameras: a sphere covers a disc of its own radius in every render mode") {
  // An emissive sphere of radius 0.3 seen by an orthographic camera 1 high: a disc of radius 0.3 of
  // the image's half height 0.5 covers pi 0.3^2 of its 1 x 1 (28.3 %), wherever the camera stands
  // (a pinhole camera at distance 2 with the same height at the sphere would see a larger disc).
  Scene s;
  Material light;
  light.emission = glm::vec3(1.0f);
  s.materials.push_back(light);
  addSphere(s, {0, 0, 0}, 0.3f, 24, 0);
  Camera cam;
  cam.position = {0, 0, 3};
  cam.orthoHeight = 0.5f;
  const int n = 64;
  for (RenderMode mode : {RenderMode::Path, RenderMode::Whitted, RenderMode::Raster}) {
    CAPTURE(int(mode));
    const RenderResult r = renderScene(s, cam, modeSettings(mode, n), mode == RenderMode::Path ? 4 : 1);
    double covered = 0.0;
    for (int i = 0; i < n * n; ++i) covered += r.image.rgb[std::size_t(i) * 3] > 0.5f ? 1.0 : 0.0;
    covered /= double(n * n);
    MESSAGE("covered " << covered);
    CHECK(covered == Rel{kPi * 0.09, 0.03});  // pixels on the rim go either way; the 24-segment sphere is a little smaller
  }
}
