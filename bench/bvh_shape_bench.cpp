// bvh_shape_bench.cpp — benchmark (not a test) of the wide tree's shape as an 8-lane lock-step SIMD group
// (llvmpipe) pays for it: per ray node visits, leaves and triangle tests, and per group of 8 rays the
// max-over-lanes inner-loop and leaf-loop iterations, for camera, bounce and shadow rays of bundled scenes.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <random>
#include <string>
#include <vector>

#include "accel/bvh.h"
#include "accel/intersect.h"
#include "accel/bvh_wide.h"
#include "accel/ray_box.h"
#include "scene/assets.h"
#include "scene/scene.h"
#include "util/error.h"

using namespace caustica;

namespace {

const char* kUsage =
    "usage: bvh_shape_bench [--size N] [--shape SPEC]... SCENE...\n"
    "For each scene and each SPEC (the syntax of $CAUSTICA_BVH_SHAPE, e.g. collapse=greedy or\n"
    "collapse=sah,wideleaf=4,leaf=1; '' = the defaults), builds the tree and traces with the C++ twin of\n"
    "the wide traversal: camera rays (one per pixel of an N x N image, default 128, groups of 8 pixels\n"
    "along a row, as llvmpipe's SIMD lanes in the 8x8 work group), two diffuse/specular bounces and one\n"
    "shadow ray per camera hit to a random emitter point (or punctual light). Prints per ray node visits,\n"
    "leaves, triangle tests, and per group of 8 the lock-step iterations: for each outer-loop step the\n"
    "inner loop runs max(1, most node visits of a lane) times and the leaf loop max(1, most triangles).\n";

// One lane's traversal, as traverseWide in bvh_wide.cpp (GLSL twin), recording per outer-loop step
// (one leaf, or the end) the node visits before it and the triangles tested.
struct LaneTrace {
  std::vector<int> inner, tris;
  int nodes = 0, leaves = 0, triTests = 0;
};

template <bool kAnyHit>
Hit traceCounted(const std::vector<gpu::BvhWideNode>& nodes, const std::vector<gpu::TriGeom>& tris, const Ray& ray,
                 float tmax, LaneTrace& lane) {
  Hit hit;
  const glm::vec3 invDir = raybox::safeInverse(ray.dir);
  const RayShear rs = makeRayShear(ray.dir);
  float closest = std::min(tmax, 3.0e38f);
  std::vector<std::uint32_t> stack;
  std::uint32_t ref = 0;
  int inner = 0;
  for (;;) {
    if ((ref & gpu::kBvhLeafBit) == 0) {
      ++inner;
      ++lane.nodes;
      const gpu::BvhWideNode& n = nodes[ref];
      std::uint32_t r[4];
      float t[4];
      int hits = 0;
      for (int k = 0; k < 4; ++k) {
        const glm::vec3 lo(n.minX[k], n.minY[k], n.minZ[k]), hi(n.maxX[k], n.maxY[k], n.maxZ[k]);
        float tn;
        const bool h = raybox::intersectAabb(ray.origin, invDir, lo, hi, closest, tn);
        t[k] = h ? tn : 3.4e38f;
        r[k] = n.child[k];
        hits += h;
      }
      auto cswap = [&](int a, int b) {
        if (t[b] < t[a]) std::swap(t[a], t[b]), std::swap(r[a], r[b]);
      };
      cswap(0, 1), cswap(2, 3), cswap(0, 2), cswap(1, 3), cswap(1, 2);
      for (int k = hits - 1; k >= 1; --k) stack.push_back(r[k]);
      if (hits > 0) {
        ref = r[0];
        continue;
      }
      // As the GLSL's BVH_INNER_STEP: a node entering no child pops the stack within the inner loop;
      // only an empty stack ends it, with the empty leaf.
      if (!stack.empty()) {
        ref = stack.back();
        stack.pop_back();
        continue;
      }
      ref = gpu::kBvhEmptyRef;
    }
    const std::uint32_t count = (ref >> gpu::kBvhCountShift) & 15u;
    int tested = 0;
    bool done = false;
    for (std::uint32_t i = 0; i < count; ++i) {
      ++tested;
      const std::uint32_t one = gpu::kBvhLeafBit | 1u << gpu::kBvhCountShift | ((ref & gpu::kBvhFirstMask) + i);
      if (intersectLeaf(tris, one, ray.origin, rs, kAnyHit, closest, hit) && kAnyHit) {
        done = true;
        break;
      }
    }
    lane.inner.push_back(inner);
    lane.tris.push_back(tested);
    lane.leaves += count > 0;
    lane.triTests += tested;
    inner = 0;
    if (done || stack.empty()) break;
    ref = stack.back();
    stack.pop_back();
  }
  return hit;
}

struct Totals {
  double rays = 0, nodes = 0, leaves = 0, tris = 0;        // per ray sums
  double groups = 0, gInner = 0, gLeaf = 0, gOuter = 0;   // per group sums (lock-step iterations)
  void addGroup(const std::vector<LaneTrace>& lanes) {
    if (lanes.empty()) return;
    std::size_t steps = 0;
    for (const LaneTrace& l : lanes) {
      rays += 1, nodes += l.nodes, leaves += l.leaves, tris += l.triTests;
      steps = std::max(steps, l.inner.size());
    }
    groups += 1;
    gOuter += double(steps);
    for (std::size_t s = 0; s < steps; ++s) {
      int mi = 1, mt = 1;  // every loop body runs at least once (masked)
      for (const LaneTrace& l : lanes)
        if (s < l.inner.size()) mi = std::max(mi, l.inner[s]), mt = std::max(mt, l.tris[s]);
      gInner += mi;
      gLeaf += mt;
    }
  }
};

struct Rng {
  std::mt19937 gen;
  explicit Rng(unsigned s) : gen(s) {}
  float u() { return std::uniform_real_distribution<float>(0.0f, 1.0f)(gen); }
};

glm::vec3 cosineAround(const glm::vec3& n, Rng& rng) {
  const float r = std::sqrt(rng.u()), phi = 6.2831853f * rng.u();
  const glm::vec3 a = std::fabs(n.x) > 0.5f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
  const glm::vec3 t = glm::normalize(glm::cross(a, n)), b = glm::cross(n, t);
  return glm::normalize(r * std::cos(phi) * t + r * std::sin(phi) * b + std::sqrt(std::max(0.0f, 1 - r * r)) * n);
}

void run(const std::string& sceneName, const std::vector<std::string>& specs, int size) {
  const Scene scene = loadScene(resolveScenePath(sceneName));
  for (const std::string& spec : specs) {
    const BvhShape shape = parseBvhShape(spec);
    const Bvh bvh = buildBvh(scene.triangles, shape.build);
    const BvhWide wide = packBvhWideNodes(bvh.nodes, shape.collapse);
    const std::vector<gpu::TriGeom> geom = packTriGeom(scene.triangles, bvh);
    // Leaf order -> input index, for the material of a hit.
    int slots = 0, leaves = 0, leafTris = 0;
    for (const gpu::BvhWideNode& n : wide.nodes)
      for (int k = 0; k < 4; ++k)
        if (n.child[k] != gpu::kBvhEmptyRef) {
          ++slots;
          if (n.child[k] & gpu::kBvhLeafBit) ++leaves, leafTris += (n.child[k] >> gpu::kBvhCountShift) & 15u;
        }
    std::vector<glm::vec3> lightPoints;  // emitter triangles' centres are enough for the shadow rays' shape
    std::vector<int> emitters;
    for (std::size_t i = 0; i < scene.triangles.size(); ++i)
      if (scene.triangles[i].material < scene.materials.size() && scene.materials[scene.triangles[i].material].isEmissive())
        emitters.push_back(int(i));
    for (const PunctualLight& p : scene.punctualLights)
      if (p.type != PunctualType::Directional) lightPoints.push_back(p.position);
    Camera cam = scene.cameras.empty() ? autoCamera(scene.bounds) : scene.cameras[0];
    const glm::vec3 right = glm::normalize(glm::cross(cam.forward, cam.up));
    const float th = std::tan(0.5f * cam.yfov), aspect = 1.0f;
    Rng rng(1);
    Totals tot[4];  // camera, bounce 1, bounce 2, shadow
    for (int y = 0; y < size; ++y)
      for (int x0 = 0; x0 < size; x0 += 8) {
        std::vector<LaneTrace> lanes[4];
        std::vector<Ray> cur;
        for (int x = x0; x < std::min(size, x0 + 8); ++x) {
          const float px = (2.0f * (x + rng.u()) / size - 1.0f) * th * aspect, py = (1.0f - 2.0f * (y + rng.u()) / size) * th;
          Ray r;
          r.origin = cam.position;
          r.dir = glm::normalize(cam.forward + px * right + py * cam.up);
          cur.push_back(r);
        }
        for (int gen = 0; gen < 3; ++gen) {
          std::vector<Ray> next;
          for (const Ray& r : cur) {
            LaneTrace lane;
            const Hit h = traceCounted<false>(wide.nodes, geom, r, 3.0e38f, lane);
            lanes[gen].push_back(lane);
            if (!h.found()) continue;
            const gpu::TriGeom& g = geom[h.tri];
            const std::uint32_t src = bvh.order[h.tri];
            const Material& m = scene.materials[std::min<std::size_t>(scene.triangles[src].material, scene.materials.size() - 1)];
            glm::vec3 n = glm::normalize(glm::cross(glm::vec3(g.v1) - glm::vec3(g.v0), glm::vec3(g.v2) - glm::vec3(g.v0)));
            if (!std::isfinite(n.x)) continue;
            const bool front = glm::dot(n, r.dir) < 0.0f;
            if (!front) n = -n;
            const glm::vec3 p = r.origin + h.t * r.dir;
            Ray b;
            if (m.transmission > 0.0f) {  // refract (ior 1.5), else reflect
              const float eta = front ? 1.0f / 1.5f : 1.5f, c = -glm::dot(n, r.dir), k = 1 - eta * eta * (1 - c * c);
              b.dir = k < 0 ? glm::reflect(r.dir, n) : glm::normalize(eta * r.dir + (eta * c - std::sqrt(k)) * n);
            } else if (m.metallic >= 1.0f && m.roughness < 0.2f) {
              b.dir = glm::reflect(r.dir, n);
            } else {
              b.dir = cosineAround(n, rng);
            }
            b.origin = p + (glm::dot(b.dir, n) > 0 ? 1e-4f : -1e-4f) * n;
            next.push_back(b);
            if (gen == 0 && (!emitters.empty() || !lightPoints.empty())) {  // one shadow ray per camera hit
              const std::size_t pick = std::size_t(rng.u() * float(emitters.size() + lightPoints.size()));
              glm::vec3 q;
              if (pick < emitters.size()) {
                const Triangle& e = scene.triangles[emitters[pick]];
                float a = rng.u(), c = rng.u();
                if (a + c > 1) a = 1 - a, c = 1 - c;
                q = e.p[0] + a * (e.p[1] - e.p[0]) + c * (e.p[2] - e.p[0]);
              } else {
                q = lightPoints[std::min(pick - emitters.size(), lightPoints.size() - 1)];
              }
              Ray s;
              s.origin = p + 1e-4f * n;
              const glm::vec3 d = q - s.origin;
              const float dist = glm::length(d);
              if (dist > 0.0f) {
                s.dir = d / dist;
                LaneTrace sl;
                traceCounted<true>(wide.nodes, geom, s, dist * 0.999f, sl);
                lanes[3].push_back(sl);
              }
            }
          }
          cur = next;
        }
        for (int k = 0; k < 4; ++k) tot[k].addGroup(lanes[k]);
      }
    std::printf("%-20s %-34s wide %5zu nodes %.2f children/node, %d leaves (%.2f tris), depth %d, stack %d\n",
                sceneName.c_str(), spec.empty() ? "(default)" : spec.c_str(), wide.nodes.size(),
                double(slots) / double(wide.nodes.size()), leaves, double(leafTris) / std::max(1, leaves), wide.depth,
                wide.stackNeed);
    const char* kinds[4] = {"camera", "bounce1", "bounce2", "shadow"};
    double sumInner = 0, sumLeaf = 0, sumOuter = 0, sumGroups = 0;
    for (int k = 0; k < 4; ++k) {
      const Totals& t = tot[k];
      if (t.rays == 0) continue;
      std::printf("  %-8s per ray: nodes %6.2f leaves %5.2f tris %6.2f | per group of 8: inner %6.2f leaf %6.2f outer %5.2f\n",
                  kinds[k], t.nodes / t.rays, t.leaves / t.rays, t.tris / t.rays, t.gInner / t.groups, t.gLeaf / t.groups,
                  t.gOuter / t.groups);
      sumInner += t.gInner, sumLeaf += t.gLeaf, sumOuter += t.gOuter, sumGroups += t.groups;
    }
    std::printf("  all      per group: inner %6.2f leaf %6.2f outer %5.2f\n", sumInner / sumGroups, sumLeaf / sumGroups,
                sumOuter / sumGroups);
  }
}

}  // namespace

int main(int argc, char** argv) {
  try {
    int size = 128;
    std::vector<std::string> specs, scenes;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--help" || a == "-h") {
        std::fputs(kUsage, stdout);
        return 0;
      } else if (a == "--size" && i + 1 < argc) {
        size = std::max(8, std::atoi(argv[++i]));
      } else if (a == "--shape" && i + 1 < argc) {
        specs.push_back(argv[++i]);
      } else if (!a.empty() && a[0] == '-') {
        throw Error("bvh_shape_bench: unknown option " + a + "\n" + kUsage);
      } else {
        scenes.push_back(a);
      }
    }
    if (specs.empty()) specs.push_back("");
    if (scenes.empty()) scenes.push_back("cornell-dispersion");
    for (const std::string& s : scenes) run(s, specs, size);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
}
