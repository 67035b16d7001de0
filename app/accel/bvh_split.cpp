// bvh_split.cpp — the binned-SAH split search: bin a node's centroids on all three axes (on all
// threads for large nodes), sweep the planes between non-empty bins, and the same for small nodes
// without bin arrays. Costs in units of surface area * prim count (world space).
#include "accel/bvh_split.h"

#include <vector>

#include "util/error.h"

namespace caustica::bvhbuild {

namespace {

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

}  // namespace

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

bool becomesLeaf(const BuildContext& ctx, const WorkItem& item, Bins& bins) {
  if (item.count == 1 || item.depth >= kMaxLeafDepth) {
    if (item.count > ctx.maxLeaf) throw Error("bvh_split.cpp: BVH depth bound violated (internal error)");
    return true;
  }
  if (item.count > ctx.maxLeaf) return false;
  F4 scale;
  const Split best = findSplit(ctx, item, bins, scale);
  const double nodeArea = item.box.halfArea();
  return !(best.found() && ctx.ct * nodeArea + ctx.ci * best.cost < ctx.ci * double(item.count) * nodeArea);
}

}  // namespace caustica::bvhbuild
