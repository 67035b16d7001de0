// bvh_build.cpp — buildBvh: options checked, build-time prims from triangles, the tree built on one thread
// (bvh_subtree.cpp) or on several (the top on one thread, subtrees on all, spliced into the
// single-threaded numbering: the same tree bit for bit), and the second build with other bins.
#include "accel/bvh.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <new>
#include <string>
#include <thread>

#include "accel/bvh_build_types.h"
#include "accel/bvh_split.h"
#include "accel/bvh_subtree.h"
#include "util/error.h"

namespace caustica {

namespace {

using namespace bvhbuild;

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

// Builds the deferred subtrees on all threads, largest first, each into its own array (sub[k]: the
// subtree's root in slot 0, its descendants numbered from 1); stats[k] its statistics.
void buildDeferred(const BuildContext& ctx, unsigned threads, const std::vector<Deferred>& deferred,
                   const std::vector<std::uint32_t>& schedule, std::vector<std::vector<gpu::BvhNode>>& sub,
                   std::vector<BuildStats>& stats) {
  std::atomic<std::size_t> next{0};
  BuildContext subCtx = ctx;
  subCtx.threads = 1;
  runOnThreads(threads, [&](unsigned) {
    for (std::size_t s = next.fetch_add(1); s < deferred.size(); s = next.fetch_add(1)) {
      const std::uint32_t k = schedule[s];
      WorkItem item = deferred[k].item;
      item.node = 0;
      sub[k].reserve(item.count);  // address space only: pages are touched as nodes are written
      sub[k].emplace_back();
      buildSubtree(subCtx, item, sub[k], stats[k], nullptr, 0);
    }
  });
}

// Splices the top of the tree and the deferred subtrees into `nodes` in the single-threaded numbering:
// top node t goes to t + (nodes of the blocks spliced in before it); block k (subtree k without its root,
// whose slot is in `top`) starts after marker_k top nodes and the earlier blocks. Frees `sub` as it goes.
void spliceSubtrees(unsigned threads, const std::vector<gpu::BvhNode>& top, const std::vector<Deferred>& deferred,
                    const std::vector<std::uint32_t>& schedule, std::vector<std::vector<gpu::BvhNode>>& sub,
                    std::vector<gpu::BvhNode>& nodes) {
  const std::size_t d = deferred.size();
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
  nodes.resize(globalOf[top.size()]);
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
    nodes[globalOf[t]] = node;
  }
  std::atomic<std::size_t> next{0};
  runOnThreads(threads, [&](unsigned) {
    for (std::size_t s = next.fetch_add(1); s < d; s = next.fetch_add(1)) {
      const std::uint32_t k = schedule[s];
      gpu::BvhNode* dst = nodes.data() + base[k];
      for (std::size_t j = 1; j < sub[k].size(); ++j) {
        gpu::BvhNode node = sub[k][j];
        node.left = fixSub(node.left, k);
        node.right = fixSub(node.right, k);
        dst[j - 1] = node;
      }
      std::vector<gpu::BvhNode>().swap(sub[k]);
    }
  });
}

// The threaded build of an inner root over n prims: the top of the tree on this thread (large nodes
// binned on all threads), down to subtrees of fewer than n / (8 * threads) prims; those are built by
// all threads, largest first, then spliced in where the single-threaded build numbers them. The result
// is the single-threaded tree bit for bit. Returns the SAH cost; fills bvh.nodes, depth and leafCount.
double buildThreaded(const BuildContext& ctx, const WorkItem& root, std::uint32_t n, unsigned threads, Bvh& bvh) {
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
  buildDeferred(ctx, threads, deferred, schedule, sub, stats);
  spliceSubtrees(threads, top, deferred, schedule, sub, bvh.nodes);

  double sah = topStats.sah;
  bvh.depth = topStats.depth;
  bvh.leafCount = topStats.leafCount;
  for (const BuildStats& st : stats) {  // in a fixed order, so the sum does not depend on scheduling
    sah += st.sah;
    bvh.depth = std::max(bvh.depth, st.depth);
    bvh.leafCount += st.leafCount;
  }
  return sah;
}

void checkOptions(const BvhBuildOptions& options, std::size_t count) {
  if (options.secondBins < 0 || options.secondBins > kMaxBins)
    throw Error("bvh_build.cpp: BvhBuildOptions::secondBins must be in [0, " + std::to_string(kMaxBins) + "]");
  if (options.bins < 2 || options.bins > kMaxBins)
    throw Error("bvh_build.cpp: BvhBuildOptions::bins must be in [2, " + std::to_string(kMaxBins) + "]");
  if (options.maxLeafSize < 1 || options.maxLeafSize > int(gpu::kBvhMaxLeafSize))
    throw Error("bvh_build.cpp: BvhBuildOptions::maxLeafSize must be in [1, " + std::to_string(gpu::kBvhMaxLeafSize) +
                "]");
  if (options.threads < 0) throw Error("bvh_build.cpp: BvhBuildOptions::threads must be >= 0");
  if (count > std::size_t(gpu::kBvhFirstMask))
    throw Error("bvh_build.cpp: too many triangles (" + std::to_string(count) + ")");
}

struct FreeDeleter {
  void operator()(Prim* p) const { std::free(p); }
};
using PrimStore = std::unique_ptr<Prim, FreeDeleter>;

// Prims of n triangles (uninitialised storage, filled on `threads` threads) and the root's work item,
// its bounds merged from per-thread parts.
PrimStore makePrims(const Triangle* triangles, std::uint32_t n, unsigned threads, WorkItem& root) {
  PrimStore primStore(static_cast<Prim*>(std::aligned_alloc(alignof(Prim), sizeof(Prim) * std::size_t(n))));
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
  root = WorkItem{0, 0, n, 1, Box{}, Box{}};
  for (unsigned t = 0; t < threads; ++t) {
    root.box.grow(partBox[t]);
    root.cbox.grow(partCbox[t]);
  }
  root.box.lo[3] = root.box.hi[3] = root.cbox.lo[3] = root.cbox.hi[3] = 0.0f;  // lanes 3 carried the indices
  return primStore;
}

Bvh buildBvhOnce(const Triangle* triangles, std::size_t count, const BvhBuildOptions& options) {
  checkOptions(options, count);
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
  WorkItem root;
  const PrimStore primStore = makePrims(triangles, n, threads, root);

  BuildContext ctx;
  ctx.prims = primStore.get();
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
    r.lmin = xyz(root.box.lo);
    r.lmax = xyz(root.box.hi);
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
    sah = buildThreaded(ctx, root, n, threads, bvh);
  }

  if (bvh.depth >= CAUSTICA_BVH_STACK)
    throw Error("bvh_build.cpp: BVH depth " + std::to_string(bvh.depth) + " exceeds the traversal stack");
  bvh.sahCost = float(sah);
  bvh.order.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) bvh.order[i] = ctx.prims[i].index();
  return bvh;
}

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

Bvh buildBvh(const std::vector<Triangle>& triangles, const BvhBuildOptions& options) {
  return buildBvh(triangles.data(), triangles.size(), options);
}

}  // namespace caustica
