// traverse_gpu_test.cpp — the GLSL BVH traversal (glsl/tests/trace_test.comp on llvmpipe) returns the same
// hits as its C++ twin, ray for ray, on the bunny, a Cornell box and a random soup.
#include <doctest/doctest.h>

#include <fstream>
#include <random>
#include <sstream>

#include "accel/bvh.h"
#include "scene/obj_mesh.h"
#include "gpu/gl_objects.h"
#include "gpu/shader_library.h"
#include "gl_test_util.h"

using namespace caustica;

namespace {


std::vector<Triangle> randomSoup(int n, std::mt19937& g) {
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<Triangle> tris(n);
  for (auto& t : tris) {
    glm::vec3 c(u(g), u(g), u(g));
    for (auto& p : t.p) p = c + 0.2f * glm::vec3(u(g), u(g), u(g));
  }
  tris[0].p[2] = tris[0].p[1];  // a degenerate one
  return tris;
}

void compareGpuWithTwin(const std::vector<Triangle>& tris, int rayCount, std::uint32_t seed) {
  Bvh bvh = buildBvh(tris);
  std::vector<gpu::TriGeom> geom = packTriGeom(tris, bvh);
  Bounds b;
  for (const auto& t : tris)
    for (const auto& p : t.p) b.grow(p);
  glm::vec3 c = 0.5f * (b.min + b.max), ext = b.max - b.min;
  std::mt19937 g(seed);
  std::uniform_real_distribution<float> u(0, 1);
  std::vector<glm::vec4> rays;
  std::vector<Ray> cpuRays;
  std::vector<float> tmaxes;
  for (int i = 0; i < rayCount; ++i) {
    Ray r;
    r.origin = c + ext * glm::vec3(u(g) - 0.5f, u(g) - 0.5f, u(g) - 0.5f) * 1.6f;
    glm::vec3 target = c + ext * glm::vec3(u(g) - 0.5f, u(g) - 0.5f, u(g) - 0.5f) * 0.8f;
    r.dir = glm::normalize(target - r.origin);
    if (i % 17 == 0) r.dir = glm::vec3(0, 0, r.dir.z >= 0 ? 1 : -1);  // axis-aligned rays
    float tmax = i % 5 == 0 ? 0.5f * glm::length(ext) : 1e30f;
    rays.push_back(glm::vec4(r.origin, tmax));
    rays.push_back(glm::vec4(r.dir, 0.0f));
    cpuRays.push_back(r);
    tmaxes.push_back(tmax);
  }
  GlBuffer nodes = GlBuffer::fromVector(bvh.nodes);
  GlBuffer geomBuf = GlBuffer::fromVector(geom);
  GlBuffer rayBuf = GlBuffer::fromVector(rays);
  GlBuffer hitBuf = GlBuffer::create(sizeof(glm::vec4) * rayCount, nullptr);
  GlBuffer occBuf = GlBuffer::create(sizeof(std::uint32_t) * rayCount, nullptr);
  ShaderLibrary lib;
  ExpandedShader src = lib.expand("tests/trace_test.comp", {});
  GlProgram prog = GlProgram::compileCompute(src.source, [&](const std::string& l) { return src.mapLog(l); }, "tests/trace_test.comp");
  prog.use();
  nodes.bindBase(GL_SHADER_STORAGE_BUFFER, CAUSTICA_BINDING_NODES);
  geomBuf.bindBase(GL_SHADER_STORAGE_BUFFER, CAUSTICA_BINDING_TRIGEOM);
  rayBuf.bindBase(GL_SHADER_STORAGE_BUFFER, 8);
  hitBuf.bindBase(GL_SHADER_STORAGE_BUFFER, 9);
  occBuf.bindBase(GL_SHADER_STORAGE_BUFFER, 10);
  glUniform1ui(0, static_cast<GLuint>(rayCount));
  glDispatchCompute((rayCount + 63) / 64, 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  checkGlError("trace test dispatch");
  std::vector<glm::vec4> hits(rayCount);
  std::vector<std::uint32_t> occ(rayCount);
  hitBuf.read(0, hits.size() * sizeof(glm::vec4), hits.data());
  occBuf.read(0, occ.size() * sizeof(std::uint32_t), occ.data());

  int mismatches = 0, hitCount = 0;
  for (int i = 0; i < rayCount; ++i) {
    Hit h = traceClosest(bvh.nodes, geom, cpuRays[i], tmaxes[i]);
    std::uint32_t gpuTri = glm::floatBitsToUint(hits[i].w);
    bool gpuOcc = occ[i] != 0;
    bool same = h.tri == gpuTri && (!h.found() || std::abs(h.t - hits[i].x) <= 1e-5f * std::max(1.0f, h.t));
    // Ties between coplanar triangles at the same t may pick either one.
    if (!same && h.found() && gpuTri != gpu::kInvalidIndex && std::abs(h.t - hits[i].x) <= 1e-5f * std::max(1.0f, h.t))
      same = true;
    if (!same || gpuOcc != traceOccluded(bvh.nodes, geom, cpuRays[i], tmaxes[i])) ++mismatches;
    hitCount += h.found();
  }
  INFO(mismatches, " of ", rayCount, " rays differ");
  CHECK(mismatches == 0);
  CHECK(hitCount > rayCount / 10);  // the rays do meet the geometry
}

}  // namespace

TEST_CASE("GPU traversal equals the C++ twin: bunny") {
  compareGpuWithTwin(loadObjTriangles(test::sourcePath("assets/meshes/bunny.obj")), 20000, 1);
}

TEST_CASE("GPU traversal equals the C++ twin: random soup with a degenerate triangle") {
  std::mt19937 g(2);
  compareGpuWithTwin(randomSoup(3000, g), 20000, 2);
}

TEST_CASE("GPU traversal equals the C++ twin: Cornell box scene") {
  Scene s = loadScene(test::sourcePath("assets/scenes/cornell-box.gltf"));
  compareGpuWithTwin(s.triangles, 20000, 3);
}
