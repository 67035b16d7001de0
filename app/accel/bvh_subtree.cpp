// bvh_subtree.cpp — one subtree of the binned-SAH BVH built depth-first: each node split at its SAH
// plane (or at the median where the depth budget requires), its prims partitioned in place, and the
// node written as a 64-byte gpu::BvhNode with both children's boxes (world space).
#include "accel/bvh_subtree.h"

#include <algorithm>

#include "accel/bvh_split.h"

namespace caustica::bvhbuild {

namespace {

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


inline double relativeArea(const BuildContext& ctx, const Box& box) {
  return ctx.rootAreaOk ? box.halfArea() / ctx.rootArea : 1.0;
}


// In-place partition of `item`'s prims at the SAH plane `best`: left gets the prims of bins below
// best.pos on best.axis, right the others. Child bounds come from the prims themselves, so they are
// exact (accumulated in locals, which stay in registers).
void partitionAtSplit(Prim* prims, const WorkItem& item, const Split& best, F4 scale, F4 lastBin, WorkItem& left,
                      WorkItem& right) {
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

// Median split of `item`'s prims along the widest centroid axis (any order when all centroids coincide).
void partitionAtMedian(Prim* prims, const WorkItem& item, WorkItem& left, WorkItem& right) {
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

// Builds the subtree of the inner node `root` (whose slot out[root.node] exists) depth-first, writing
// 64-byte nodes straight into `out`: a node's inner children get the next free slots when it is split

}  // namespace

void buildSubtree(const BuildContext& ctx, const WorkItem& root, std::vector<gpu::BvhNode>& out, BuildStats& st,
                  std::vector<Deferred>* deferred, std::uint32_t deferBelow) {
  const F4 lastBin = splat(float(ctx.bins - 1));
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
    const bool forceMedian = item.depth + medianLevels(item.count, ctx.maxLeaf) >= kMaxLeafDepth;
    WorkItem kid[2] = {{0, item.first, 0, item.depth + 1, Box{}, Box{}}, {0, 0, 0, item.depth + 1, Box{}, Box{}}};
    WorkItem& left = kid[0];
    WorkItem& right = kid[1];
    if (best.found() && !forceMedian) partitionAtSplit(ctx.prims, item, best, scale, lastBin, left, right);
    if (left.count == 0 || left.count == item.count) partitionAtMedian(ctx.prims, item, left, right);
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
    n.lmin = xyz(left.box.lo);
    n.lmax = xyz(left.box.hi);
    n.rmin = xyz(right.box.lo);
    n.rmax = xyz(right.box.hi);
    n.left = ref[0];
    n.right = ref[1];
    n.reserved0 = n.reserved1 = 0;
    if (inner[1]) work.push_back(right);
    if (inner[0]) work.push_back(left);
  }
}

}  // namespace caustica::bvhbuild
