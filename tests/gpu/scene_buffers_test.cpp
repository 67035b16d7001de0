// scene_buffers_test.cpp — the TriShade words split over several storage blocks (app/gpu/scene_buffers.*,
// glsl/lib/split_buffers.glsl): with the block size lowered by $CAUSTICA_MAX_SSBO_BYTES a small scene is
// split, and the image must be the same bits as the unsplit render (same arithmetic, same random
// stream); too many blocks is a clear error. BVH nodes and TriGeom are read through buffer textures
// and never split: the lowered block size must not refuse them.
#include <cstdlib>
#include <cstring>

#include "gl_test_util.h"
#include "util/error.h"

using namespace caustica;
using namespace caustica::test;

namespace {

// Sets an environment variable for one scope (the GL limits are read when a Renderer is made).
struct ScopedEnv {
  std::string name;
  ScopedEnv(const char* n, const std::string& value) : name(n) { setenv(n, value.c_str(), 1); }
  ~ScopedEnv() { unsetenv(name.c_str()); }
};

// A textured floor and a smooth sphere under a quad light: every array (nodes, TriGeom, TriShade with
// texcoords) is large enough to split at a few KiB per block. 532 triangles. The checker texture has
// `checker` x `checker` texels (2: 16 bytes; 64: 16 KiB of texel words, more than a 10,000-byte block).
Scene splitScene(int checkerSide = 2) {
  Scene s;
  Texture checker;
  checker.width = checker.height = checkerSide;
  checker.nearest = true;
  for (int y = 0; y < checkerSide; ++y)
    for (int x = 0; x < checkerSide; ++x) {
      static const unsigned char kLight[4] = {230, 230, 230, 255}, kBlue[4] = {40, 90, 200, 255};
      const bool light = ((x * 2 / checkerSide) + (y * 2 / checkerSide)) % 2 == 0;  // 2x2 squares of any side
      const unsigned char* rgba = light ? kLight : kBlue;
      for (int c = 0; c < 4; ++c) checker.rgba.push_back(rgba[c]);
    }
  s.textures.push_back(checker);
  Material floor;
  floor.baseColor = glm::vec4(0.9f, 0.9f, 0.9f, 1.0f);
  floor.baseColorTexture = 0;
  const Material light = emitterMaterial(12.0f);
  Material ball;
  ball.baseColor = glm::vec4(0.8f, 0.4f, 0.2f, 1.0f);
  ball.baseColorTexture = 0;
  s.materials = {floor, light, ball};
  addQuad(s, {-2.0f, 0, 2.0f}, {2.0f, 0, 2.0f}, {2.0f, 0, -2.0f}, {-2.0f, 0, -2.0f}, 0);
  addQuad(s, {-0.4f, 2.5f, -0.4f}, {0.4f, 2.5f, -0.4f}, {0.4f, 2.5f, 0.4f}, {-0.4f, 2.5f, 0.4f}, 1);
  addSphere(s, {0.0f, 0.7f, 0.0f}, 0.6f, 12, 2);
  s.texcoords.resize(s.triangles.size());
  for (std::size_t i = 0; i < s.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const glm::vec3& p = s.triangles[i].p[k];
      s.texcoords[i].uv[k] = glm::vec2(p.x * 2.0f, p.z * 2.0f + p.y);  // texcoords everywhere
    }
  finishBounds(s);
  s.cameras.push_back(lookAt({0.0f, 1.6f, 3.2f}, {0.0f, 0.5f, 0.0f}, 0.8f));
  return s;
}

RenderSettings settingsFor(RenderMode mode) {
  RenderSettings s;
  s.width = 40;
  s.height = 32;
  s.mode = mode;
  s.integrator = Integrator::Mis;
  return s;
}

struct SplitRender {
  Image image;
  std::vector<std::string> defines;
  SceneBufferLayout layout;
};
SplitRender render(const Scene& scene, RenderMode mode, int spp) {
  ShaderLibrary& library = testShaderLibrary();
  Renderer r(library, scene, scene.cameras[0], settingsFor(mode));
  while (r.samplesPerPixel() < spp) r.renderPass(std::min(4, spp - r.samplesPerPixel()));
  return {r.image(), r.shaderDefines(), r.bufferLayout()};
}

// Whether any define starts with `prefix` (a NAME=VALUE define matches its NAME).
bool hasDefineStartingWith(const std::vector<std::string>& d, const std::string& prefix) {
  for (const auto& x : d)
    if (x.rfind(prefix, 0) == 0) return true;
  return false;
}

}  // namespace

TEST_CASE("scene buffers: a scene split over several storage blocks renders the same image, bit for bit") {
  const Scene scene = splitScene();
  for (const RenderModeSpec& spec : renderModes()) {
    const RenderMode mode = spec.mode;
    const std::string modeName = spec.name;
    CAPTURE(modeName);
    const SplitRender whole = render(scene, mode, 8);
    CHECK(whole.layout.extraBlocks() == 0);
    CHECK_FALSE(hasDefineStartingWith(whole.defines, "CAUSTICA_TRIGEOM_PARTS"));
    SplitRender split;
    {
      // 10,000 bytes per block: the TriShade words (36 B per triangle, ~22 KB) in 3 parts.
      ScopedEnv limit("CAUSTICA_MAX_SSBO_BYTES", "10000");
      split = render(scene, mode, 8);
    }
    const SplitArray& a = split.layout.triShade;
    CHECK(a.parts >= 2);
    CHECK(a.perPart * a.elementBytes <= 10000);
    CHECK(a.perPart % gpu::kTriShadeWordsTextured == 0);  // whole triangles per part
    CHECK(a.count > (a.parts - 1) * a.perPart);    // every part holds something
    CHECK(split.layout.nodes.parts == 1);           // buffer textures: larger than 10,000 bytes, not split
    CHECK(split.layout.triGeom.parts == 1);
    CHECK(split.layout.triGeom.count * sizeof(gpu::TriGeom) > 10000);
    CHECK(hasDefineStartingWith(split.defines, "CAUSTICA_TRISHADE_PARTS=" + std::to_string(a.parts)));
    REQUIRE(split.image.rgb.size() == whole.image.rgb.size());
    CHECK(meanOf(whole.image) > 0.02);  // lit (measured 0.044): the comparison below is not of two black images
    CHECK(std::memcmp(split.image.rgb.data(), whole.image.rgb.data(), whole.image.rgb.size() * sizeof(float)) == 0);
  }
}

TEST_CASE("scene buffers: textures, materials and the light tree are not bound by the storage-block size") {
  // They are read through buffer textures: a texture block larger than a storage block renders, and
  // gives the same image as without the lowered limit (a storage-block check on them refused it).
  const Scene scene = splitScene(64);
  const SplitRender whole = render(scene, RenderMode::Path, 4);
  SplitRender split;
  {
    ScopedEnv limit("CAUSTICA_MAX_SSBO_BYTES", "15000");
    split = render(scene, RenderMode::Path, 4);
  }
  CHECK(scene.textures[0].rgba.size() > 15000);  // 64 x 64 texels of one word each
  CHECK(meanOf(whole.image) > 0.02);
  CHECK(std::memcmp(split.image.rgb.data(), whole.image.rgb.data(), whole.image.rgb.size() * sizeof(float)) == 0);
}

TEST_CASE("scene buffers: GL 4.3's 8 storage blocks still split the TriShade words in two") {
  const Scene scene = splitScene();
  const SplitRender whole = render(scene, RenderMode::Path, 4);
  ScopedEnv blocks("CAUSTICA_MAX_SSBO_BLOCKS", "8");
  ScopedEnv limit("CAUSTICA_MAX_SSBO_BYTES", "15000");  // TriShade (~22 KB) in 2 parts
  const SplitRender split = render(scene, RenderMode::Path, 4);
  CHECK(split.layout.triShade.parts == 2);
  CHECK(split.layout.extraBlocks() == 1);
  CHECK(std::memcmp(split.image.rgb.data(), whole.image.rgb.data(), whole.image.rgb.size() * sizeof(float)) == 0);
}

TEST_CASE("scene buffers: more blocks than the GPU has, or than a split allows, is a clear error") {
  const Scene scene = splitScene();
  {
    ScopedEnv blocks("CAUSTICA_MAX_SSBO_BLOCKS", "8");
    ScopedEnv limit("CAUSTICA_MAX_SSBO_BYTES", "10000");  // needs 7 + 2 blocks
    CHECK_THROWS_WITH_AS(render(scene, RenderMode::Path, 1), doctest::Contains("storage blocks"), Error);
  }
  {
    ScopedEnv limit("CAUSTICA_MAX_SSBO_BYTES", "4096");  // TriShade in 6 parts: more than 4
    CHECK_THROWS_WITH_AS(render(scene, RenderMode::Path, 1), doctest::Contains("more than 4 storage blocks"), Error);
  }
}
