// compressed_files_test.cpp — quantized attributes, vertex colours and tangents as the loader reads them,
// EXT_meshopt_compression's modes, filters and fallback buffers on made-up files, and the compressed
// variants in tests/data/wild/ (scripts/make-test-data:
// Draco, meshopt with and without filters, KHR_mesh_quantization, WebP) load to the same world-space
// triangles as their uncompressed source: every source triangle has one in the variant with the same
// material whose corners lie within the quantization step (positions, normals, texcoords after any
// KHR_texture_transform, vertex colours) — in any triangle order and any rotation of its corners.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <meshoptimizer.h>
#include <stb_image_write.h>

#include "gltf_builder.h"
#include "scene/assets.h"
#include "scene/scene.h"

using namespace caustica;
using caustica::test::Gltf;
using caustica::test::TempDir;
using caustica::test::json;

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

namespace {
constexpr int kSByte = 5120, kUByte = 5121, kSShort = 5122, kUShort = 5123, kFloat32 = 5126;

// One triangle with the given attributes (accessor indices) and material, under the root.
void triangleWith(Gltf& g, const json& attributes, int material = -1) {
  json prim = {{"attributes", attributes}};
  if (material >= 0) prim["material"] = material;
  g.root({{"mesh", g.mesh(prim)}});
}
}  // namespace

TEST_CASE("KHR_mesh_quantization: integer and normalized attributes decode; without the extension they are refused") {
  TempDir dir;
  const unsigned char png[4] = {255, 255, 255, 255};
  REQUIRE(stbi_write_png((dir.path / "one.png").string().c_str(), 1, 1, 4, png, 4));
  const auto textured = [&](Gltf& g) {
    g.doc["images"] = {{{"uri", "one.png"}}};
    g.doc["textures"] = {{{"source", 0}}};
    return g.add("materials", {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
  };
  struct Case {
    const char* name;
    std::function<void(Gltf&)> build;
    std::function<void(const Scene&)> check;
  };
  const Case cases[] = {
      {"POSITION as unsigned bytes (integer values)",
       [&](Gltf& g) {
         const int pos = g.accessor(std::vector<std::uint8_t>{0, 0, 0, 2, 0, 0, 0, 3, 0}, kUByte, "VEC3");
         triangleWith(g, {{"POSITION", pos}});
       },
       [](const Scene& s) {
         CHECK(s.triangles[0].p[1] == glm::vec3(2, 0, 0));
         CHECK(s.triangles[0].p[2] == glm::vec3(0, 3, 0));
       }},
      {"POSITION as normalized shorts, NORMAL as normalized bytes",
       [&](Gltf& g) {
         const int pos = g.accessor(std::vector<std::int16_t>{0, 0, 0, 32767, 0, 0, 0, -32768, 0}, kSShort, "VEC3", true);
         const int n = g.accessor(std::vector<std::int8_t>{0, 0, -127, 0, 0, -127, 0, 0, -128}, kSByte, "VEC3", true);
         triangleWith(g, {{"POSITION", pos}, {"NORMAL", n}});
       },
       [](const Scene& s) {
         CHECK(s.triangles[0].p[1] == glm::vec3(1, 0, 0));
         CHECK(s.triangles[0].p[2] == glm::vec3(0, -1, 0));  // -32768 clamps to -1 (glTF 3.11)
         CHECK(glm::length(s.triangles[0].normal(2) - glm::vec3(0, 0, -1)) < 1e-4f);
       }},
      {"TEXCOORD_0 as integer shorts and normalized signed bytes",
       [&](Gltf& g) {
         const int uv = g.accessor(std::vector<std::int16_t>{0, 0, 4, 0, 0, -4}, kSShort, "VEC2");
         const int uv1 = g.accessor(std::vector<std::int8_t>{0, 0, 127, 0, 0, -127}, kSByte, "VEC2", true);
         const int m = textured(g);
         triangleWith(g, {{"POSITION", g.positions(test::kTriangle)}, {"TEXCOORD_0", uv}, {"TEXCOORD_1", uv1}}, m);
       },
       [](const Scene& s) {
         CHECK(triangleUv(s, 0, 1) == glm::vec2(4, 0));
         CHECK(triangleUv(s, 0, 2) == glm::vec2(0, -4));
       }},
  };
  for (const Case& c : cases) {
    CAPTURE(std::string(c.name));
    Gltf g;
    c.build(g);
    g.doc["extensionsUsed"] = {"KHR_mesh_quantization"};
    const Scene s = g.load(dir);
    REQUIRE(s.triangles.size() == 1);
    c.check(s);
    g.doc.erase("extensionsUsed");  // the same file without the extension: the formats are not glTF's
    const std::string error = test::loadError(dir.write("plain.gltf", g.text()));
    CHECK(error.find("component type") != std::string::npos);
    CHECK(error.find("allowed: FLOAT") != std::string::npos);
  }
}

TEST_CASE("COLOR_0: float, normalized unsigned byte and short, VEC3 and VEC4; white where a primitive has none") {
  TempDir dir;
  struct Case {
    const char* name;
    int accessor;  // filled below
    glm::vec4 corner1;
  };
  Gltf g;
  const int pos = g.positions(test::kTriangle);
  // Corner 1 of each: the colour the accessor holds there.
  const int f3 = g.accessor(std::vector<float>{1, 1, 1, 0.25f, 0.5f, 0.75f, 1, 1, 1}, kFloat32, "VEC3");
  const int f4 = g.accessor(std::vector<float>{1, 1, 1, 1, 0.25f, 0.5f, 0.75f, 0.5f, 1, 1, 1, 1}, kFloat32, "VEC4");
  const int b4 = g.accessor(std::vector<std::uint8_t>{255, 255, 255, 255, 51, 102, 153, 204, 255, 255, 255, 255}, kUByte,
                            "VEC4", true);
  const int s3 = g.accessor(std::vector<std::uint16_t>{65535, 65535, 65535, 13107, 0, 65535, 65535, 65535, 65535},
                            kUShort, "VEC3", true);
  Case cases[] = {{"float VEC3", f3, {0.25f, 0.5f, 0.75f, 1.0f}},
                  {"float VEC4", f4, {0.25f, 0.5f, 0.75f, 0.5f}},
                  {"normalized UNSIGNED_BYTE VEC4", b4, {0.2f, 0.4f, 0.6f, 0.8f}},
                  {"normalized UNSIGNED_SHORT VEC3", s3, {0.2f, 0.0f, 1.0f, 1.0f}}};
  g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", pos}}}})}});  // first: no colours
  for (const Case& c : cases) g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", pos}, {"COLOR_0", c.accessor}}}})}});
  const Scene s = g.load(dir);
  REQUIRE(s.triangles.size() == 5);
  REQUIRE(s.colors.size() == 5);
  CHECK(triangleColor(s, 0, 1) == glm::vec4(1.0f));  // the primitive without COLOR_0 is white
  for (std::size_t i = 0; i < 4; ++i) {
    CAPTURE(std::string(cases[i].name));
    const glm::vec4 c = triangleColor(s, i + 1, 1);
    for (int k = 0; k < 4; ++k) CHECK(c[k] == doctest::Approx(cases[i].corner1[k]).epsilon(1e-6));
    CHECK(triangleColor(s, i + 1, 0) == glm::vec4(1.0f));
  }
  SUBCASE("colours on the very first primitive") {
    Gltf first;
    const int c = first.accessor(std::vector<float>{0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f}, kFloat32, "VEC3");
    const int p = first.positions(test::kTriangle);
    first.root({{"mesh", first.mesh({{"attributes", {{"POSITION", p}, {"COLOR_0", c}}}})}});
    first.root({{"mesh", first.mesh({{"attributes", {{"POSITION", p}}}})}});
    const Scene f = first.load(dir, "first.gltf");
    REQUIRE(f.colors.size() == 2);
    CHECK(triangleColor(f, 0, 2) == glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
    CHECK(triangleColor(f, 1, 2) == glm::vec4(1.0f));
  }
  SUBCASE("signed bytes are not a colour format") {
    Gltf bad;
    const int c = bad.accessor(std::vector<std::int8_t>{1, 2, 3, 4, 5, 6, 7, 8, 9}, kSByte, "VEC3", true);
    bad.root({{"mesh", bad.mesh({{"attributes", {{"POSITION", bad.positions(test::kTriangle)}, {"COLOR_0", c}}}})}});
    bad.doc["extensionsUsed"] = {"KHR_mesh_quantization"};
    const std::string error = test::loadError(dir.write("bad-color.gltf", bad.text()));
    CHECK(error.find("COLOR_0") != std::string::npos);
    CHECK(error.find("allowed: FLOAT, normalized UNSIGNED_BYTE, normalized UNSIGNED_SHORT") != std::string::npos);
  }
}

TEST_CASE("TANGENT: kept for normal-mapped primitives, turned by the node, its sign flipped by a mirroring node") {
  TempDir dir;
  const unsigned char png[4] = {128, 128, 255, 255};
  REQUIRE(stbi_write_png((dir.path / "flat.png").string().c_str(), 1, 1, 4, png, 4));
  Gltf g;
  g.doc["images"] = {{{"uri", "flat.png"}}};
  g.doc["textures"] = {{{"source", 0}}};
  const int bumped = g.add("materials", {{"normalTexture", {{"index", 0}}}});
  const int plain = g.diffuse();
  const int pos = g.positions(test::kTriangle);
  const int n = g.accessor(test::kTriangleNormals, kFloat32, "VEC3");
  const int uv = g.accessor(std::vector<float>{0, 0, 1, 0, 0, 1}, kFloat32, "VEC2");
  const int t = g.accessor(std::vector<float>{1, 0, 0, -1, 1, 0, 0, -1, 1, 0, 0, -1}, kFloat32, "VEC4");
  const json attributes = {{"POSITION", pos}, {"NORMAL", n}, {"TEXCOORD_0", uv}, {"TANGENT", t}};
  const int mesh = g.add("meshes", {{"primitives", json::array({{{"attributes", attributes}, {"material", bumped}},
                                                                 {{"attributes", attributes}, {"material", plain}}})}});
  g.root({{"mesh", mesh}, {"rotation", {0.0, 0.0, 0.7071068, 0.7071068}}});  // 90 degrees about +z
  g.root({{"mesh", mesh}, {"scale", {-1.0, 1.0, 1.0}}});                     // mirrored
  const Scene s = g.load(dir);
  REQUIRE(s.triangles.size() == 4);
  REQUIRE(s.tangents.size() == 4);
  const glm::vec4 turned = triangleTangent(s, 0, 0);
  CHECK(glm::length(glm::vec3(turned) - glm::vec3(0, 1, 0)) < 1e-6f);  // +x turned to +y
  CHECK(turned.w == -1.0f);
  CHECK(triangleTangent(s, 1, 0) == glm::vec4(0.0f));  // no normal map: not kept
  const glm::vec4 mirrored = triangleTangent(s, 2, 0);
  CHECK(glm::length(glm::vec3(mirrored) - glm::vec3(-1, 0, 0)) < 1e-6f);
  CHECK(mirrored.w == 1.0f);  // the mirror turns cross(normal, tangent) around: the sign follows
}

namespace {
// A buffer view compressed with meshoptimizer's encoders, appended to the builder's buffer.
int meshoptView(Gltf& g, const std::vector<unsigned char>& compressed, std::size_t count, std::size_t stride,
                const char* mode, const char* filter, std::size_t byteLength) {
  while (g.bin.size() % 4) g.bin += '\0';
  const std::size_t offset = g.bin.size();
  g.bin.append(reinterpret_cast<const char*>(compressed.data()), compressed.size());
  json ext = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", compressed.size()}, {"byteStride", stride},
              {"count", count}, {"mode", mode}};
  if (filter) ext["filter"] = filter;
  json view = {{"buffer", 1}, {"byteLength", byteLength}, {"extensions", {{"EXT_meshopt_compression", ext}}}};
  if (std::string(mode) == "ATTRIBUTES") view["byteStride"] = stride;
  g.doc["bufferViews"].push_back(view);
  return int(g.doc["bufferViews"].size() - 1);
}

// The document with a fallback buffer 1 of `fallbackBytes` and no data.
std::string withFallback(Gltf& g, std::size_t fallbackBytes) {
  json d = json::parse(g.text());
  d["buffers"].push_back({{"byteLength", fallbackBytes}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}});
  d["extensionsUsed"] = {"EXT_meshopt_compression"};
  d["extensionsRequired"] = {"EXT_meshopt_compression"};
  return d.dump();
}
}  // namespace

TEST_CASE("EXT_meshopt_compression: INDICES mode, QUATERNION filter, a fallback buffer without data") {
  TempDir dir;
  Gltf g;
  // Two triangles' positions (float, 12-byte stride), indices as an index sequence (INDICES mode).
  const std::vector<float> positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0, 3, 0, 0, 2, 1, 0};
  std::vector<unsigned char> vb(meshopt_encodeVertexBufferBound(6, 12));
  vb.resize(meshopt_encodeVertexBuffer(vb.data(), vb.size(), positions.data(), 6, 12));
  const std::vector<std::uint16_t> indices = {0, 1, 2, 3, 4, 5};
  std::vector<unsigned char> ib(meshopt_encodeIndexSequenceBound(6, 6));
  ib.resize(meshopt_encodeIndexSequence(ib.data(), ib.size(), std::vector<unsigned>(indices.begin(), indices.end()).data(), 6));
  const int posView = meshoptView(g, vb, 6, 12, "ATTRIBUTES", nullptr, 72);
  const int idxView = meshoptView(g, ib, 6, 2, "INDICES", nullptr, 12);
  // EXT_mesh_gpu_instancing rotations, 16-bit quaternions with the QUATERNION filter: +90 deg about +y.
  const float q[8] = {0, 0.7071068f, 0, 0.7071068f, 0, 0, 0, 1};
  std::vector<unsigned char> filtered(16);
  meshopt_encodeFilterQuat(filtered.data(), 2, 8, 16, q);
  std::vector<unsigned char> rb(meshopt_encodeVertexBufferBound(2, 8));
  rb.resize(meshopt_encodeVertexBuffer(rb.data(), rb.size(), filtered.data(), 2, 8));
  const int rotView = meshoptView(g, rb, 2, 8, "ATTRIBUTES", "QUATERNION", 16);
  const auto accessorOn = [&](int view, int componentType, const char* type, std::size_t count, bool normalized) {
    json a = {{"bufferView", view}, {"componentType", componentType}, {"count", count}, {"type", type}};
    if (normalized) a["normalized"] = true;
    return g.add("accessors", a);
  };
  const int pos = accessorOn(posView, kFloat32, "VEC3", 6, false);
  g.doc["accessors"][std::size_t(pos)]["min"] = {0, 0, 0};
  g.doc["accessors"][std::size_t(pos)]["max"] = {3, 1, 0};
  const int idx = accessorOn(idxView, kUShort, "SCALAR", 6, false);
  const int rot = accessorOn(rotView, kSShort, "VEC4", 2, true);
  g.root({{"mesh", g.mesh({{"attributes", {{"POSITION", pos}}}, {"indices", idx}})},
          {"extensions", {{"EXT_mesh_gpu_instancing", {{"attributes", {{"ROTATION", rot}}}}}}}});
  const std::string text = withFallback(g, 100);
  const Scene s = loadScene(dir.write("meshopt.gltf", text));
  REQUIRE(s.triangles.size() == 4);  // two triangles, two instances
  // Instance 0 turns +x to -z (90 degrees about +y); instance 1 is the identity.
  CHECK(glm::length(s.triangles[0].p[1] - glm::vec3(0, 0, -1)) < 1e-4f);
  CHECK(glm::length(s.triangles[1].p[1] - glm::vec3(0, 0, -3)) < 1e-4f);
  CHECK(s.triangles[3].p[1] == glm::vec3(3, 0, 0));

  SUBCASE("an uncompressed view in the fallback buffer is refused") {
    json d = json::parse(text);
    d["bufferViews"].push_back({{"buffer", 1}, {"byteLength", 4}});
    d["accessors"][std::size_t(idx)]["bufferView"] = d["bufferViews"].size() - 1;
    d["accessors"][std::size_t(idx)]["count"] = 2;
    const std::string error = test::loadError(dir.write("plain-in-fallback.gltf", d.dump()));
    CHECK(error.find("lies in buffers[1], an EXT_meshopt_compression fallback buffer") != std::string::npos);
  }
}
