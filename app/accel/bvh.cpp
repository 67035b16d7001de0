// bvh.cpp — binned-SAH BVH builder (writes 64-byte gpu::BvhNode directly, on threads) and the C++ twins of the
// GLSL ray–triangle test (intersect.glsl) and stack traversal (traverse.glsl). All positions and
// distances are in world space; t is measured in units of |ray.dir|.
#include "accel/bvh.h"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <memory>
#include <new>
#include <exception>
#include <mutex>
#include <thread>
#include <cmath>
#include <string>
#if defined(__SSE__)
#include <xmmintrin.h>
#endif

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
#if defined(__SSE__)
// minps/maxps compute exactly a < b ? a : b and a > b ? a : b per lane (GCC otherwise emits compare + blend).
inline F4 vmin(F4 a, F4 b) { return F4(_mm_min_ps(__m128(a), __m128(b))); }
inline F4 vmax(F4 a, F4 b) { return F4(_mm_max_ps(__m128(a), __m128(b))); }
#else
inline F4 vmin(F4 a, F4 b) { return a < b ? a : b; }
inline F4 vmax(F4 a, F4 b) { return a > b ? a : b; }
#endif

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

// A node still to be built (an inner node): its slot in the node array being written, its range of
// prims, its level (root = 1), the bounds of its prims and the bounds of their centroids.
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
void boundsOfRange(const Prim* prims, std::uint32_t first, std::uint32_t count, Box& box, Box& cbox) {
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

typedef Bin Bins[3][kMaxBins];

// Ref of a leaf over prims [first, first + count) (gpu_layout.h, BvhNode).
inline std::uint32_t leafRef(std::uint32_t first, std::uint32_t count) {
  if (first > gpu::kBvhFirstMask || count > gpu::kBvhMaxLeafSize || count == 0)
    throw Error("bvh.cpp: leaf out of the packed range (internal error)");
  return gpu::kBvhLeafBit | count << gpu::kBvhCountShift | first;
}

// Runs fn(t) for t in [0, threads), t = 0 on the calling thread, and rethrows the first exception.
template <class Fn>
void runOnThreads(unsigned threads, const Fn& fn) {
  std::exception_ptr failure;
  std::mutex failureMutex;
  auto guarded = [&](unsigned t) {
    try {
      fn(t);
    } catch (...) {
      std::lock_guard<std::mutex> lock(failureMutex);
      if (!failure) failure = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(guarded, t);
  guarded(0);
  for (std::thread& th : pool) th.join();
  if (failure) std::rethrow_exception(failure);
}

// Settings and shared inputs of one build. Every subtree owns a disjoint range of `prims`.
struct BuildContext {
  Prim* prims = nullptr;
  int bins = 16;
  std::uint32_t maxLeaf = 4;
  double ct = 1.0, ci = 1.0;
  double rootArea = 1.0;
  bool rootAreaOk = false;
  unsigned threads = 1;  // for binning the large nodes at the top of the tree
};

// Depth, leaf count and SAH cost (relative to the root's surface area) of a built part of the tree.
struct BuildStats {
  int depth = 0;
  int leafCount = 0;
  double sah = 0.0;
};

// Nodes at least this large are binned on all threads (top of the tree in a threaded build).
constexpr std::uint32_t kParallelBinMin = 1u << 15;

// Per-axis bin scales: bins / centroid extent, 0 on a flat (or overflowing) axis, which is then not binned.
F4 binScale(const Box& cbox, int bins, bool& anyAxis) {
  F4 scale = splat(0.0f);
  anyAxis = false;
  for (int a = 0; a < 3; ++a) {
    const float s = float(bins) / (cbox.hi[a] - cbox.lo[a]);
    scale[a] = (s > 0.0f && std::isfinite(s)) ? s : 0.0f;
    anyAxis |= scale[a] > 0.0f;
  }
  return scale;
}

// Adds prims [first, first + count) to the bins of all three axes (flat axes all land in bin 0).
void binPrims(const Prim* prims, std::uint32_t first, std::uint32_t count, F4 cmin, F4 scale, int nbins, Bins& bins) {
  const F4 lastBin = splat(float(nbins - 1));
  for (const Prim *p = prims + first, *end = prims + first + count; p < end; ++p) {
    const I4 b = binsOf(centroidOf(*p), cmin, scale, lastBin);
    for (int a = 0; a < 3; ++a) {
      Bin& bin = bins[a][b[a]];
      bin.box.grow(p->box);
      bin.count++;
    }
  }
}

// Binned SAH sweep over the axes with a centroid extent; pos = first bin of the right child. Costs are
// in units of area * count (the node's own terms are constant). Leaves every bin empty again.
void sweepBins(Bins& binsPerAxis, F4 scale, int bins, Split& best) {
  for (int a = 0; a < 3; ++a) {
    if (scale[a] <= 0.0f) {
      binsPerAxis[a][0] = Bin{};
      continue;
    }
    // Sweep over the non-empty bins only (planes between empty bins give the same partitions).
    int used[kMaxBins], m = 0;
    for (int i = 0; i < bins; ++i) {  // branch-free: the pattern of empty bins is unpredictable
      used[m] = i;
      m += binsPerAxis[a][i].count > 0;
    }
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

// Nodes of at most this many prims find their split without the bin arrays (smallSplit).
// (At most maxLeafSize prims: the leaf-or-split decisions, half of all split searches. Larger values
// measured no faster on the 1 M sphere.)
constexpr std::uint32_t kSmallNode = 4;

// The binned-SAH split of a small node, equal to binning and sweeping it (same candidate planes in the
// same order, same float boxes and double costs), but over its prims sorted by bin instead of over all
// bins: only the non-empty bins exist, so nothing is scanned or cleared.
void smallSplit(const Prim* prims, const WorkItem& item, F4 scale, F4 lastBin, Split& best) {
  const std::uint32_t count = item.count;
  I4 bin[kSmallNode];
  for (std::uint32_t i = 0; i < count; ++i) bin[i] = binsOf(centroidOf(prims[item.first + i]), item.cbox.lo, scale, lastBin);
  for (int a = 0; a < 3; ++a) {
    if (scale[a] <= 0.0f) continue;
    int idx[kSmallNode];  // prims by bin on this axis (insertion sort)
    for (std::uint32_t i = 0; i < count; ++i) {
      std::uint32_t j = i;
      for (; j > 0 && bin[idx[j - 1]][a] > bin[i][a]; --j) idx[j] = idx[j - 1];
      idx[j] = int(i);
    }
    // Groups of equal bins: the non-empty bins, in order.
    Box groupBox[kSmallNode];
    int groupCount[kSmallNode], groupBin[kSmallNode], m = 0;
    for (std::uint32_t i = 0; i < count; ++i) {
      const int b = bin[idx[i]][a];
      if (m == 0 || groupBin[m - 1] != b) {
        groupBin[m] = b;
        groupBox[m] = Box{};
        groupCount[m] = 0;
        ++m;
      }
      groupBox[m - 1].grow(prims[item.first + idx[i]].box);
      groupCount[m - 1]++;
    }
    double rightCost[kSmallNode];
    int rightCount[kSmallNode];
    Box acc;
    int cnt = 0;
    for (int k = m - 1; k > 0; --k) {
      acc.grow(groupBox[k]);
      cnt += groupCount[k];
      rightCost[k] = acc.halfArea() * cnt;
      rightCount[k] = cnt;
    }
    acc = Box{};
    cnt = 0;
    for (int k = 1; k < m; ++k) {
      acc.grow(groupBox[k - 1]);
      cnt += groupCount[k - 1];
      best.consider(a, groupBin[k], acc.halfArea() * cnt + rightCost[k], cnt, rightCount[k]);
    }
  }
}

// Best binned-SAH split of a node. Large nodes are binned on ctx.threads threads: bins merge by
// min/max and sums, so the result is the single-threaded one exactly.
Split findSplit(const BuildContext& ctx, const WorkItem& item, Bins& bins, F4& scale) {
  Split best;
  bool anyAxis = false;
  scale = binScale(item.cbox, ctx.bins, anyAxis);
  if (!anyAxis) return best;
  const F4 lastBin = splat(float(ctx.bins - 1));
  if (item.count <= kSmallNode) {
    smallSplit(ctx.prims, item, scale, lastBin, best);
    return best;
  }
  if (ctx.threads > 1 && item.count >= kParallelBinMin) {
    const unsigned threads = ctx.threads;
    std::vector<Bins> partial(threads - 1);  // thread 0 bins into `bins`
    runOnThreads(threads, [&](unsigned t) {
      const std::uint32_t lo = item.first + std::uint32_t(std::uint64_t(item.count) * t / threads);
      const std::uint32_t hi = item.first + std::uint32_t(std::uint64_t(item.count) * (t + 1) / threads);
      binPrims(ctx.prims, lo, hi - lo, item.cbox.lo, scale, ctx.bins, t == 0 ? bins : partial[t - 1]);
    });
    for (const Bins& p : partial)
      for (int a = 0; a < 3; ++a)
        for (int i = 0; i < ctx.bins; ++i) {
          bins[a][i].box.grow(p[a][i].box);
          bins[a][i].count += p[a][i].count;
        }
  } else {
    binPrims(ctx.prims, item.first, item.count, item.cbox.lo, scale, ctx.bins, bins);
  }
  sweepBins(bins, scale, ctx.bins, best);
  return best;
}

// Whether a node becomes a leaf: one prim, the depth budget spent, or few enough prims that SAH
// prefers testing them all to splitting. Larger nodes are inner nodes (their split is found later).
bool becomesLeaf(const BuildContext& ctx, const WorkItem& item, Bins& bins) {
  if (item.count == 1 || item.depth >= kMaxLeafDepth) {
    if (item.count > ctx.maxLeaf) throw Error("bvh.cpp: BVH depth bound violated (internal error)");
    return true;
  }
  if (item.count > ctx.maxLeaf) return false;
  F4 scale;
  const Split best = findSplit(ctx, item, bins, scale);
  const double nodeArea = item.box.halfArea();
  return !(best.found() && ctx.ct * nodeArea + ctx.ci * best.cost < ctx.ci * double(item.count) * nodeArea);
}

inline double relativeArea(const BuildContext& ctx, const Box& box) {
  return ctx.rootAreaOk ? box.halfArea() / ctx.rootArea : 1.0;
}

// A subtree left for the threaded phase: its root (an inner node) and where the single-threaded
// build would have numbered its descendants: after `marker` nodes of the top of the tree.
struct Deferred {
  WorkItem item;
  std::uint32_t marker;
};

// Builds the subtree of the inner node `root` (whose slot out[root.node] exists) depth-first, writing
// 64-byte nodes straight into `out`: a node's inner children get the next free slots when it is split
// (left, then right), so the numbering is the depth-first one of packing a finished tree. With
// `deferred`, inner nodes of fewer than deferBelow prims are not built but appended to it.
void buildSubtree(const BuildContext& ctx, const WorkItem& root, std::vector<gpu::BvhNode>& out, BuildStats& st,
                  std::vector<Deferred>* deferred, std::uint32_t deferBelow) {
  const std::uint32_t maxLeaf = ctx.maxLeaf;
  const F4 lastBin = splat(float(ctx.bins - 1));
  Prim* const prims = ctx.prims;
  std::vector<WorkItem> work{root};
  Bins bins;  // kept empty between nodes
  while (!work.empty()) {
    const WorkItem item = work.back();
    work.pop_back();
    if (deferred && item.count < deferBelow) {  // left for the parallel phase
      deferred->push_back({item, std::uint32_t(out.size())});
      continue;
    }
    F4 scale;
    const Split best = findSplit(ctx, item, bins, scale);

    // Split at the SAH plane unless the depth budget requires a median split (which keeps
    // depth + medianLevels(count) constant, so leaves never pass kMaxLeafDepth).
    const bool forceMedian = item.depth + medianLevels(item.count, maxLeaf) >= kMaxLeafDepth;
    WorkItem kid[2] = {{0, item.first, 0, item.depth + 1, Box{}, Box{}}, {0, 0, 0, item.depth + 1, Box{}, Box{}}};
    WorkItem& left = kid[0];
    WorkItem& right = kid[1];
    if (best.found() && !forceMedian) {
      // In-place partition; child bounds come from the prims themselves, so they are exact.
      // (The bounds are accumulated in locals, which stay in registers.)
      Box lbox, lcbox, rbox, rcbox;
      const int axis = best.axis, pos = best.pos;
      const F4 cmin = item.cbox.lo;
      std::uint32_t i = item.first, j = item.first + item.count;
      while (i < j) {
        const F4 c = centroidOf(prims[i]);
        if (binsOf(c, cmin, scale, lastBin)[axis] < pos) {
          lbox.grow(prims[i].box);
          lcbox.grow(c);
          ++i;
        } else {
          --j;
          std::swap(prims[i], prims[j]);
          rbox.grow(prims[j].box);
          rcbox.grow(c);
        }
      }
      left.count = i - item.first;
      left.box = lbox;
      left.cbox = lcbox;
      right.box = rbox;
      right.cbox = rcbox;
    }
    if (left.count == 0 || left.count == item.count) {
      // Median split along the widest centroid axis (any order when all centroids coincide).
      int a = 0;
      for (int k = 1; k < 3; ++k)
        if (item.cbox.hi[k] - item.cbox.lo[k] > item.cbox.hi[a] - item.cbox.lo[a]) a = k;
      left.count = item.count / 2;
      Prim* begin = prims + item.first;
      std::nth_element(begin, begin + left.count, begin + item.count,
                       [a](const Prim& p, const Prim& q) { return centroidOf(p)[a] < centroidOf(q)[a]; });
      boundsOfRange(prims, item.first, left.count, left.box, left.cbox);
      boundsOfRange(prims, item.first + left.count, item.count - left.count, right.box, right.cbox);
    }
    right.first = item.first + left.count;
    right.count = item.count - left.count;
    st.sah += ctx.ct * relativeArea(ctx, item.box);

    // Children: leaves go into the ref; inner children get the next slots, left first.
    std::uint32_t ref[2];
    bool inner[2];
    for (int k = 0; k < 2; ++k) {
      inner[k] = !becomesLeaf(ctx, kid[k], bins);
      if (inner[k]) {
        kid[k].node = std::uint32_t(out.size());
        out.emplace_back();
        ref[k] = kid[k].node;
      } else {
        ref[k] = leafRef(kid[k].first, kid[k].count);
        st.leafCount++;
        st.depth = std::max(st.depth, kid[k].depth);
        st.sah += ctx.ci * double(kid[k].count) * relativeArea(ctx, kid[k].box);
      }
    }
    gpu::BvhNode& n = out[item.node];
    n.lmin = glm::vec3(left.box.lo[0], left.box.lo[1], left.box.lo[2]);
    n.lmax = glm::vec3(left.box.hi[0], left.box.hi[1], left.box.hi[2]);
    n.rmin = glm::vec3(right.box.lo[0], right.box.lo[1], right.box.lo[2]);
    n.rmax = glm::vec3(right.box.hi[0], right.box.hi[1], right.box.hi[2]);
    n.left = ref[0];
    n.right = ref[1];
    n.reserved0 = n.reserved1 = 0;
    if (inner[1]) work.push_back(right);
    if (inner[0]) work.push_back(left);
  }
}

}  // namespace

namespace {
Bvh buildBvhOnce(const Triangle* triangles, std::size_t count, const BvhBuildOptions& options);
}  // namespace

Bvh buildBvh(const Triangle* triangles, std::size_t count, const BvhBuildOptions& options) {
  Bvh bvh = buildBvhOnce(triangles, count, options);
  // Small meshes: a second build with other bins, kept when its SAH cost is lower (binned SAH splits
  // greedily top-down, so more bins can make a worse tree: docs/architecture.md, "BVH build").
  if (options.secondBins > 0 && options.secondBins != options.bins && count < options.secondBinsBelow) {
    BvhBuildOptions o = options;
    o.bins = options.secondBins;
    o.secondBins = 0;
    try {
      Bvh other = buildBvhOnce(triangles, count, o);
      if (other.sahCost < bvh.sahCost) bvh = std::move(other);
    } catch (const Error&) {
      // Too deep for the traversal stack with these bins: the first tree stands.
    }
  }
  return bvh;
}

namespace {
Bvh buildBvhOnce(const Triangle* triangles, std::size_t count, const BvhBuildOptions& options) {
  if (options.secondBins < 0 || options.secondBins > kMaxBins)
    throw Error("bvh.cpp: BvhBuildOptions::secondBins must be in [0, " + std::to_string(kMaxBins) + "]");
  if (options.bins < 2 || options.bins > kMaxBins)
    throw Error("bvh.cpp: BvhBuildOptions::bins must be in [2, " + std::to_string(kMaxBins) + "]");
  if (options.maxLeafSize < 1 || options.maxLeafSize > int(gpu::kBvhMaxLeafSize))
    throw Error("bvh.cpp: BvhBuildOptions::maxLeafSize must be in [1, " + std::to_string(gpu::kBvhMaxLeafSize) + "]");
  if (options.threads < 0) throw Error("bvh.cpp: BvhBuildOptions::threads must be >= 0");
  if (count > std::size_t(gpu::kBvhFirstMask))
    throw Error("bvh.cpp: too many triangles (" + std::to_string(count) + ")");

  Bvh bvh;
  const std::uint32_t n = std::uint32_t(count);
  gpu::BvhNode emptyRoot{};  // a root of two empty slots (inverted boxes)
  emptyRoot.lmin = emptyRoot.rmin = glm::vec3(kInf);
  emptyRoot.lmax = emptyRoot.rmax = glm::vec3(-kInf);
  emptyRoot.left = emptyRoot.right = gpu::kBvhEmptyRef;
  if (n == 0) {
    bvh.nodes.push_back(emptyRoot);
    bvh.depth = 1;
    bvh.leafCount = 1;
    return bvh;
  }

  unsigned threads = options.threads > 0 ? unsigned(options.threads) : std::max(1u, std::thread::hardware_concurrency());
  if (n < 65536) threads = 1;  // small meshes: starting threads costs more than it saves

  // Prims (uninitialised storage, filled in parallel) and the root's bounds, merged from per-thread parts.
  struct FreeDeleter {
    void operator()(Prim* p) const { std::free(p); }
  };
  std::unique_ptr<Prim, FreeDeleter> primStore(static_cast<Prim*>(std::aligned_alloc(alignof(Prim), sizeof(Prim) * std::size_t(n))));
  if (!primStore) throw std::bad_alloc();
  Prim* const prims = primStore.get();
  std::vector<Box> partBox(threads), partCbox(threads);
  runOnThreads(threads, [&](unsigned t) {
    const std::uint32_t lo = std::uint32_t(std::uint64_t(n) * t / threads), hi = std::uint32_t(std::uint64_t(n) * (t + 1) / threads);
    Box box, cbox;
    for (std::uint32_t i = lo; i < hi; ++i) {
      Prim* p = new (prims + i) Prim(triangleBox(triangles[i]), i);
      box.grow(p->box);
      cbox.grow(centroidOf(*p));
    }
    partBox[t] = box;
    partCbox[t] = cbox;
  });
  WorkItem root{0, 0, n, 1, Box{}, Box{}};
  for (unsigned t = 0; t < threads; ++t) {
    root.box.grow(partBox[t]);
    root.cbox.grow(partCbox[t]);
  }
  root.box.lo[3] = root.box.hi[3] = root.cbox.lo[3] = root.cbox.hi[3] = 0.0f;  // lanes 3 carried the indices

  BuildContext ctx;
  ctx.prims = prims;
  ctx.bins = options.bins;
  ctx.maxLeaf = std::uint32_t(options.maxLeafSize);
  ctx.ct = options.costTraversal;
  ctx.ci = options.costIntersect;
  ctx.rootArea = root.box.halfArea();
  ctx.rootAreaOk = ctx.rootArea > 0.0 && std::isfinite(ctx.rootArea);
  ctx.threads = threads;

  Bins rootBins;
  double sah = 0.0;
  if (becomesLeaf(ctx, root, rootBins)) {  // one leaf: a root holding it and an empty slot
    gpu::BvhNode r = emptyRoot;
    r.lmin = glm::vec3(root.box.lo[0], root.box.lo[1], root.box.lo[2]);
    r.lmax = glm::vec3(root.box.hi[0], root.box.hi[1], root.box.hi[2]);
    r.left = leafRef(0, n);
    bvh.nodes.push_back(r);
    bvh.depth = 1;
    bvh.leafCount = 1;
    sah = ctx.ci * double(n);
  } else if (threads == 1) {
    // One thread: the nodes go straight into place. n slots bound the inner nodes; reserving them
    // only reserves address space (pages are touched as nodes are written).
    bvh.nodes.reserve(n);
    bvh.nodes.emplace_back();
    BuildStats st;
    buildSubtree(ctx, root, bvh.nodes, st, nullptr, 0);
    sah = st.sah;
    bvh.depth = st.depth;
    bvh.leafCount = st.leafCount;
  } else {
    // The top of the tree on this thread (large nodes binned on all threads), down to subtrees of
    // fewer than n / (8 * threads) prims; those are built by all threads, largest first, each into its
    // own array, then spliced in where the single-threaded build numbers them. The result is the
    // single-threaded tree bit for bit.
    std::vector<gpu::BvhNode> top{gpu::BvhNode{}};
    std::vector<Deferred> deferred;
    BuildStats topStats;
    buildSubtree(ctx, root, top, topStats, &deferred, std::max<std::uint32_t>(2, n / (8 * threads)));
    const std::size_t d = deferred.size();
    std::vector<std::uint32_t> schedule(d);
    for (std::size_t k = 0; k < d; ++k) schedule[k] = std::uint32_t(k);
    std::sort(schedule.begin(), schedule.end(), [&](std::uint32_t x, std::uint32_t y) {
      return deferred[x].item.count != deferred[y].item.count ? deferred[x].item.count > deferred[y].item.count : x < y;
    });
    std::vector<std::vector<gpu::BvhNode>> sub(d);
    std::vector<BuildStats> stats(d);
    std::atomic<std::size_t> next{0};
    BuildContext subCtx = ctx;
    subCtx.threads = 1;
    runOnThreads(threads, [&](unsigned) {
      for (std::size_t s = next.fetch_add(1); s < d; s = next.fetch_add(1)) {
        const std::uint32_t k = schedule[s];
        WorkItem item = deferred[k].item;
        item.node = 0;
        sub[k].reserve(item.count);  // address space only, as above
        sub[k].emplace_back();
        buildSubtree(subCtx, item, sub[k], stats[k], nullptr, 0);
      }
    });

    // Splice: top node t goes to t + (nodes of the blocks spliced in before it); block k (subtree k
    // without its root, whose slot is in `top`) starts after marker_k top nodes and the earlier blocks.
    std::vector<std::uint32_t> globalOf(top.size() + 1), base(d);
    std::vector<std::int32_t> owner(top.size(), -1);
    {
      std::size_t k = 0;
      std::uint32_t shift = 0;
      for (std::uint32_t t = 0; t <= top.size(); ++t) {
        for (; k < d && deferred[k].marker == t; ++k) {
          base[k] = t + shift;
          shift += std::uint32_t(sub[k].size() - 1);
        }
        globalOf[t] = t + shift;
      }
    }
    for (std::size_t k = 0; k < d; ++k) owner[deferred[k].item.node] = std::int32_t(k);
    auto fixTop = [&](std::uint32_t ref) { return (ref & gpu::kBvhLeafBit) ? ref : globalOf[ref]; };
    auto fixSub = [&](std::uint32_t ref, std::size_t k) { return (ref & gpu::kBvhLeafBit) ? ref : base[k] + ref - 1; };
    // The top nodes (and the subtrees' roots, in their slots) first, then the blocks on all threads,
    // each thread copying and freeing whole subtrees.
    bvh.nodes.resize(globalOf[top.size()]);
    for (std::uint32_t t = 0; t < top.size(); ++t) {
      gpu::BvhNode node;
      if (owner[t] >= 0) {
        const std::size_t o = std::size_t(owner[t]);
        node = sub[o][0];
        node.left = fixSub(node.left, o);
        node.right = fixSub(node.right, o);
      } else {
        node = top[t];
        node.left = fixTop(node.left);
        node.right = fixTop(node.right);
      }
      bvh.nodes[globalOf[t]] = node;
    }
    next = 0;
    runOnThreads(threads, [&](unsigned) {
      for (std::size_t s = next.fetch_add(1); s < d; s = next.fetch_add(1)) {
        const std::uint32_t k = schedule[s];
        gpu::BvhNode* dst = bvh.nodes.data() + base[k];
        for (std::size_t j = 1; j < sub[k].size(); ++j) {
          gpu::BvhNode node = sub[k][j];
          node.left = fixSub(node.left, k);
          node.right = fixSub(node.right, k);
          dst[j - 1] = node;
        }
        std::vector<gpu::BvhNode>().swap(sub[k]);
      }
    });
    sah = topStats.sah;
    bvh.depth = topStats.depth;
    bvh.leafCount = topStats.leafCount;
    for (const BuildStats& st : stats) {  // in a fixed order, so the sum does not depend on scheduling
      sah += st.sah;
      bvh.depth = std::max(bvh.depth, st.depth);
      bvh.leafCount += st.leafCount;
    }
  }

  if (bvh.depth >= CAUSTICA_BVH_STACK)
    throw Error("bvh.cpp: BVH depth " + std::to_string(bvh.depth) + " exceeds the traversal stack");
  bvh.sahCost = float(sah);
  bvh.order.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) bvh.order[i] = prims[i].index();
  return bvh;
}
}  // namespace

Bvh buildBvh(const std::vector<Triangle>& triangles, const BvhBuildOptions& options) {
  return buildBvh(triangles.data(), triangles.size(), options);
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

double bvhSahCost(const std::vector<gpu::BvhNode>& nodes, float costTraversal, float costIntersect) {
  if (nodes.empty()) return 0.0;
  auto halfArea = [](const glm::vec3& lo, const glm::vec3& hi) {
    const double dx = double(hi.x) - lo.x, dy = double(hi.y) - lo.y, dz = double(hi.z) - lo.z;
    return dx * dy + dy * dz + dz * dx;
  };
  glm::vec3 lo, hi;
  if (!bvhBounds(nodes, lo, hi)) return 0.0;
  const double rootArea = halfArea(lo, hi);
  const bool rootOk = rootArea > 0.0 && std::isfinite(rootArea);
  auto rel = [&](const glm::vec3& a, const glm::vec3& b) { return rootOk ? halfArea(a, b) / rootArea : 1.0; };
  const gpu::BvhNode& r = nodes[0];
  if (r.right == gpu::kBvhEmptyRef)  // one leaf (or none): no inner node to pay for
    return (r.left & gpu::kBvhLeafBit) ? costIntersect * double((r.left >> gpu::kBvhCountShift) & 15u) : 0.0;
  double cost = costTraversal * 1.0;  // the root
  std::vector<std::uint32_t> stack{0};
  while (!stack.empty()) {
    const gpu::BvhNode& node = nodes.at(stack.back());
    stack.pop_back();
    const std::uint32_t refs[2] = {node.left, node.right};
    const glm::vec3 los[2] = {node.lmin, node.rmin}, his[2] = {node.lmax, node.rmax};
    for (int k = 0; k < 2; ++k) {
      if (refs[k] & gpu::kBvhLeafBit) {
        cost += costIntersect * double((refs[k] >> gpu::kBvhCountShift) & 15u) * rel(los[k], his[k]);
      } else {
        cost += costTraversal * rel(los[k], his[k]);
        stack.push_back(refs[k]);
      }
    }
  }
  return cost;
}

bool isZeroAreaTriangle(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2) {
  const glm::vec3 n = glm::cross(p1 - p0, p2 - p0);
  return n.x == 0.0f && n.y == 0.0f && n.z == 0.0f;
}

void packedTrianglePositions(const glm::vec3* p, glm::vec3& q0, glm::vec3& q1, glm::vec3& q2) {
  const bool point = isZeroAreaTriangle(p[0], p[1], p[2]);
  q0 = p[0];
  q1 = point ? p[0] : p[1];
  q2 = point ? p[0] : p[2];
}

void appendTriGeom(const Triangle* triangles, std::size_t count, const Bvh& bvh, std::vector<gpu::TriGeom>& out) {
  if (bvh.order.size() != count)
    throw Error("bvh.cpp: BVH was built for " + std::to_string(bvh.order.size()) + " triangles, got " +
                std::to_string(count));
  const std::size_t base = out.size();
  out.resize(base + count);
  for (std::size_t i = 0; i < count; ++i) {
    const Triangle& t = triangles[bvh.order[i]];
    glm::vec3 q0, q1, q2;
    packedTrianglePositions(t.p, q0, q1, q2);
    out[base + i].v0 = glm::vec4(q0, glm::uintBitsToFloat(t.material));
    out[base + i].v1 = glm::vec4(q1, 0.0f);
    out[base + i].v2 = glm::vec4(q2, 0.0f);
  }
}

std::vector<gpu::TriGeom> packTriGeom(const std::vector<Triangle>& triangles, const Bvh& bvh) {
  std::vector<gpu::TriGeom> out;
  appendTriGeom(triangles.data(), triangles.size(), bvh, out);
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
  // Zero-area triangles can pass the test above once their vertices are rounded in ray space (in a
  // scratch search the t error bound below then rejected every one, docs/architecture.md "Traversal",
  // but that is not proven). The GLSL twin has no such check: packedTrianglePositions stores them as
  // one point, which det == 0 rejects; this check keeps the reference right for any vertices.
  if (isZeroAreaTriangle(p0, p1, p2)) return false;

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

bool intersectLeaf(const std::vector<gpu::TriGeom>& tris, std::uint32_t ref, const glm::vec3& origin,
                   const RayShear& rs, bool anyHit, float& closest, Hit& hit) {
  const std::uint32_t first = ref & gpu::kBvhFirstMask;
  const std::uint32_t count = (ref >> gpu::kBvhCountShift) & 15u;
  bool found = false;
  for (std::uint32_t i = first; i < first + count; ++i) {
    const gpu::TriGeom& g = tris[i];
    float t, u, v;
    if (intersectTriangleSheared(origin, rs, glm::vec3(g.v0), glm::vec3(g.v1), glm::vec3(g.v2), closest, t, u, v)) {
      closest = t;
      hit.t = t;
      hit.u = u;
      hit.v = v;
      hit.tri = i;
      found = true;
      if (anyHit) break;
    }
  }
  return found;
}

bool intersectTriangle(const Ray& ray, const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2,
                       float tmax, float& t, float& u, float& v) {
  return intersectTriangleSheared(ray.origin, makeRayShear(ray.dir), p0, p1, p2, tmax, t, u, v);
}

namespace {

using raybox::bvhVisitNode;
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
      std::uint32_t near, far;
      float farT;
      const int hits = bvhVisitNode(node, ray.origin, invDir, closest, near, far, farT);
      // The builder bounds the depth, so the stack never overflows; the guard only protects memory.
      if (hits == 2 && sp < CAUSTICA_BVH_STACK) {
        stackRef[sp] = far;
        stackT[sp] = farT;
        ++sp;
      }
      if (hits > 0) {
        ref = near;
        continue;
      }
    } else {
      if (intersectLeaf(tris, ref, ray.origin, rs, kAnyHit, closest, hit) && kAnyHit) return hit;
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
