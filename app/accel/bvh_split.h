// bvh_split.h — the binned-SAH split search of the BVH builder (internal, bvh_build.cpp): where a node
// splits (findSplit: axis and bin plane of least SAH cost) and whether it becomes a leaf (becomesLeaf).
#pragma once
#include <cstdint>
#include <cstdlib>
#include <limits>

#include "accel/bvh_build_types.h"

namespace caustica::bvhbuild {

struct Bin {
  Box box;
  int count = 0;
};
typedef Bin Bins[3][kMaxBins];

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

// Best binned-SAH split of a node; `scale` gets the per-axis bin scales that binsOf() partitions with.
// `bins` is scratch, empty on entry and on return. Large nodes are binned on ctx.threads threads: bins
// merge by min/max and sums, so the result is the single-threaded one exactly.
Split findSplit(const BuildContext& ctx, const WorkItem& item, Bins& bins, F4& scale);

// Whether a node becomes a leaf: one prim, the depth budget spent, or few enough prims that SAH
// prefers testing them all to splitting. Larger nodes are inner nodes (their split is found later).
bool becomesLeaf(const BuildContext& ctx, const WorkItem& item, Bins& bins);

}  // namespace caustica::bvhbuild
