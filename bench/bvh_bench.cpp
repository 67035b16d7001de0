// bvh_bench.cpp — benchmark (not a test) of the BVH builder and the C++ traversal: build time (wall and
// CPU), Mtris/s, SAH cost, node/leaf counts and depth, and single-thread traceClosest Mrays/s, for the
// bunny and a generated displaced sphere of about 1M triangles, over a few (bins, maxLeafSize, threads) choices.
#include <cmath>
#include "scene/assets.h"
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <algorithm>
#include <chrono>
#include <ctime>
#include <thread>
#include <exception>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "accel/bvh.h"
#include "accel/bvh_traverse.h"
#include "scene/obj_mesh.h"
#include "util/error.h"

using namespace caustica;

namespace {

const char* kUsage =
    "usage: bvh_bench [--csv FILE] [--threads N] [--quick] [--repeats R] [--no-trace] [--mesh bunny|sphere1M|sphere4M]\n"
    "                 [--help]\n"
    "Builds BVHs over the bunny (assets/meshes/bunny.obj) and a ~1M-triangle displaced sphere with\n"
    "several (bins, maxLeafSize) settings and prints build time, Mtris/s, SAH cost, nodes, leaves,\n"
    "depth and single-thread traceClosest speed on random rays (builds: best of several, wall time\n"
    "and CPU time of all threads; Mtris/s from wall time). --threads N builds with 1 and N threads\n"
    "(default: the hardware's count). --csv FILE also writes the table. --quick: only 16 bins, leaf 4.\n"
    "--repeats R: builds per setting (default 5 bunny, 3 sphere). --no-trace: skip the rays.\n"
    "--mesh: only that mesh (sphere4M: 4,190,208 triangles, only on request). The last column is a hash\n"
    "(FNV-1a) of the nodes and the leaf order: equal hashes, equal trees.\n";


// UV sphere of radius ~1 with a bumpy displacement: 2 * nu * (nv - 1) triangles (one per pole cell).
std::vector<Triangle> displacedSphere(int nu, int nv) {
  auto point = [&](int i, int j) {
    const float phi = 6.2831853f * float(i % nu) / float(nu), theta = 3.1415927f * float(j) / float(nv);
    const float r = 1.0f + 0.12f * std::sin(9.0f * theta) * std::cos(7.0f * phi) +
                    0.03f * std::sin(41.0f * theta + 3.0f * phi) * std::cos(37.0f * phi);
    return r * glm::vec3(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
  };
  std::vector<Triangle> tris;
  tris.reserve(std::size_t(2) * nu * nv);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const glm::vec3 a = point(i, j), b = point(i + 1, j), c = point(i + 1, j + 1), d = point(i, j + 1);
      if (j > 0) tris.push_back(makeTriangle(a, b, c));
      if (j < nv - 1) tris.push_back(makeTriangle(a, c, d));
    }
  return tris;
}

// Processor time of this process (all its threads) in seconds: unlike wall time, it is not inflated
// by other processes competing for the cores.
double cpuSeconds() { return double(std::clock()) / CLOCKS_PER_SEC; }

struct Row {
  std::string mesh;
  std::size_t tris;
  int bins, leaf, threads;
  double buildMs, cpuMs, mtris, sah;
  std::size_t nodes;
  int leaves, depth;
  double mrays, hitFraction;
  std::uint64_t hash;
};

// FNV-1a over bytes: compares trees of two builders (same hash: same nodes and leaf order, bit for bit).
std::uint64_t fnv1a(const void* data, std::size_t size, std::uint64_t h = 1469598103934665603ull) {
  const unsigned char* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

// Rays from a sphere around the mesh (3x its bounding radius) towards random points in its bounds.
std::vector<Ray> randomRays(const std::vector<Triangle>& tris, int count) {
  Bounds b;
  for (const Triangle& t : tris)
    for (const glm::vec3& p : t.p) b.grow(p);
  const glm::vec3 c = 0.5f * (b.min + b.max);
  const float radius = 0.5f * glm::length(b.max - b.min);
  std::mt19937 gen(1234);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  std::vector<Ray> rays(count);
  for (Ray& r : rays) {
    const float z = 2.0f * u01(gen) - 1.0f, phi = 6.2831853f * u01(gen), s = std::sqrt(1.0f - z * z);
    r.origin = c + 3.0f * radius * glm::vec3(s * std::cos(phi), s * std::sin(phi), z);
    const glm::vec3 target = glm::mix(b.min, b.max, glm::vec3(u01(gen), u01(gen), u01(gen)));
    r.dir = glm::normalize(target - r.origin);
  }
  return rays;
}

double wallSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

Row measure(const std::string& name, const std::vector<Triangle>& tris, const std::vector<Ray>& rays, int bins,
            int leaf, int threads, int repeats) {
  BvhBuildOptions opt;
  opt.bins = bins;
  opt.maxLeafSize = leaf;
  opt.secondBins = 0;  // one build per row: the table compares bin counts
  opt.threads = threads;
  Bvh bvh;
  double best = 1e30, bestCpu = 1e30;
  for (int k = 0; k < repeats; ++k) {  // best of `repeats` builds
    const double t0 = wallSeconds(), c0 = cpuSeconds();
    bvh = buildBvh(tris, opt);
    best = std::min(best, wallSeconds() - t0);
    bestCpu = std::min(bestCpu, cpuSeconds() - c0);
  }
  const std::vector<gpu::TriGeom> geom = packTriGeom(tris, bvh);
  std::size_t hits = 0;
  const double t0 = cpuSeconds();
  for (const Ray& r : rays) hits += traceClosest(bvh.nodes, geom, r).found();
  const double traceS = rays.empty() ? 1.0 : cpuSeconds() - t0;
  const std::uint64_t hash = fnv1a(bvh.order.data(), bvh.order.size() * sizeof(std::uint32_t),
                                   fnv1a(bvh.nodes.data(), bvh.nodes.size() * sizeof(gpu::BvhNode)));
  return {name,         tris.size(),          bins,       leaf, threads, best * 1e3, bestCpu * 1e3, double(tris.size()) / best * 1e-6,
          bvh.sahCost,  bvh.nodes.size(),     bvh.leafCount, bvh.depth, double(rays.size()) / traceS * 1e-6,
          rays.empty() ? 0.0 : double(hits) / double(rays.size()), hash};
}

}  // namespace

int main(int argc, char** argv) {
  std::string csvPath, onlyMesh;
  bool quick = false, trace = true;
  int repeats = 0;
  int threads = int(std::max(1u, std::thread::hardware_concurrency()));
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h")) {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (!std::strcmp(argv[i], "--csv") && i + 1 < argc) {
      csvPath = argv[++i];
    } else if (!std::strcmp(argv[i], "--quick")) {
      quick = true;
    } else if (!std::strcmp(argv[i], "--no-trace")) {
      trace = false;
    } else if (!std::strcmp(argv[i], "--repeats") && i + 1 < argc) {
      repeats = std::max(1, std::atoi(argv[++i]));
    } else if (!std::strcmp(argv[i], "--mesh") && i + 1 < argc) {
      onlyMesh = argv[++i];
    } else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc) {
      threads = std::atoi(argv[++i]);
      if (threads < 1) {
        std::fprintf(stderr, "bvh_bench: --threads must be >= 1\n");
        return 2;
      }
    } else {
      std::fprintf(stderr, "bvh_bench: unknown argument '%s'\n%s", argv[i], kUsage);
      return 2;
    }
  }
  try {
    struct Mesh {
      std::string name;
      std::vector<Triangle> tris;
      int rays, repeats;
    };
    std::vector<Mesh> meshes;
    if (onlyMesh.empty() || onlyMesh == "bunny")
      meshes.push_back({"bunny", loadObjTriangles(sourceDir() + "/assets/meshes/bunny.obj"), 200000, 5});
    if (onlyMesh.empty() || onlyMesh == "sphere1M") meshes.push_back({"sphere1M", displacedSphere(1024, 512), 100000, 3});
    if (onlyMesh == "sphere4M") meshes.push_back({"sphere4M", displacedSphere(2048, 1024), 100000, 3});
    if (meshes.empty()) throw Error("--mesh must be bunny, sphere1M or sphere4M");

    std::vector<Row> rows;
    std::printf("%-9s %9s %4s %4s %3s %9s %9s %8s %8s %9s %8s %5s %8s %5s %16s\n", "mesh", "tris", "bins", "leaf", "thr",
                "build_ms", "cpu_ms", "Mtris/s", "SAH", "nodes", "leaves", "depth", "Mrays/s", "hit%", "hash");
    for (const Mesh& m : meshes) {
      const std::vector<Ray> rays = trace ? randomRays(m.tris, m.rays) : std::vector<Ray>{};
      const std::vector<int> binChoices = quick ? std::vector<int>{16} : std::vector<int>{8, 16, 32};
      const std::vector<int> leafChoices = quick ? std::vector<int>{4} : std::vector<int>{1, 2, 4, 8};
      for (int bins : binChoices)
        for (int leaf : leafChoices)
          for (int thr : {1, threads}) {
            if (thr == threads && threads == 1 && !rows.empty() && rows.back().threads == 1 && rows.back().leaf == leaf &&
                rows.back().bins == bins && rows.back().mesh == m.name)
              continue;  // --threads 1: one row per setting
            const Row r = measure(m.name, m.tris, rays, bins, leaf, thr, repeats > 0 ? repeats : m.repeats);
            std::printf("%-9s %9zu %4d %4d %3d %9.2f %9.2f %8.2f %8.4f %9zu %8d %5d %8.3f %5.1f %016llx\n", r.mesh.c_str(),
                        r.tris, r.bins, r.leaf, r.threads, r.buildMs, r.cpuMs, r.mtris, r.sah, r.nodes, r.leaves, r.depth,
                        r.mrays, 100.0 * r.hitFraction, (unsigned long long)r.hash);
            std::fflush(stdout);
            rows.push_back(r);
          }
    }
    if (!csvPath.empty()) {
      std::ofstream csv(csvPath);
      if (!csv) throw Error(csvPath + ": cannot write");
      csv << "mesh,tris,bins,max_leaf,threads,build_ms,cpu_ms,mtris_per_s,sah_cost,nodes,leaves,depth,mrays_per_s,hit_fraction\n";
      for (const Row& r : rows)
        csv << r.mesh << ',' << r.tris << ',' << r.bins << ',' << r.leaf << ',' << r.threads << ',' << r.buildMs << ','
            << r.cpuMs << ',' << r.mtris << ','
            << r.sah << ',' << r.nodes << ',' << r.leaves << ',' << r.depth << ',' << r.mrays << ',' << r.hitFraction
            << '\n';
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bvh_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
