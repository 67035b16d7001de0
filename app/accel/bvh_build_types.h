// bvh_build_types.h — the binned-SAH builder's own types (not part of the public API, bvh.h): boxes in
// 4-wide float vectors, build-time primitives, nodes still to be built, the build's settings, and the
// thread runner. Shared by the split search (bvh_split.cpp) and the build (bvh_build.cpp); world space.
#pragma once
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <mutex>
#include <thread>
#include <vector>
#if defined(__SSE__)
#include <xmmintrin.h>
#endif

#include "shared/gpu_layout.h"

namespace caustica::bvhbuild {

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

}  // namespace caustica::bvhbuild
