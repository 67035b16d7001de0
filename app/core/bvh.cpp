// bvh.cpp — binned-SAH BVH builder (flattened to 32-byte gpu::BvhNode) and the C++ twins of the
// GLSL ray–triangle test (intersect.glsl) and stack traversal (traverse.glsl). All positions and
// distances are in world space; t is measured in units of |ray.dir|.
#include "bvh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "error.h"

namespace caustica {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
// Deepest level a leaf may have (root = 1). Near-child-first traversal pushes at most one entry per
// level below the root, so a tree of depth <= this never needs more than CAUSTICA_BVH_STACK - 2 entries.
constexpr int kMaxLeafDepth = CAUSTICA_BVH_STACK - 1;
constexpr int kMaxBins = 64;

// Axis-aligned box; an empty box has min = +inf, max = -inf (neutral for grow()).
struct Box {
  glm::vec3 min{kInf};
  glm::vec3 max{-kInf};
  void grow(const Box& b) {
    min = glm::min(min, b.min);
    max = glm::max(max, b.max);
  }
  // Half the surface area in double precision (no overflow for huge coordinates); 0 when empty.
  double halfArea() const {
    if (!(min.x <= max.x && min.y <= max.y && min.z <= max.z)) return 0.0;
    const double dx = double(max.x) - min.x, dy = double(max.y) - min.y, dz = double(max.z) - min.z;
    return dx * dy + dy * dz + dz * dx;
  }
};

// Build-time primitive: bounds, sanitised centroid and index of the input triangle (40 bytes).
struct Prim {
  Box box;
  glm::vec3 centroid;
  std::uint32_t index;
};

struct Bin {
  Box box;
  int count = 0;
};

// A node still to be built: its slot in the node array, its range of prims, its level and bounds.
struct WorkItem {
  std::uint32_t node;
  std::uint32_t first;
  std::uint32_t count;
  int depth;
  Box box;
};

// Levels that a median-split subtree over n prims needs below its root: ceil(log2(ceil(n / leaf))).
int medianLevels(std::uint64_t n, std::uint64_t leaf) {
  std::uint64_t leaves = (n + leaf - 1) / leaf;
  int levels = 0;
  while ((std::uint64_t(1) << levels) < leaves) ++levels;
  return levels;
}

// Bin of a centroid coordinate; identical arithmetic in binning and partitioning keeps them consistent.
inline int binOf(float c, float cmin, float scale, int bins) {
  const float f = (c - cmin) * scale;
  return f > 0.0f ? int(std::min(f, float(bins - 1))) : 0;
}

Box boxOfRange(const std::vector<Prim>& prims, std::uint32_t first, std::uint32_t count) {
  Box b;
  for (std::uint32_t i = first; i < first + count; ++i) b.grow(prims[i].box);
  return b;
}

// Box of one triangle ignoring NaN coordinates (a triangle with NaN never hits, so any box is safe).
Box triangleBox(const Triangle& tri) {
  Box b;
  for (const glm::vec3& p : tri.p)
    for (int a = 0; a < 3; ++a) {
      b.min[a] = std::fmin(b.min[a], p[a]);
      b.max[a] = std::fmax(b.max[a], p[a]);
    }
  return b;
}

}  // namespace

Bvh buildBvh(const std::vector<Triangle>& triangles, const BvhBuildOptions& options) {
  if (options.bins < 2 || options.bins > kMaxBins)
    throw Error("bvh.cpp: BvhBuildOptions::bins must be in [2, " + std::to_string(kMaxBins) + "]");
  if (options.maxLeafSize < 1) throw Error("bvh.cpp: BvhBuildOptions::maxLeafSize must be >= 1");
  if (triangles.size() >= std::size_t(0x7fffffff))
    throw Error("bvh.cpp: too many triangles (" + std::to_string(triangles.size()) + ")");

  Bvh bvh;
  const std::uint32_t n = std::uint32_t(triangles.size());
  const int bins = options.bins;
  const std::uint32_t maxLeaf = std::uint32_t(options.maxLeafSize);
  const double ct = options.costTraversal, ci = options.costIntersect;

  if (n == 0) {  // one empty node with an inverted box: traversal rejects it before reading children
    gpu::BvhNode empty{};
    empty.bmin = glm::vec3(kInf);
    empty.bmax = glm::vec3(-kInf);
    bvh.nodes.push_back(empty);
    bvh.depth = 1;
    bvh.leafCount = 1;
    return bvh;
  }

  std::vector<Prim> prims;
  prims.reserve(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    Prim p;
    p.box = triangleBox(triangles[i]);
    p.index = i;
    for (int a = 0; a < 3; ++a) {  // halves first: no overflow; non-finite centroids (NaN/inf) -> 0
      const float c = 0.5f * p.box.min[a] + 0.5f * p.box.max[a];
      p.centroid[a] = std::isfinite(c) ? c : 0.0f;
    }
    prims.push_back(p);
  }

  bvh.nodes.reserve(2 * std::size_t(n));
  bvh.nodes.emplace_back();
  std::vector<WorkItem> work;
  work.push_back({0, 0, n, 1, boxOfRange(prims, 0, n)});
  const double rootArea = work.back().box.halfArea();
  const bool rootAreaOk = rootArea > 0.0 && std::isfinite(rootArea);
  double sah = 0.0;

  std::array<std::array<Bin, kMaxBins>, 3> binsPerAxis;
  while (!work.empty()) {
    const WorkItem item = work.back();
    work.pop_back();
    const double area = rootAreaOk ? item.box.halfArea() / rootArea : 1.0;
    gpu::BvhNode& out = bvh.nodes[item.node];
    out.bmin = item.box.min;
    out.bmax = item.box.max;

    auto makeLeaf = [&]() {
      gpu::BvhNode& leaf = bvh.nodes[item.node];
      leaf.leftFirst = item.first;
      leaf.triCount = item.count;
      bvh.leafCount++;
      bvh.depth = std::max(bvh.depth, item.depth);
      sah += ci * double(item.count) * area;
    };
    if (item.count == 1 || item.depth >= kMaxLeafDepth) {
      if (item.count > maxLeaf) throw Error("bvh.cpp: BVH depth bound violated (internal error)");
      makeLeaf();
      continue;
    }

    // Centroid bounds decide which axes can be binned.
    Box cbox;
    for (std::uint32_t i = item.first; i < item.first + item.count; ++i) {
      cbox.min = glm::min(cbox.min, prims[i].centroid);
      cbox.max = glm::max(cbox.max, prims[i].centroid);
    }
    float scale[3];
    bool anyAxis = false;
    for (int a = 0; a < 3; ++a) {
      const float s = float(bins) / (cbox.max[a] - cbox.min[a]);
      scale[a] = (s > 0.0f && std::isfinite(s)) ? s : 0.0f;  // 0: axis is flat (or overflowing)
      anyAxis |= scale[a] > 0.0f;
    }

    // Binned SAH: find the cheapest plane over all axes. Costs are multiplied by the node's area.
    int bestAxis = -1, bestSplit = 0;
    double bestCost = std::numeric_limits<double>::infinity();
    std::uint32_t bestImbalance = ~0u;
    if (anyAxis) {
      // Flat axes have scale 0, so all their prims land in bin 0 and are ignored afterwards.
      for (auto& axisBins : binsPerAxis) std::fill(axisBins.begin(), axisBins.begin() + bins, Bin{});
      for (std::uint32_t i = item.first; i < item.first + item.count; ++i) {
        const Prim& p = prims[i];
        for (int a = 0; a < 3; ++a) {
          Bin& bin = binsPerAxis[a][binOf(p.centroid[a], cbox.min[a], scale[a], bins)];
          bin.box.grow(p.box);
          bin.count++;
        }
      }
      for (int a = 0; a < 3; ++a) {
        if (scale[a] <= 0.0f) continue;
        // Sweep over the non-empty bins only (planes between empty bins give the same partitions).
        int used[kMaxBins], m = 0;
        for (int i = 0; i < bins; ++i)
          if (binsPerAxis[a][i].count > 0) used[m++] = i;
        double rightCost[kMaxBins];  // area * count of used bins [k, m)
        int rightCount[kMaxBins];
        Box acc;
        int cnt = 0;
        for (int k = m - 1; k > 0; --k) {
          const Bin& bin = binsPerAxis[a][used[k]];
          acc.grow(bin.box);
          cnt += bin.count;
          rightCost[k] = acc.halfArea() * cnt;
          rightCount[k] = cnt;
        }
        acc = Box{};
        cnt = 0;
        for (int k = 0; k < m - 1; ++k) {
          const Bin& bin = binsPerAxis[a][used[k]];
          acc.grow(bin.box);
          cnt += bin.count;
          const double cost = acc.halfArea() * cnt + rightCost[k + 1];
          const std::uint32_t imbalance = std::uint32_t(std::abs(cnt - rightCount[k + 1]));
          // Ties (e.g. flat boxes with zero area) go to the more balanced split.
          if (cost < bestCost || (cost == bestCost && imbalance < bestImbalance)) {
            bestCost = cost;
            bestAxis = a;
            bestSplit = used[k + 1];  // left: bins < bestSplit
            bestImbalance = imbalance;
          }
        }
      }
    }

    const double nodeArea = item.box.halfArea();
    const bool sahFound = bestAxis >= 0 && std::isfinite(bestCost);
    if (item.count <= maxLeaf) {
      // Small enough for a leaf: split only if SAH says it pays (and depth allows, checked above).
      const bool split = sahFound && ct * nodeArea + ci * bestCost < ci * double(item.count) * nodeArea;
      if (!split) {
        makeLeaf();
        continue;
      }
    }

    // Split: SAH plane unless the depth budget requires a median split (which keeps
    // depth + medianLevels(count) constant, so leaves never pass kMaxLeafDepth).
    const bool forceMedian = item.depth + medianLevels(item.count, maxLeaf) >= kMaxLeafDepth;
    std::uint32_t leftCount = 0;
    Box leftBox, rightBox;
    if (sahFound && !forceMedian) {
      const int a = bestAxis;
      const float cmin = cbox.min[a], s = scale[a];
      Prim* begin = prims.data() + item.first;
      Prim* mid = std::partition(begin, begin + item.count, [&](const Prim& p) {
        return binOf(p.centroid[a], cmin, s, bins) < bestSplit;
      });
      leftCount = std::uint32_t(mid - begin);
      for (int i = 0; i < bins; ++i) (i < bestSplit ? leftBox : rightBox).grow(binsPerAxis[a][i].box);
    }
    if (leftCount == 0 || leftCount == item.count) {
      // Median split along the widest centroid axis (any order when all centroids coincide).
      int a = 0;
      const glm::vec3 ext = cbox.max - cbox.min;
      if (ext.y > ext[a]) a = 1;
      if (ext.z > ext[a]) a = 2;
      leftCount = item.count / 2;
      Prim* begin = prims.data() + item.first;
      std::nth_element(begin, begin + leftCount, begin + item.count,
                       [a](const Prim& p, const Prim& q) { return p.centroid[a] < q.centroid[a]; });
      leftBox = boxOfRange(prims, item.first, leftCount);
      rightBox = boxOfRange(prims, item.first + leftCount, item.count - leftCount);
    }

    const std::uint32_t left = std::uint32_t(bvh.nodes.size());
    bvh.nodes[item.node].leftFirst = left;
    bvh.nodes[item.node].triCount = 0;
    bvh.nodes.emplace_back();
    bvh.nodes.emplace_back();
    sah += ct * area;
    work.push_back({left + 1, item.first + leftCount, item.count - leftCount, item.depth + 1, rightBox});
    work.push_back({left, item.first, leftCount, item.depth + 1, leftBox});
  }

  if (bvh.depth >= CAUSTICA_BVH_STACK)
    throw Error("bvh.cpp: BVH depth " + std::to_string(bvh.depth) + " exceeds the traversal stack");
  bvh.sahCost = float(sah);
  bvh.order.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) bvh.order[i] = prims[i].index;
  return bvh;
}

std::vector<gpu::TriGeom> packTriGeom(const std::vector<Triangle>& triangles, const Bvh& bvh) {
  if (bvh.order.size() != triangles.size())
    throw Error("bvh.cpp: BVH was built for " + std::to_string(bvh.order.size()) + " triangles, got " +
                std::to_string(triangles.size()));
  std::vector<gpu::TriGeom> out(triangles.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const Triangle& t = triangles[bvh.order[i]];
    out[i].v0 = glm::vec4(t.p[0], glm::uintBitsToFloat(t.material));
    out[i].v1 = glm::vec4(t.p[1], 0.0f);
    out[i].v2 = glm::vec4(t.p[2], 0.0f);
  }
  return out;
}

namespace {

// Cyclic permutation that moves axis kz to z (keeps handedness; both faces are accepted anyway).
inline glm::vec3 permuteToKz(const glm::vec3& a, int kz) {
  return kz == 0 ? glm::vec3(a.y, a.z, a.x) : (kz == 1 ? glm::vec3(a.z, a.x, a.y) : a);
}

}  // namespace

// Woop, Benthin, Wald 2013 ("Watertight ray/triangle intersection"), in the form of pbrt-v4's
// IntersectTriangle: translate to the ray origin, permute so the largest direction component is z,
// shear so the ray is +z, then 2D edge functions. Shared edges give exactly negated edge functions,
// so no ray passes between two triangles. Exactly zero edge functions are recomputed in double.
bool intersectTriangle(const Ray& ray, const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2,
                       float tmax, float& t, float& u, float& v) {
  const glm::vec3 ad = glm::abs(ray.dir);
  const int kz = ad.x > ad.y ? (ad.x > ad.z ? 0 : 2) : (ad.y > ad.z ? 1 : 2);
  const glm::vec3 d = permuteToKz(ray.dir, kz);
  if (d.z == 0.0f) return false;  // zero direction
  const float sz = 1.0f / d.z;
  const float sx = -d.x * sz, sy = -d.y * sz;

  const glm::vec3 a = permuteToKz(p0 - ray.origin, kz);
  const glm::vec3 b = permuteToKz(p1 - ray.origin, kz);
  const glm::vec3 c = permuteToKz(p2 - ray.origin, kz);
  const float ax = a.x + sx * a.z, ay = a.y + sy * a.z;
  const float bx = b.x + sx * b.z, by = b.y + sy * b.z;
  const float cx = c.x + sx * c.z, cy = c.y + sy * c.z;

  float e0 = bx * cy - by * cx;  // edge function opposite p0 (weight of p0)
  float e1 = cx * ay - cy * ax;  // opposite p1
  float e2 = ax * by - ay * bx;  // opposite p2
  if (e0 == 0.0f || e1 == 0.0f || e2 == 0.0f) {  // products of floats are exact in double
    e0 = float(double(bx) * double(cy) - double(by) * double(cx));
    e1 = float(double(cx) * double(ay) - double(cy) * double(ax));
    e2 = float(double(ax) * double(by) - double(ay) * double(bx));
  }
  if ((e0 < 0.0f || e1 < 0.0f || e2 < 0.0f) && (e0 > 0.0f || e1 > 0.0f || e2 > 0.0f)) return false;
  const float det = e0 + e1 + e2;
  if (det == 0.0f) return false;  // ray in the triangle's plane
  // Zero-area triangles can pass the test above once their vertices are rounded in ray space.
  const glm::vec3 n = glm::cross(p1 - p0, p2 - p0);
  if (n.x == 0.0f && n.y == 0.0f && n.z == 0.0f) return false;

  const float tScaled = e0 * (sz * a.z) + e1 * (sz * b.z) + e2 * (sz * c.z);
  const float invDet = 1.0f / det;
  const float tt = tScaled * invDet;
  if (!(tt > 0.0f && tt < tmax)) return false;  // also rejects NaN
  t = tt;
  u = e1 * invDet;
  v = e2 * invDet;
  return true;
}

namespace {

constexpr float kDirTiny = 1e-20f;
// Relative widening of a box's exit distance: covers the rounding of the slab distances and of t.
constexpr float kBoxPad = 1.0f + 1.0f / (1 << 20);
constexpr float kBig = 3.0e38f;

// Guarded reciprocal: |d| < 1e-20 becomes +-1e-20 (sign by d >= 0, as in GLSL), so never inf or NaN.
inline glm::vec3 safeInverse(const glm::vec3& d) {
  glm::vec3 r;
  for (int a = 0; a < 3; ++a) {
    const float g = std::fabs(d[a]) < kDirTiny ? (d[a] >= 0.0f ? kDirTiny : -kDirTiny) : d[a];
    r[a] = 1.0f / g;
  }
  return r;
}

// Slab test; twin of intersectAabb() in intersect.glsl. tnear: entry distance clamped to >= 0.
// An exit distance of exactly 0 (origin on a slab plane with a guarded ~0 direction component)
// is treated as "inside" so that rays lying on a box face still visit it; this is conservative.
inline bool intersectAabb(const glm::vec3& org, const glm::vec3& invDir, const glm::vec3& bmin,
                          const glm::vec3& bmax, float tmax, float& tnear) {
  const glm::vec3 t0 = (bmin - org) * invDir;
  const glm::vec3 t1 = (bmax - org) * invDir;
  const glm::vec3 lo = glm::min(t0, t1);
  glm::vec3 hi = glm::max(t0, t1);
  for (int a = 0; a < 3; ++a) hi[a] = hi[a] == 0.0f ? kBig : hi[a];
  tnear = std::max(std::max(lo.x, lo.y), std::max(lo.z, 0.0f));
  const float tfar = std::min(std::min(hi.x, hi.y), std::min(hi.z, tmax)) * kBoxPad;
  return tnear <= tfar;
}

// Traversal shared by closest and any hit: near child first, far child on a fixed-size stack.
template <bool kAnyHit>
Hit traverse(const std::vector<gpu::BvhNode>& nodes, const std::vector<gpu::TriGeom>& tris,
             const Ray& ray, float tmax) {
  Hit hit;
  if (nodes.empty()) return hit;
  const gpu::BvhNode& root = nodes[0];
  if (!(root.bmin.x <= root.bmax.x)) return hit;  // empty scene (inverted root box)
  const glm::vec3 invDir = safeInverse(ray.dir);
  float tnear;
  if (!intersectAabb(ray.origin, invDir, root.bmin, root.bmax, tmax, tnear)) return hit;

  float closest = tmax;
  std::uint32_t stack[CAUSTICA_BVH_STACK];
  std::uint32_t sp = 0;
  std::uint32_t index = 0;
  for (;;) {
    const gpu::BvhNode& node = nodes[index];
    if (node.triCount > 0) {
      for (std::uint32_t i = node.leftFirst; i < node.leftFirst + node.triCount; ++i) {
        const gpu::TriGeom& g = tris[i];
        float t, u, v;
        if (intersectTriangle(ray, glm::vec3(g.v0), glm::vec3(g.v1), glm::vec3(g.v2), closest, t, u, v)) {
          closest = t;
          hit.t = t;
          hit.u = u;
          hit.v = v;
          hit.tri = i;
          if (kAnyHit) return hit;
        }
      }
    } else {
      const std::uint32_t left = node.leftFirst;
      float tl, tr;
      const bool hl = intersectAabb(ray.origin, invDir, nodes[left].bmin, nodes[left].bmax, closest, tl);
      const bool hr = intersectAabb(ray.origin, invDir, nodes[left + 1].bmin, nodes[left + 1].bmax, closest, tr);
      if (hl && hr) {
        const std::uint32_t first = tl <= tr ? left : left + 1;
        // The builder bounds the depth, so this never overflows; the guard only protects memory.
        if (sp < CAUSTICA_BVH_STACK) stack[sp++] = first == left ? left + 1 : left;
        index = first;
        continue;
      }
      if (hl || hr) {
        index = hl ? left : left + 1;
        continue;
      }
    }
    if (sp == 0) break;
    index = stack[--sp];
  }
  return hit;
}

}  // namespace

Hit traceClosest(const std::vector<gpu::BvhNode>& nodes, const std::vector<gpu::TriGeom>& tris,
                 const Ray& ray, float tmax) {
  return traverse<false>(nodes, tris, ray, tmax);
}

bool traceOccluded(const std::vector<gpu::BvhNode>& nodes, const std::vector<gpu::TriGeom>& tris,
                   const Ray& ray, float tmax) {
  return traverse<true>(nodes, tris, ray, tmax).found();
}

}  // namespace caustica
