// traverse_gpu_test.cpp — the GLSL BVH traversal (glsl/tests/trace_test.comp on llvmpipe, 4-wide nodes)
// returns the same hits as its C++ twin, ray for ray, on the bunny, a Cornell box and a random soup.
#include <doctest/doctest.h>

#include <array>
#include <cstring>
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>

#include "accel/bvh.h"
#include "accel/bvh_traverse.h"
#include "accel/bvh_wide.h"
#include "accel/spawn.h"
#include "accel/tlas.h"
#include "gpu/bvh_textures.h"
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

// Traces rays (two vec4 each: origin and tmax, direction) with glsl/tests/trace_test.comp: per ray
// (t, u, v, tri bits) of traceClosest and 1/0 of traceOccluded.
void traceOnGpu(const Bvh& bvh, const std::vector<gpu::BvhWideNode>& wide, const std::vector<gpu::TriGeom>& geom,
                const std::vector<glm::vec4>& rays, std::vector<glm::vec4>& hits, std::vector<std::uint32_t>& occ) {
  const int rayCount = static_cast<int>(rays.size() / 2);
  GlBuffer nodes = GlBuffer::fromVector(bvh.nodes);
  GlBuffer geomBuf = GlBuffer::fromVector(geom);
  GlBuffer rayBuf = GlBuffer::fromVector(rays);
  GlBuffer hitBuf = GlBuffer::create(sizeof(glm::vec4) * rayCount, nullptr);
  GlBuffer occBuf = GlBuffer::create(sizeof(std::uint32_t) * rayCount, nullptr);
  GlProgram prog = test::compileTestShader("tests/trace_test.comp");
  prog.use();
  BvhTextures textures(nodes, bvh.nodes.size(), geomBuf, geom.size(), "traverse test", wide);
  textures.bind();
  geomBuf.bindBase(GL_SHADER_STORAGE_BUFFER, CAUSTICA_BINDING_TRIGEOM);
  rayBuf.bindBase(GL_SHADER_STORAGE_BUFFER, 8);
  hitBuf.bindBase(GL_SHADER_STORAGE_BUFFER, 9);
  occBuf.bindBase(GL_SHADER_STORAGE_BUFFER, 10);
  glUniform1ui(0, static_cast<GLuint>(rayCount));
  glDispatchCompute((rayCount + 63) / 64, 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  checkGlError("trace test dispatch");
  hits.assign(rayCount, glm::vec4(0.0f));
  occ.assign(rayCount, 0u);
  hitBuf.read(0, hits.size() * sizeof(glm::vec4), hits.data());
  occBuf.read(0, occ.size() * sizeof(std::uint32_t), occ.data());
}

// One ray for both sides, from `origin` towards `target` with no tmax: appended to the GPU list (two
// vec4: origin and tmax, direction) and to the C++ twin's.
void addRay(std::vector<glm::vec4>& rays, std::vector<Ray>& cpu, glm::vec3 origin, glm::vec3 target) {
  const Ray r{origin, glm::normalize(target - origin)};
  cpu.push_back(r);
  rays.push_back(glm::vec4(r.origin, 1e30f));
  rays.push_back(glm::vec4(r.dir, 0.0f));
}

// `shape`: the tree's build and collapse (parseBvhShape syntax; "" = the defaults).
void compareGpuWithTwin(const std::vector<Triangle>& tris, int rayCount, std::uint32_t seed, const std::string& shapeSpec = "") {
  const BvhShape shape = parseBvhShape(shapeSpec);
  Bvh bvh = buildBvh(tris, shape.build);
  const std::vector<gpu::BvhWideNode> wide = packBvhWideNodes(bvh.nodes, shape.collapse).nodes;
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
  std::vector<glm::vec4> hits;
  std::vector<std::uint32_t> occ;
  traceOnGpu(bvh, wide, geom, rays, hits, occ);

  int mismatches = 0, hitCount = 0;
  for (int i = 0; i < rayCount; ++i) {
    Hit h = traceClosest(wide, geom, cpuRays[i], tmaxes[i]);
    std::uint32_t gpuTri = glm::floatBitsToUint(hits[i].w);
    bool gpuOcc = occ[i] != 0;
    bool same = h.tri == gpuTri && (!h.found() || std::abs(h.t - hits[i].x) <= 1e-5f * std::max(1.0f, h.t));
    // Ties between coplanar triangles at the same t may pick either one.
    if (!same && h.found() && gpuTri != gpu::kInvalidIndex && std::abs(h.t - hits[i].x) <= 1e-5f * std::max(1.0f, h.t))
      same = true;
    if (!same || gpuOcc != traceOccluded(wide, geom, cpuRays[i], tmaxes[i])) ++mismatches;
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

TEST_CASE("GPU traversal equals the C++ twin: bunny, greedy collapse and merged leaves of up to 8 triangles") {
  const std::vector<Triangle> bunny = loadObjTriangles(test::sourcePath("assets/meshes/bunny.obj"));
  compareGpuWithTwin(bunny, 8000, 4, "collapse=greedy");
  compareGpuWithTwin(bunny, 8000, 5, "collapse=sah,leaf=1,wideleaf=8,cl=16");
}

TEST_CASE("GPU traversal equals the C++ twin: random soup with a degenerate triangle") {
  std::mt19937 g(2);
  compareGpuWithTwin(randomSoup(3000, g), 20000, 2);
}

TEST_CASE("GPU traversal equals the C++ twin: Cornell box scene") {
  Scene s = loadScene(test::sourcePath("assets/scenes/cornell-box.gltf"));
  compareGpuWithTwin(s.triangles, 20000, 3);
}

TEST_CASE("watertight: 100,000 rays from inside a closed jittered sphere never escape, on the GPU and in C++") {
  // A closed mesh with shared, jittered vertices (a UV sphere with poles), rays from random inside
  // points aimed exactly at vertices, at points on edges, and anywhere. Every ray must hit the mesh:
  // an escape is a crack between triangles that share an edge (pbrt-v4's Watertight test).
  std::mt19937 g(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const int rings = 24, segs = 48;
  std::vector<glm::vec3> v;  // v[0] north pole, then rings - 1 rings of segs, then the south pole
  v.push_back({0.0f, 1.0f, 0.0f});
  for (int i = 1; i < rings; ++i)
    for (int j = 0; j < segs; ++j) {
      const float th = 3.14159265f * (i + 0.3f * (u(g) - 0.5f)) / rings, ph = 6.2831853f * (j + 0.3f * (u(g) - 0.5f)) / segs;
      const float r = 1.0f + 0.05f * (u(g) - 0.5f);
      v.push_back(r * glm::vec3(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)));
    }
  v.push_back({0.0f, -1.0f, 0.0f});
  auto at = [&](int i, int j) { return 1 + (i - 1) * segs + (j % segs); };
  std::vector<std::array<int, 3>> idx;
  for (int j = 0; j < segs; ++j) idx.push_back({0, at(1, j + 1), at(1, j)});
  for (int i = 1; i < rings - 1; ++i)
    for (int j = 0; j < segs; ++j) {
      idx.push_back({at(i, j), at(i, j + 1), at(i + 1, j + 1)});
      idx.push_back({at(i, j), at(i + 1, j + 1), at(i + 1, j)});
    }
  const int south = static_cast<int>(v.size()) - 1;
  for (int j = 0; j < segs; ++j) idx.push_back({south, at(rings - 1, j), at(rings - 1, j + 1)});
  std::vector<Triangle> tris;
  for (const auto& t : idx) tris.push_back(makeTriangle(v[t[0]], v[t[1]], v[t[2]]));
  Bvh bvh = buildBvh(tris);
  std::vector<gpu::TriGeom> geom = packTriGeom(tris, bvh);

  const int rayCount = 100000;
  std::vector<glm::vec4> rays;
  std::vector<Ray> cpu;
  for (int k = 0; k < rayCount; ++k) {
    const glm::vec3 o = 0.9f * std::cbrt(u(g)) * glm::normalize(glm::vec3(u(g) - 0.5f, u(g) - 0.5f, u(g) - 0.5f) + 1e-6f);
    glm::vec3 target;
    const auto& t = idx[static_cast<size_t>(u(g) * idx.size()) % idx.size()];
    if (k % 3 == 0) target = v[t[k % 3 == 0 ? (k / 3) % 3 : 0]];               // a vertex, exactly
    else if (k % 3 == 1) target = glm::mix(v[t[0]], v[t[1]], u(g));            // a point on an edge
    else target = 2.0f * glm::normalize(glm::vec3(u(g) - 0.5f, u(g) - 0.5f, u(g) - 0.5f) + 1e-6f);  // anywhere
    addRay(rays, cpu, o, target);
  }
  std::vector<glm::vec4> hits;
  std::vector<std::uint32_t> occ;
  const BvhWide wide = packBvhWideNodes(bvh.nodes);
  traceOnGpu(bvh, wide.nodes, geom, rays, hits, occ);
  int gpuEscapes = 0, cpuEscapes = 0, gpuOccMisses = 0;
  for (int k = 0; k < rayCount; ++k) {
    gpuEscapes += glm::floatBitsToUint(hits[k].w) == gpu::kInvalidIndex;
    gpuOccMisses += occ[k] == 0u;
    cpuEscapes += !traceClosest(bvh.nodes, geom, cpu[k], 1e30f).found();
    cpuEscapes += !traceClosest(wide.nodes, geom, cpu[k], 1e30f).found();
  }
  CHECK(gpuEscapes == 0);
  CHECK(gpuOccMisses == 0);
  CHECK(cpuEscapes == 0);
}

TEST_CASE("GPU traversal: zero-area triangles are never hit (packed as one point; the shader has no area test)") {
  // Collinear triangles with three distinct vertices (p, p + d, p + 3d in both windings) and two-vertex
  // ones, kept where cross(p1 - p0, p2 - p0) is exactly 0 in float, and rays aimed at points on them
  // from all sides: in ray space the vertices round off the line, so the edge functions can share a
  // sign with det != 0. intersect.glsl relies on packTriGeom storing them as one point (det == 0 for
  // every ray); the C++ twin tests the area itself.
  std::mt19937 g(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Triangle> tris;
  for (int i = 0; tris.size() < 400; ++i) {
    const glm::vec3 p = glm::floor(8.0f * glm::vec3(u(g), u(g), u(g))) * 0.125f;
    const glm::vec3 d = glm::floor(4.0f * glm::vec3(u(g), u(g), u(g))) * 0.0625f;
    Triangle t = i % 4 == 3   ? makeTriangle(p, p + 3.0f * d, p + 3.0f * d)
                 : i % 2 == 0 ? makeTriangle(p, p + d, p + 3.0f * d)
                              : makeTriangle(p, p + 3.0f * d, p + d);
    if (d != glm::vec3(0.0f) && isZeroAreaTriangle(t.p[0], t.p[1], t.p[2])) tris.push_back(t);
  }
  Bvh bvh = buildBvh(tris);
  std::vector<gpu::TriGeom> geom = packTriGeom(tris, bvh);
  std::vector<glm::vec4> rays;
  std::vector<Ray> cpu;
  for (const Triangle& t : tris)
    for (int k = 0; k < 50; ++k) {
      const glm::vec3 target = glm::mix(t.p[0], t.p[2], float(k % 11) / 10.0f);
      const glm::vec3 o = target + 2.0f * glm::normalize(glm::vec3(u(g), u(g), u(g)) + 1e-6f);
      addRay(rays, cpu, o, target);
    }
  std::vector<glm::vec4> hits;
  std::vector<std::uint32_t> occ;
  const BvhWide wide = packBvhWideNodes(bvh.nodes);
  traceOnGpu(bvh, wide.nodes, geom, rays, hits, occ);
  int gpuHits = 0, gpuOccluded = 0, cpuHits = 0;
  for (std::size_t k = 0; k < cpu.size(); ++k) {
    gpuHits += glm::floatBitsToUint(hits[k].w) != gpu::kInvalidIndex;
    gpuOccluded += occ[k] != 0u;
    cpuHits += traceClosest(wide.nodes, geom, cpu[k], 1e30f).found();
  }
  INFO("of ", cpu.size(), " rays: GPU hits ", gpuHits, ", GPU occluded ", gpuOccluded, ", C++ twin hits ", cpuHits);
  CHECK(gpuHits == 0);
  CHECK(gpuOccluded == 0);
  CHECK(cpuHits == 0);
}

TEST_CASE("reintersect on the GPU: rays spawned from hits on 1,000 triangles (1e-8..1e8) never hit their own triangle") {
  // The triangles of tests/accel/spawn_test.cpp's Reintersect test, all in one BVH: from a hit point on
  // each, 1,000 rays leave through offsetRayOrigin (its GLSL twin is bit-equal, twins_gpu_test) and
  // the GLSL traversal must never report that triangle (a self-hit has t ~ 0, so nothing can hide it).
  std::mt19937 g(2024);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), u01(0.0f, 1.0f), e(-8.0f, 8.0f);
  std::normal_distribution<float> nd;
  auto direction = [&] {
    for (;;) {
      glm::vec3 d(nd(g), nd(g), nd(g));
      if (glm::length(d) > 1e-6f) return glm::normalize(d);
    }
  };
  std::vector<Triangle> tris;
  std::vector<glm::vec3> points, errors, normals;
  while (tris.size() < 1000) {
    const glm::vec3 c = std::pow(10.0f, e(g)) * glm::vec3(u(g), u(g), u(g));
    const float size = std::pow(10.0f, e(g));
    Triangle t = makeTriangle(c + size * glm::vec3(u(g), u(g), u(g)), c + size * glm::vec3(u(g), u(g), u(g)),
                              c + size * glm::vec3(u(g), u(g), u(g)));
    const glm::dvec3 n = glm::cross(glm::dvec3(t.p[1]) - glm::dvec3(t.p[0]), glm::dvec3(t.p[2]) - glm::dvec3(t.p[0]));
    if (!(glm::length(n) > 0.0)) continue;
    const glm::vec3 ng(glm::normalize(n));
    float b1 = u01(g), b2 = u01(g);
    if (b1 + b2 > 1.0f) {
      b1 = 1.0f - b1;
      b2 = 1.0f - b2;
    }
    const float b0 = 1.0f - b1 - b2;
    tris.push_back(t);
    points.push_back(b0 * t.p[0] + b1 * t.p[1] + b2 * t.p[2]);
    errors.push_back(hitPointError(b0, b1, b2, t.p[0], t.p[1], t.p[2]));
    normals.push_back(ng);
  }
  Bvh bvh = buildBvh(tris);
  std::vector<gpu::TriGeom> geom = packTriGeom(tris, bvh);
  std::vector<std::uint32_t> leafOf(tris.size());  // input index -> index in leaf order
  for (std::uint32_t i = 0; i < bvh.order.size(); ++i) leafOf[bvh.order[i]] = i;
  const int perTriangle = 1000;
  std::vector<glm::vec4> rays;
  rays.reserve(tris.size() * perTriangle * 2);
  for (size_t i = 0; i < tris.size(); ++i)
    for (int k = 0; k < perTriangle; ++k) {
      const glm::vec3 w = direction();
      const glm::vec3 n = glm::dot(w, normals[i]) > 0.0f ? normals[i] : -normals[i];
      rays.push_back(glm::vec4(offsetRayOrigin(points[i], errors[i], n), 3.0e38f));
      rays.push_back(glm::vec4(w, 0.0f));
    }
  std::vector<glm::vec4> hits;
  std::vector<std::uint32_t> occ;
  traceOnGpu(bvh, packBvhWideNodes(bvh.nodes).nodes, geom, rays, hits, occ);
  int selfHits = 0;
  for (size_t r = 0; r < hits.size(); ++r) selfHits += glm::floatBitsToUint(hits[r].w) == leafOf[r / perTriangle];
  CHECK(selfHits == 0);
}

TEST_CASE("instanced GPU traversal (traverse_instanced.glsl) equals its C++ twin (app/accel/tlas.cpp)") {
  // A random soup and a quad, 12 instances: mirrored, rotated, non-uniformly scaled, on a grid.
  std::mt19937 g(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  Scene s;
  s.triangles = randomSoup(400, g);
  s.meshes.push_back({0, 400, 0});
  s.triangles.push_back(makeTriangle({-1, -1, 0}, {1, -1, 0}, {1, 1, 0}));
  s.triangles.push_back(makeTriangle({-1, -1, 0}, {1, 1, 0}, {-1, 1, 0}));
  s.meshes.push_back({400, 2, 1});
  for (int i = 0; i < 12; ++i) {
    glm::dmat4 m(1.0);
    m = glm::translate(m, glm::dvec3(3.0 * (i % 4), 3.0 * (i / 4), 0.3 * u(g)));
    m = glm::rotate(m, 3.0 * double(u(g)), glm::normalize(glm::dvec3(u(g), u(g), u(g) + 2.0)));
    m = glm::scale(m, glm::dvec3(i % 3 == 0 ? -1.0 : 1.0, 0.6 + 0.4 * (i % 2), 1.0 + 0.2 * (i % 5)));
    s.instances.push_back({std::uint32_t(i % 4 == 3 ? 1 : 0), m});
  }
  const InstancedBvh two = buildInstancedBvh(s);
  std::vector<gpu::BvhNode> texels = two.nodes;  // the records follow the nodes (both 64 bytes)
  for (const gpu::InstanceRecord& r : two.instances) {
    gpu::BvhNode n;
    std::memcpy(&n, &r, sizeof n);
    texels.push_back(n);
  }
  const int rayCount = 20000;
  std::vector<glm::vec4> rays;
  std::vector<Ray> cpuRays;
  std::vector<float> tmaxes;
  std::uniform_real_distribution<float> v(0.0f, 1.0f);
  for (int i = 0; i < rayCount; ++i) {
    const glm::vec3 target(-2.0f + 13.0f * v(g), -2.0f + 10.0f * v(g), -1.5f + 3.0f * v(g));
    Ray r;
    r.origin = target + 15.0f * glm::normalize(glm::vec3(v(g) - 0.5f, v(g) - 0.5f, v(g) - 0.2f));
    r.dir = glm::normalize(target - r.origin);
    const float tmax = i % 5 == 0 ? 14.0f : 1e30f;
    rays.push_back(glm::vec4(r.origin, tmax));
    rays.push_back(glm::vec4(r.dir, 0.0f));
    cpuRays.push_back(r);
    tmaxes.push_back(tmax);
  }
  GlBuffer nodes = GlBuffer::fromVector(texels);
  GlBuffer geomBuf = GlBuffer::fromVector(two.tris);
  GlBuffer rayBuf = GlBuffer::fromVector(rays);
  GlBuffer hitBuf = GlBuffer::create(sizeof(glm::uvec4) * rayCount, nullptr);
  GlBuffer occBuf = GlBuffer::create(sizeof(glm::uvec2) * rayCount, nullptr);
  GlProgram prog = test::compileTestShader("tests/trace_instanced_test.comp");
  prog.use();
  BvhTextures textures(nodes, texels.size(), geomBuf, two.tris.size(), "instanced traverse test");
  textures.bind();
  rayBuf.bindBase(GL_SHADER_STORAGE_BUFFER, 8);
  hitBuf.bindBase(GL_SHADER_STORAGE_BUFFER, 9);
  occBuf.bindBase(GL_SHADER_STORAGE_BUFFER, 10);
  glUniform1ui(0, static_cast<GLuint>(rayCount));
  glUniform1ui(1, static_cast<GLuint>(two.nodes.size()));
  glDispatchCompute((rayCount + 63) / 64, 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  checkGlError("instanced trace test dispatch");
  std::vector<glm::uvec4> hits(rayCount);
  std::vector<glm::uvec2> occ(rayCount);
  hitBuf.read(0, hits.size() * sizeof(glm::uvec4), hits.data());
  occBuf.read(0, occ.size() * sizeof(glm::uvec2), occ.data());
  int mismatches = 0, hitCount = 0;
  for (int i = 0; i < rayCount; ++i) {
    const InstancedHit h = traceClosest(two, cpuRays[i], tmaxes[i]);
    const float gpuT = glm::uintBitsToFloat(hits[i].x);
    const bool sameT = !h.hit.found() || std::abs(h.hit.t - gpuT) <= 1e-5f * std::max(1.0f, h.hit.t);
    const bool same = (h.hit.tri == hits[i].w && h.instance == occ[i].x && sameT) ||
                      (h.hit.found() && hits[i].w != gpu::kInvalidIndex && sameT);  // ties at equal t
    if (!same || (occ[i].y != 0) != traceOccluded(two, cpuRays[i], tmaxes[i])) ++mismatches;
    hitCount += h.hit.found();
  }
  INFO(mismatches, " of ", rayCount, " rays differ");
  CHECK(mismatches == 0);
  CHECK(hitCount > rayCount / 10);
}
