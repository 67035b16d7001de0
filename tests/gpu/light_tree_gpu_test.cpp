// light_tree_gpu_test.cpp — the GLSL light tree (glsl/lib/light_tree.glsl, run by
// glsl/tests/light_tree_test.comp on llvmpipe) equals its C++ twins (app/accel/light_tree.h):
// lightImportance, sampleLightTree and lightTreePdf, on the bundled many-lights scene's tree and on
// random lights, at random shading points.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "accel/gpu_scene.h"
#include "accel/light_tree.h"
#include "gpu/gl_objects.h"
#include "gpu/shader_library.h"
#include "scene/scene.h"
#include "gl_test_util.h"

using namespace caustica;
using namespace caustica::test;

namespace {

double relDiff(float a, float b) {
  if (a == b) return 0.0;
  return std::abs(static_cast<double>(a) - b) / std::max(std::abs(static_cast<double>(a)), std::abs(static_cast<double>(b)));
}

// Runs the GLSL functions on `queries` random points around the tree's bounds and compares.
void checkTwins(const std::string& what, const std::vector<gpu::LightNode>& nodes, std::uint32_t seed) {
  REQUIRE(!nodes.empty());
  glm::vec3 lo(nodes[0].boundsMin), hi(nodes[0].boundsMax);
  glm::vec3 mid = 0.5f * (lo + hi), half = 0.6f * (hi - lo) + glm::vec3(0.1f);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), sym(-1.0f, 1.0f);
  std::normal_distribution<float> g;
  std::vector<std::uint32_t> leaves;
  for (std::uint32_t i = 0; i < nodes.size(); ++i)
    if (nodes[i].link.y & gpu::kLightNodeLeaf) leaves.push_back(i);
  const int n = 4096;
  std::vector<glm::uvec4> in;
  struct Query { glm::vec3 p, nrm; float u; std::uint32_t leaf, node; };
  std::vector<Query> qs;
  for (int i = 0; i < n; ++i) {
    Query q;
    q.p = mid + half * glm::vec3(sym(rng), sym(rng), sym(rng));
    glm::vec3 d(g(rng), g(rng), g(rng));
    q.nrm = i % 8 == 0 ? glm::vec3(0.0f) : glm::normalize(d);
    q.u = unit(rng);
    q.leaf = leaves[rng() % leaves.size()];
    q.node = static_cast<std::uint32_t>(rng() % nodes.size());
    in.push_back(sameBits<glm::uvec4>(glm::vec4(q.p, q.u)));
    in.push_back(glm::uvec4(sameBits<glm::uvec3>(q.nrm), q.leaf));
    in.push_back(glm::uvec4(q.node, 0u, 0u, 0u));
    qs.push_back(q);
  }
  GlProgram prog = compileTestShader("tests/light_tree_test.comp");
  GlBuffer nodeBuf = GlBuffer::fromVector(nodes);
  GlBuffer inBuf = GlBuffer::fromVector(in);
  GlBuffer outBuf = GlBuffer::create(sizeof(glm::uvec4) * 2 * n, nullptr, GL_DYNAMIC_READ);
  prog.use();
  GlBufferTexture nodeTex = GlBufferTexture::create(nodeBuf, GL_RGBA32UI);  // as the renderer reads it
  nodeTex.bind(CAUSTICA_TEXUNIT_LIGHT_NODES);
  inBuf.bindBase(GL_SHADER_STORAGE_BUFFER, 0);
  outBuf.bindBase(GL_SHADER_STORAGE_BUFFER, 1);
  glUniform1ui(0, static_cast<GLuint>(n));
  glDispatchCompute((n + 63) / 64, 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<glm::uvec4> out(2 * n);
  outBuf.read(0, sizeof(glm::uvec4) * out.size(), out.data());

  int otherChoice = 0, sampled = 0;
  double worstPmf = 0.0, worstPdf = 0.0, worstImportance = 0.0;
  for (int i = 0; i < n; ++i) {
    const Query& q = qs[i];
    std::uint32_t tri = 0;
    float pmf = 0.0f;
    bool ok = sampleLightTree(nodes, q.p, q.nrm, q.u, tri, pmf);
    bool gOk = out[2 * i].x != 0u;
    if (ok != gOk || (ok && tri != out[2 * i].y)) {
      ++otherChoice;  // rounding put u on the other side of a split (or an importance on the other side of 0)
    } else if (ok) {
      ++sampled;
      worstPmf = std::max(worstPmf, relDiff(pmf, sameBits<float>(out[2 * i].z)));
    }
    worstPdf = std::max(worstPdf, relDiff(lightTreePdf(nodes, q.p, q.nrm, q.leaf), sameBits<float>(out[2 * i].w)));
    worstImportance =
        std::max(worstImportance, relDiff(lightImportance(nodes[q.node], q.p, q.nrm), sameBits<float>(out[2 * i + 1].x)));
  }
  MESSAGE(what, ": ", otherChoice, " of ", n, " choices differ; worst relative difference: pmf ", worstPmf,
          ", lightTreePdf ", worstPdf, ", lightImportance ", worstImportance);
  CHECK(sampled > n / 2);
  CHECK(otherChoice <= n / 200);       // measured: 0 (many-lights), 0 (random)
  CHECK(worstPmf <= 1e-4);             // float rounding over ~10-20 levels; measured 2.4e-5
  CHECK(worstPdf <= 1e-4);             // measured 2.7e-5
  CHECK(worstImportance <= 1e-4);      // measured 4.0e-5
}

}  // namespace

TEST_CASE("GLSL light tree equals its C++ twins: lightImportance, sampleLightTree, lightTreePdf") {
  Scene scene = loadScene(sourcePath("assets/scenes/many-lights.gltf"));
  GpuScene g = packScene(scene, buildBvh(scene.triangles));
  checkTwins("many-lights", g.lightTree.nodes, 1);

  std::mt19937 rng(3);
  std::uniform_real_distribution<float> pos(-5.0f, 5.0f), off(-0.3f, 0.3f), unit(0.0f, 1.0f);
  std::vector<LightTreeItem> items;
  for (int i = 0; i < 700; ++i) {
    LightTreeItem t;
    t.tri = static_cast<std::uint32_t>(i);
    glm::vec3 c(pos(rng), pos(rng), pos(rng));
    for (auto& v : t.v) v = c + glm::vec3(off(rng), off(rng), off(rng));
    t.power = std::pow(10.0, 4.0 * unit(rng) - 2.0);
    t.twoSided = unit(rng) < 0.2f;
    items.push_back(t);
  }
  checkTwins("random lights", buildLightTree(items, 700).nodes, 2);
}
