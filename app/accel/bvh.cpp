// bvh.cpp — binned-SAH BVH builder (a binary tree, packed into 64-byte gpu::BvhNode) and the C++ twins of the
// GLSL ray–triangle test (intersect.glsl) and stack traversal (traverse.glsl). All positions and
// distances are in world space; t is measured in units of |ray.dir|.
#include "accel/bvh.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <cmath>
#include <string>

#include "accel/ray_box.h"
#include "accel/spawn.h"
#include "util/error.h"

namespace caustica {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
// Deepest level a leaf may have (root = 1). Near-child-first traversal pushes at most one entry per
// level below the root, so a tree of depth <= this never needs more than CAUSTICA_BVH_STACK - 2 entries.
constexpr int kMaxLeafDepth = CAUSTICA_BVH_STACK - 1;
constexpr int kMaxBins = 64;

// 4-wide float vector (GCC/Clang vector extension, compiled to SSE/NEON): lanes x, y, z, unused.
typedef float F4 __attribute__((vector_size(16)));
typedef std::int32_t I4 __attribute__((vector_size(16)));
inline F4 splat(float x) { return F4{x, x, x, x}; }
inline F4 vmin(F4 a, F4 b) { return a < b ? a : b; }
inline F4 vmax(F4 a, F4 b) { return a > b ? a : b; }

// Axis-aligned box in world space. An empty box has lo = +inf, hi = -inf, which grow() treats as neutral.
struct Box {
  F4 lo = splat(kInf);
  F4 hi = splat(-kInf);
  void grow(const Box& b) {
    lo = vmin(lo, b.lo);
    hi = vmax(hi, b.hi);
  }
  void grow(F4 p) {
    lo = vmin(lo, p);
    hi = vmax(hi, p);
  }
  // Half the surface area, in double so that huge coordinates cannot overflow. Box must not be empty.
  double halfArea() const {
    const double dx = double(hi[0]) - lo[0], dy = double(hi[1]) - lo[1], dz = double(hi[2]) - lo[2];
    return dx * dy + dy * dz + dz * dx;
  }
};

// Build-time primitive (32 bytes): the finite bounds of one input triangle in lanes 0-2; its index
// split into two 16-bit halves stored as exact small floats in the 4th lanes (never used as geometry).
struct Prim {
  Box box;
  Prim(const Box& b, std::uint32_t index) : box(b) {
    box.lo[3] = float(index & 0xffffu);
    box.hi[3] = float(index >> 16);
  }
  std::uint32_t index() const { return std::uint32_t(box.lo[3]) | std::uint32_t(box.hi[3]) << 16; }
};

// Centroid of a prim's box (halves first, so no overflow near FLT_MAX).
inline F4 centroidOf(const Prim& p) { return splat(0.5f) * p.box.lo + splat(0.5f) * p.box.hi; }

// Bins of a centroid on all axes: floor((c - cmin) * scale) clamped to [0, bins - 1]. A NaN from a
// flat or overflowing axis (scale 0) becomes bin 0, and so does the 4th lane (scale 0 there too).
// Binning and partitioning both use this function.
inline I4 binsOf(F4 c, F4 cmin, F4 scale, F4 lastBin) {
  return __builtin_convertvector(vmin(vmax((c - cmin) * scale, splat(0.0f)), lastBin), I4);
}

struct Bin {
  Box box;
  int count = 0;
};

// Best split found so far: axis, position (first bin of the right child), cost
// (area * count summed over both children) and |left - right| counts for breaking ties.
struct Split {
  int axis = -1;
  int pos = 0;
  double cost = std::numeric_limits<double>::infinity();
  std::uint32_t imbalance = ~0u;
  void consider(int a, int p, double c, int countLeft, int countRight) {
    const std::uint32_t imb = std::uint32_t(std::abs(countLeft - countRight));
    if (c < cost || (c == cost && imb < imbalance)) {  // ties (e.g. zero areas) go to the balanced split
      axis = a;
      pos = p;
      cost = c;
      imbalance = imb;
    }
  }
  bool found() const { return axis >= 0 && std::isfinite(cost); }
};

// A node still to be built: its slot in the node array, its range of prims, its level, the bounds
// of its prims and the bounds of their centroids.
struct WorkItem {
  std::uint32_t node;
  std::uint32_t first;
  std::uint32_t count;
  int depth;
  Box box;
  Box cbox;
};

// Levels that a median-split subtree over n prims needs below its root: ceil(log2(ceil(n / leaf))).
int medianLevels(std::uint64_t n, std::uint64_t leaf) {
  const std::uint64_t leaves = (n + leaf - 1) / leaf;
  int levels = 0;
  while ((std::uint64_t(1) << levels) < leaves) ++levels;
  return levels;
}

// Bounds and centroid bounds of prims [first, first + count).
void boundsOfRange(const std::vector<Prim>& prims, std::uint32_t first, std::uint32_t count, Box& box, Box& cbox) {
  box = Box{};
  cbox = Box{};
  for (std::uint32_t i = first; i < first + count; ++i) {
    box.grow(prims[i].box);
    cbox.grow(centroidOf(prims[i]));
  }
}

// Finite box of one triangle. A triangle with a NaN or infinite coordinate never hits, so it is
// binned as a point at the origin; this keeps every bound and centroid finite.
Box triangleBox(const Triangle& tri) {
  Box b;
  for (const glm::vec3& p : tri.p) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      b.lo = b.hi = splat(0.0f);
      return b;
    }
    b.grow(F4{p.x, p.y, p.z, 0.0f});
  }
  return b;
}

}  // namespace

namespace {

// Shared state of one build: the prims (each subtree owns a disjoint range), the node array (sized for
// the largest possible tree; each subtree writes only the nodes it allocates) and the next free node.
struct BuildContext {
  std::vector<Prim>& prims;
  std::vector<BvhBinaryNode>& nodes;
  std::atomic<std::uint32_t> nextNode{1};
  int bins = 16;
  std::uint32_t maxLeaf = 4;
  double ct = 1.0, ci = 1.0;
  double rootArea = 1.0;
  bool rootAreaOk = false;
};

// Depth, leaf count and SAH cost (relative to the root's area) of a built part of the tree.
struct BuildStats {
  int depth = 0;
  int leafCount = 0;
  double sah = 0.0;
};

// Builds the subtree of `root` depth-first. With `deferred`, nodes of fewer than deferBelow prims are
// not built but appended to it (their node slots and prim ranges are already theirs).
void buildSubtree(BuildContext& ctx, const WorkItem& root, BuildStats& st, std::vector<WorkItem>* deferred,
                  std::uint32_t deferBelow) {
  const int bins = ctx.bins;
  const std::uint32_t maxLeaf = ctx.maxLeaf;
  const double ct = ctx.ct, ci = ctx.ci;
  std::vector<WorkItem> work{root};
  Bin binsPerAxis[3][kMaxBins];  // kept empty between nodes
  const F4 lastBin = splat(float(bins - 1));
  while (!work.empty()) {
    const WorkItem item = work.back();
    work.pop_back();
    if (deferred && item.count < deferBelow) {  // left for the parallel phase
      deferred->push_back(item);
      continue;
    }
    const double nodeArea = item.box.halfArea();
    const double relArea = ctx.rootAreaOk ? nodeArea / ctx.rootArea : 1.0;
    BvhBinaryNode& out = ctx.nodes[item.node];
    out.bmin = glm::vec3(item.box.lo[0], item.box.lo[1], item.box.lo[2]);
    out.bmax = glm::vec3(item.box.hi[0], item.box.hi[1], item.box.hi[2]);

    auto makeLeaf = [&]() {
      if (item.count > maxLeaf) throw Error("bvh.cpp: BVH depth bound violated (internal error)");
      BvhBinaryNode& leaf = ctx.nodes[item.node];
      leaf.leftFirst = item.first;
      leaf.triCount = item.count;
      st.leafCount++;
      st.depth = std::max(st.depth, item.depth);
      st.sah += ci * double(item.count) * relArea;
    };
    if (item.count == 1 || item.depth >= kMaxLeafDepth) {
      makeLeaf();
      continue;
    }

    // Axes with a usable centroid extent get binned; flat (or overflowing) axes get scale 0.
    F4 scale = splat(0.0f);
    bool anyAxis = false;
    for (int a = 0; a < 3; ++a) {
      const float s = float(bins) / (item.cbox.hi[a] - item.cbox.lo[a]);
      scale[a] = (s > 0.0f && std::isfinite(s)) ? s : 0.0f;
      anyAxis |= scale[a] > 0.0f;
    }

    // Binned SAH over the axes with a centroid extent; pos = first bin of the right child. Costs are
    // in units of area * count (the node's own terms are constant).
    Split best;
    if (anyAxis) {
      for (std::uint32_t i = item.first; i < item.first + item.count; ++i) {
        const Prim& p = ctx.prims[i];
        const I4 b = binsOf(centroidOf(p), item.cbox.lo, scale, lastBin);
        for (int a = 0; a < 3; ++a) {  // flat axes all land in bin 0 and are ignored below
          Bin& bin = binsPerAxis[a][b[a]];
          bin.box.grow(p.box);
          bin.count++;
        }
      }
      for (int a = 0; a < 3; ++a) {
        if (scale[a] <= 0.0f) {
          binsPerAxis[a][0] = Bin{};
          continue;
        }
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
        for (int k = 1; k < m; ++k) {
          const Bin& bin = binsPerAxis[a][used[k - 1]];
          acc.grow(bin.box);
          cnt += bin.count;
          best.consider(a, used[k], acc.halfArea() * cnt + rightCost[k], cnt, rightCount[k]);
        }
        for (int k = 0; k < m; ++k) binsPerAxis[a][used[k]] = Bin{};  // all bins empty again
      }
    }

    if (item.count <= maxLeaf) {
      // Small enough for a leaf: split only if SAH says it pays.
      const bool split = best.found() && ct * nodeArea + ci * best.cost < ci * double(item.count) * nodeArea;
      if (!split) {
        makeLeaf();
        continue;
      }
    }

    // Split at the SAH plane unless the depth budget requires a median split (which keeps
    // depth + medianLevels(count) constant, so leaves never pass kMaxLeafDepth).
    const bool forceMedian = item.depth + medianLevels(item.count, maxLeaf) >= kMaxLeafDepth;
    WorkItem left{0, item.first, 0, item.depth + 1, Box{}, Box{}};
    WorkItem right{0, 0, 0, item.depth + 1, Box{}, Box{}};
    if (best.found() && !forceMedian) {
      // In-place partition; child bounds come from the prims themselves, so they are exact.
      std::uint32_t i = item.first, j = item.first + item.count;
      while (i < j) {
        const F4 c = centroidOf(ctx.prims[i]);
        if (binsOf(c, item.cbox.lo, scale, lastBin)[best.axis] < best.pos) {
          left.box.grow(ctx.prims[i].box);
          left.cbox.grow(c);
          ++i;
        } else {
          --j;
          std::swap(ctx.prims[i], ctx.prims[j]);
          right.box.grow(ctx.prims[j].box);
          right.cbox.grow(c);
        }
      }
      left.count = i - item.first;
    }
    if (left.count == 0 || left.count == item.count) {
      // Median split along the widest centroid axis (any order when all centroids coincide).
      int a = 0;
      for (int k = 1; k < 3; ++k)
        if (item.cbox.hi[k] - item.cbox.lo[k] > item.cbox.hi[a] - item.cbox.lo[a]) a = k;
      left.count = item.count / 2;
      Prim* begin = ctx.prims.data() + item.first;
      std::nth_element(begin, begin + left.count, begin + item.count,
                       [a](const Prim& p, const Prim& q) { return centroidOf(p)[a] < centroidOf(q)[a]; });
      boundsOfRange(ctx.prims, item.first, left.count, left.box, left.cbox);
      boundsOfRange(ctx.prims, item.first + left.count, item.count - left.count, right.box, right.cbox);
    }
    right.first = item.first + left.count;
    right.count = item.count - left.count;

    left.node = ctx.nextNode.fetch_add(2);
    right.node = left.node + 1;
    ctx.nodes[item.node].leftFirst = left.node;
    ctx.nodes[item.node].triCount = 0;
    st.sah += ct * relArea;
    work.push_back(right);
    work.push_back(left);
  }

}

}  // namespace

Bvh buildBvh(const std::vector<Triangle>& triangles, const BvhBuildOptions& options) {
  if (options.bins < 2 || options.bins > kMaxBins)
    throw Error("bvh.cpp: BvhBuildOptions::bins must be in [2, " + std::to_string(kMaxBins) + "]");
  if (options.maxLeafSize < 1 || options.maxLeafSize > int(gpu::kBvhMaxLeafSize))
    throw Error("bvh.cpp: BvhBuildOptions::maxLeafSize must be in [1, " + std::to_string(gpu::kBvhMaxLeafSize) + "]");
  if (options.threads < 0) throw Error("bvh.cpp: BvhBuildOptions::threads must be >= 0");
  if (triangles.size() > std::size_t(gpu::kBvhFirstMask))
    throw Error("bvh.cpp: too many triangles (" + std::to_string(triangles.size()) + ")");

  Bvh bvh;
  const std::uint32_t n = std::uint32_t(triangles.size());

  if (n == 0) {  // one empty node with an inverted box; packed as a root of two empty slots
    BvhBinaryNode empty{};
    empty.bmin = glm::vec3(kInf);
    empty.bmax = glm::vec3(-kInf);
    bvh.binary.push_back(empty);
    bvh.depth = 1;
    bvh.leafCount = 1;
    bvh.nodes = packBvhNodes(bvh.binary);
    return bvh;
  }

  std::vector<Prim> prims;
  prims.reserve(n);
  for (std::uint32_t i = 0; i < n; ++i) prims.emplace_back(triangleBox(triangles[i]), i);

  bvh.binary.resize(2 * std::size_t(n) - 1);  // the most nodes a binary tree over n prims can have
  BuildContext ctx{prims, bvh.binary};
  ctx.bins = options.bins;
  ctx.maxLeaf = std::uint32_t(options.maxLeafSize);
  ctx.ct = options.costTraversal;
  ctx.ci = options.costIntersect;
  WorkItem root{0, 0, n, 1, Box{}, Box{}};
  boundsOfRange(prims, 0, n, root.box, root.cbox);
  ctx.rootArea = root.box.halfArea();
  ctx.rootAreaOk = ctx.rootArea > 0.0 && std::isfinite(ctx.rootArea);

  // The top of the tree on this thread, down to subtrees of fewer than n / (8 * threads) prims; those
  // are then built by `threads` threads, largest first. Every subtree owns its prim range and the
  // nodes it allocates, so the tree (shape, boxes, leaf order) is the one a single thread builds; only
  // the binary node numbering depends on scheduling, and packBvhNodes renumbers depth-first.
  unsigned threads = options.threads > 0 ? unsigned(options.threads) : std::max(1u, std::thread::hardware_concurrency());
  if (n < 65536) threads = 1;  // small meshes: starting threads costs more than it saves
  BuildStats top;
  std::vector<WorkItem> deferred;
  buildSubtree(ctx, root, top, threads > 1 ? &deferred : nullptr, std::max<std::uint32_t>(1, n / (8 * threads)));
  std::sort(deferred.begin(), deferred.end(), [](const WorkItem& x, const WorkItem& y) {
    return x.count != y.count ? x.count > y.count : x.first < y.first;
  });
  std::vector<BuildStats> stats(deferred.size());
  std::atomic<std::size_t> next{0};
  std::exception_ptr failure;
  std::mutex failureMutex;
  auto worker = [&]() {
    try {
      for (std::size_t k = next.fetch_add(1); k < deferred.size(); k = next.fetch_add(1))
        buildSubtree(ctx, deferred[k], stats[k], nullptr, 0);
    } catch (...) {
      std::lock_guard<std::mutex> lock(failureMutex);
      if (!failure) failure = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads && !deferred.empty(); ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);

  double sah = top.sah;
  bvh.depth = top.depth;
  bvh.leafCount = top.leafCount;
  for (const BuildStats& st : stats) {  // in a fixed order, so the sum does not depend on scheduling
    sah += st.sah;
    bvh.depth = std::max(bvh.depth, st.depth);
    bvh.leafCount += st.leafCount;
  }
  bvh.binary.resize(ctx.nextNode.load());

  if (bvh.depth >= CAUSTICA_BVH_STACK)
    throw Error("bvh.cpp: BVH depth " + std::to_string(bvh.depth) + " exceeds the traversal stack");
  bvh.sahCost = float(sah);
  bvh.nodes = packBvhNodes(bvh.binary);
  bvh.order.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) bvh.order[i] = prims[i].index();
  return bvh;
}

std::vector<gpu::BvhNode> packBvhNodes(const std::vector<BvhBinaryNode>& binary) {
  std::vector<gpu::BvhNode> out;
  if (binary.empty()) return out;
  const std::uint32_t kEmptyRef = gpu::kBvhEmptyRef;
  const glm::vec3 inf(kInf);
  // Ref of binary node b once packed: leaves in place, inner nodes by the index `innerIndex` gives.
  std::vector<std::uint32_t> innerIndex(binary.size(), gpu::kInvalidIndex);
  auto leafRef = [&](const BvhBinaryNode& b) {
    if (b.leftFirst > gpu::kBvhFirstMask || b.triCount > gpu::kBvhMaxLeafSize)
      throw Error("bvh.cpp: leaf out of the packed range (internal error)");
    return gpu::kBvhLeafBit | b.triCount << gpu::kBvhCountShift | b.leftFirst;
  };
  const BvhBinaryNode& root = binary[0];
  if (root.triCount > 0 || !(root.bmin.x <= root.bmax.x)) {  // one leaf, or an empty tree
    gpu::BvhNode n{};
    const bool empty = root.triCount == 0;
    n.lmin = empty ? inf : root.bmin;
    n.lmax = empty ? -inf : root.bmax;
    n.left = empty ? kEmptyRef : leafRef(root);
    n.rmin = inf;
    n.rmax = -inf;
    n.right = kEmptyRef;
    out.push_back(n);
    return out;
  }
  // Depth-first, parents before children; a node's children are packed where it is popped.
  out.reserve(binary.size() / 2 + 1);  // one per inner node: (binary nodes - 1) / 2
  std::vector<std::uint32_t> work{0};
  innerIndex[0] = 0;
  out.emplace_back();
  while (!work.empty()) {
    const std::uint32_t b = work.back();
    work.pop_back();
    const BvhBinaryNode& node = binary[b];
    const std::uint32_t l = node.leftFirst, r = node.leftFirst + 1;
    gpu::BvhNode n{};
    n.lmin = binary[l].bmin;
    n.lmax = binary[l].bmax;
    n.rmin = binary[r].bmin;
    n.rmax = binary[r].bmax;
    std::uint32_t refs[2];
    const std::uint32_t kids[2] = {l, r};
    for (int k = 0; k < 2; ++k) {
      const BvhBinaryNode& c = binary[kids[k]];
      if (c.triCount > 0) {
        refs[k] = leafRef(c);
      } else {
        innerIndex[kids[k]] = std::uint32_t(out.size());
        refs[k] = innerIndex[kids[k]];
        out.emplace_back();
      }
    }
    n.left = refs[0];
    n.right = refs[1];
    out[innerIndex[b]] = n;
    for (int k = 1; k >= 0; --k)
      if (binary[kids[k]].triCount == 0) work.push_back(kids[k]);
  }
  return out;
}

bool bvhBounds(const std::vector<gpu::BvhNode>& nodes, glm::vec3& lo, glm::vec3& hi) {
  lo = glm::vec3(kInf);
  hi = glm::vec3(-kInf);
  if (nodes.empty()) return false;
  const gpu::BvhNode& r = nodes[0];
  bool any = false;
  if (r.left != gpu::kBvhEmptyRef) {
    lo = glm::min(lo, r.lmin);
    hi = glm::max(hi, r.lmax);
    any = true;
  }
  if (r.right != gpu::kBvhEmptyRef) {
    lo = glm::min(lo, r.rmin);
    hi = glm::max(hi, r.rmax);
    any = true;
  }
  return any;
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

RayShear makeRayShear(const glm::vec3& dir) {
  const glm::vec3 ad = glm::abs(dir);
  RayShear s;
  s.kz = ad.x > ad.y ? (ad.x > ad.z ? 0 : 2) : (ad.y > ad.z ? 1 : 2);
  const glm::vec3 d = permuteToKz(dir, s.kz);
  s.sz = d.z == 0.0f ? 0.0f : 1.0f / d.z;
  s.sx = -d.x * s.sz;
  s.sy = -d.y * s.sz;
  return s;
}

// Woop, Benthin, Wald 2013 ("Watertight ray/triangle intersection"), in the form of pbrt-v4's
// IntersectTriangle: translate to the ray origin, permute so the largest direction component is z,
// shear so the ray is +z, then 2D edge functions. Shared edges give exactly negated edge functions,
// so no ray passes between two triangles. Exactly zero edge functions are recomputed in double.
bool intersectTriangleSheared(const glm::vec3& origin, const RayShear& rs, const glm::vec3& p0, const glm::vec3& p1,
                              const glm::vec3& p2, float tmax, float& t, float& u, float& v) {
  if (rs.sz == 0.0f) return false;  // zero direction
  const float sx = rs.sx, sy = rs.sy, sz = rs.sz;
  const int kz = rs.kz;

  const glm::vec3 a = permuteToKz(p0 - origin, kz);
  const glm::vec3 b = permuteToKz(p1 - origin, kz);
  const glm::vec3 c = permuteToKz(p2 - origin, kz);
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

  const float az = sz * a.z, bz = sz * b.z, cz = sz * c.z;
  const float tScaled = e0 * az + e1 * bz + e2 * cz;
  const float invDet = 1.0f / det;
  const float tt = tScaled * invDet;
  if (!(tt > 0.0f && tt < tmax)) return false;  // also rejects NaN
  // t must be conservatively positive: beyond the bound of its own rounding error (pbrt-v4), so a
  // ray spawned past a hit point's error box never re-hits the surface it leaves. Like pbrt-v4's,
  // this bound is right for unit-length directions only (it mixes units of t with world units):
  // every caller normalises (a short unnormalised shadow ray lost real occluders at 1e-4 scale).
  const float maxZt = std::max(std::fabs(az), std::max(std::fabs(bz), std::fabs(cz)));
  const float maxXt = std::max(std::fabs(ax), std::max(std::fabs(bx), std::fabs(cx)));
  const float maxYt = std::max(std::fabs(ay), std::max(std::fabs(by), std::fabs(cy)));
  const float deltaZ = gammaBound(3) * maxZt;
  const float deltaX = gammaBound(5) * (maxXt + maxZt);
  const float deltaY = gammaBound(5) * (maxYt + maxZt);
  const float deltaE = 2.0f * (gammaBound(2) * maxXt * maxYt + deltaY * maxXt + deltaX * maxYt);
  const float maxE = std::max(std::fabs(e0), std::max(std::fabs(e1), std::fabs(e2)));
  const float deltaT = 3.0f * (gammaBound(3) * maxE * maxZt + deltaE * maxZt + deltaZ * maxE) * std::fabs(invDet);
  if (tt <= deltaT) return false;
  t = tt;
  u = e1 * invDet;
  v = e2 * invDet;
  return true;
}

bool intersectTriangle(const Ray& ray, const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2,
                       float tmax, float& t, float& u, float& v) {
  return intersectTriangleSheared(ray.origin, makeRayShear(ray.dir), p0, p1, p2, tmax, t, u, v);
}

namespace {

using raybox::intersectAabb;
using raybox::kBoxPad;
using raybox::safeInverse;

// Traversal shared by closest and any hit, in the GLSL twin's order: near child first, the far one on
// a fixed-size stack with its entry distance; a popped subtree that starts beyond the closest hit is
// skipped (closest hit only). Leaves are packed into the refs (gpu_layout.h, BvhNode).
template <bool kAnyHit>
Hit traverse(const std::vector<gpu::BvhNode>& nodes, const std::vector<gpu::TriGeom>& tris,
             const Ray& ray, float tmax) {
  Hit hit;
  if (nodes.empty()) return hit;
  const glm::vec3 invDir = safeInverse(ray.dir);
  const RayShear rs = makeRayShear(ray.dir);

  float closest = tmax;
  std::uint32_t stackRef[CAUSTICA_BVH_STACK];
  float stackT[CAUSTICA_BVH_STACK];
  std::uint32_t sp = 0;
  std::uint32_t ref = 0;  // the root, an inner node
  // Next stacked ref that may still hold a closer hit, or kInvalidIndex.
  auto pop = [&]() -> std::uint32_t {
    while (sp > 0) {
      --sp;
      if (kAnyHit || stackT[sp] <= closest * kBoxPad) return stackRef[sp];
    }
    return gpu::kInvalidIndex;
  };
  for (;;) {
    if ((ref & gpu::kBvhLeafBit) == 0) {
      const gpu::BvhNode& node = nodes[ref];
      float tl, tr;
      const bool hl = intersectAabb(ray.origin, invDir, node.lmin, node.lmax, closest, tl);
      const bool hr = intersectAabb(ray.origin, invDir, node.rmin, node.rmax, closest, tr);
      const bool leftFirst = hl && (!hr || tl <= tr);
      // The builder bounds the depth, so the stack never overflows; the guard only protects memory.
      if (hl && hr && sp < CAUSTICA_BVH_STACK) {
        stackRef[sp] = leftFirst ? node.right : node.left;
        stackT[sp] = leftFirst ? tr : tl;
        ++sp;
      }
      if (hl || hr) {
        ref = leftFirst ? node.left : node.right;
        continue;
      }
    } else {
      const std::uint32_t first = ref & gpu::kBvhFirstMask;
      const std::uint32_t count = (ref >> gpu::kBvhCountShift) & 15u;
      for (std::uint32_t i = first; i < first + count; ++i) {
        const gpu::TriGeom& g = tris[i];
        float t, u, v;
        if (intersectTriangleSheared(ray.origin, rs, glm::vec3(g.v0), glm::vec3(g.v1), glm::vec3(g.v2), closest, t, u, v)) {
          closest = t;
          hit.t = t;
          hit.u = u;
          hit.v = v;
          hit.tri = i;
          if (kAnyHit) return hit;
        }
      }
    }
    ref = pop();
    if (ref == gpu::kInvalidIndex) break;
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
