// compressed_files_test.cpp — the compressed variants in tests/data/wild/ (scripts/make-test-data:
// Draco, meshopt with and without filters, KHR_mesh_quantization, WebP) load to the same world-space
// triangles as their uncompressed source: every source triangle has one in the variant with the same
// material whose corners lie within the quantization step (positions, normals, texcoords after any
// KHR_texture_transform, vertex colours) — in any triangle order and any rotation of its corners.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/assets.h"
#include "scene/scene.h"

using namespace caustica;

namespace {

std::string wild(const std::string& name) { return sourceDir() + "/tests/data/wild/" + name; }

// The texture coordinates a material's base-colour texture reads: the triangle's after the texture's
// KHR_texture_transform (gltfpack dequantizes texcoords that way).
glm::vec2 effectiveUv(const Scene& s, std::size_t tri, int k) {
  const glm::vec2 uv = triangleUv(s, tri, k);
  const Material& m = s.materials[s.triangles[tri].material];
  if (m.baseColorTexture < 0) return uv;
  const Texture& t = s.textures[std::size_t(m.baseColorTexture)];
  return {glm::dot(t.uvRow0, glm::vec3(uv, 1.0f)), glm::dot(t.uvRow1, glm::vec3(uv, 1.0f))};
}

struct Worst {
  float position = 0.0f, normalDegrees = 0.0f, uv = 0.0f, color = 0.0f;
  std::size_t unmatched = 0;
};

// Matches every triangle of `a` (the source) with one of `b` and returns the largest differences.
Worst compare(const Scene& a, const Scene& b, float positionTolerance) {
  Worst w;
  std::vector<glm::vec3> centroids(b.triangles.size());
  for (std::size_t j = 0; j < b.triangles.size(); ++j)
    centroids[j] = (b.triangles[j].p[0] + b.triangles[j].p[1] + b.triangles[j].p[2]) / 3.0f;
  std::vector<bool> used(b.triangles.size(), false);
  for (std::size_t i = 0; i < a.triangles.size(); ++i) {
    const Triangle& t = a.triangles[i];
    const glm::vec3 c = (t.p[0] + t.p[1] + t.p[2]) / 3.0f;
    const std::string& material = a.materials[t.material].name;
    // The nearest unused triangle of the same material, corners matched under some rotation.
    float best = 1e30f;
    std::size_t bestJ = 0;
    int bestShift = 0;
    for (std::size_t j = 0; j < b.triangles.size(); ++j) {
      if (used[j] || glm::length(centroids[j] - c) > 4.0f * positionTolerance) continue;
      if (b.materials[b.triangles[j].material].name != material) continue;
      for (int shift = 0; shift < 3; ++shift) {
        float d = 0.0f;
        for (int k = 0; k < 3; ++k) d = std::max(d, glm::length(t.p[k] - b.triangles[j].p[(k + shift) % 3]));
        if (d < best) best = d, bestJ = j, bestShift = shift;
      }
    }
    if (best > positionTolerance) {
      ++w.unmatched;
      continue;
    }
    used[bestJ] = true;
    const Triangle& u = b.triangles[bestJ];
    w.position = std::max(w.position, best);
    // Under REPEAT a whole triangle may move by whole texture repeats (gltfpack wraps texcoords into
    // its quantization range): the same texels. uvShift[0] is that move.
    glm::vec2 uvShift[1] = {glm::vec2(0.0f)};
    const Material& m = a.materials[t.material];
    if (m.baseColorTexture >= 0) {
      const Texture& tex = a.textures[std::size_t(m.baseColorTexture)];
      const glm::vec2 d = effectiveUv(a, i, 0) - effectiveUv(b, bestJ, bestShift);
      uvShift[0] = glm::vec2(tex.repeatS ? std::round(d.x) : 0.0f, tex.repeatT ? std::round(d.y) : 0.0f);
    }
    for (int k = 0; k < 3; ++k) {
      const int l = (k + bestShift) % 3;
      const float cosine = std::clamp(glm::dot(t.normal(k), u.normal(l)), -1.0f, 1.0f);
      w.normalDegrees = std::max(w.normalDegrees, std::acos(cosine) * 57.29578f);
      // Texture coordinates only where a texture reads them (gltfpack drops unused ones).
      if (m.readsTextures())
        w.uv = std::max(w.uv, glm::length(effectiveUv(a, i, k) - effectiveUv(b, bestJ, l) - uvShift[0]));
      w.color = std::max(w.color, glm::length(triangleColor(a, i, k) - triangleColor(b, bestJ, l)));
    }
  }
  return w;
}

}  // namespace

TEST_CASE("compressed files load to their source's triangles within the quantization step") {
  const Scene source = loadScene(wild("compress-source.gltf"));
  REQUIRE(source.triangles.size() > 900);
  struct Case {
    const char* file;
    // Largest differences allowed; measured (gltf-transform 4.5.1, gltfpack 1.3.0): positions
    // 4.1e-5 (Draco), 4.3e-5 (quantize, meshopt), 9.9e-5 (gltfpack integer), 5.0e-5 (gltfpack float);
    // normals 0.19 deg (Draco 10-bit), 0.09 deg (16-bit), 0.81 deg (gltfpack 8-bit); texcoords 1.8e-4;
    // colours 1.7e-3 (8-bit, half a step 2.0e-3).
    float position;       // scene units (the box is 2 wide): 14-bit quantization of each mesh's extent
    float normalDegrees;  // 8-bit (gltfpack), 10-bit (Draco) or 16-bit
    float uv;             // 12-bit over [0, 4] (the floor repeats its texture 4 times)
    float color;          // 8-bit normalized colours
  };
  const Case cases[] = {
      {"compress-draco.glb", 2e-4f, 0.3f, 5e-4f, 4e-3f},
      {"compress-draco-sequential.glb", 2e-4f, 0.3f, 5e-4f, 4e-3f},
      {"compress-quantized.glb", 2e-4f, 0.3f, 5e-4f, 4e-3f},
      {"compress-meshopt.glb", 2e-4f, 0.3f, 5e-4f, 4e-3f},
      {"compress-gltfpack.glb", 2e-4f, 1.2f, 5e-4f, 4e-3f},
      {"compress-gltfpack-filters.glb", 2e-4f, 1.2f, 5e-4f, 4e-3f},
      {"compress-gltfpack-filters.gltf", 2e-4f, 1.2f, 5e-4f, 4e-3f},
      // Geometry rewritten as float: positions and texcoords exact, normals re-encoded (1e-6 rad apart).
      {"compress-webp.glb", 1e-6f, 0.1f, 1e-6f, 1e-6f},
  };
  for (const Case& c : cases) {
    CAPTURE(std::string(c.file));
    const Scene s = loadScene(wild(c.file));
    CHECK(s.triangles.size() == source.triangles.size());
    const Worst w = compare(source, s, std::max(c.position, 1e-7f));
    MESSAGE(std::string(c.file) << ": position " << w.position << ", normal " << w.normalDegrees << " deg, uv " << w.uv
                   << ", colour " << w.color);
    CHECK(w.unmatched == 0);
    CHECK(w.position <= c.position);
    CHECK(w.normalDegrees <= c.normalDegrees);
    CHECK(w.uv <= c.uv);
    CHECK(w.color <= c.color);
  }
}
