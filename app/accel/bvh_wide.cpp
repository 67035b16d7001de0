// bvh_wide.cpp — collapse of the binary SAH tree into 4-wide nodes, and the C++ twin of the GLSL
// 4-wide traversal (glsl/lib/traverse.glsl); keep the two in step.
#include "accel/bvh_wide.h"

#include <algorithm>
#include <string>

#include "accel/ray_box.h"
#include "util/error.h"

namespace caustica {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
// Entry distance of a child the ray misses: above every hit's (tnear <= tmax * kBoxPad <= 3e38 * pad).
constexpr float kMissT = 3.4e38f;

// One child of a node under construction: its world-space box and ref (gpu_layout.h, BvhNode).
struct Slot {
  glm::vec3 lo, hi;
  std::uint32_t ref;
};

float surfaceArea(const Slot& c) {
  const glm::vec3 e = c.hi - c.lo;
  return e.x * e.y + e.y * e.z + e.z * e.x;
}

void setSlot(gpu::BvhWideNode& n, int k, const glm::vec3& lo, const glm::vec3& hi, std::uint32_t ref) {
  n.minX[k] = lo.x;
  n.maxX[k] = hi.x;
  n.minY[k] = lo.y;
  n.maxY[k] = hi.y;
  n.minZ[k] = lo.z;
  n.maxZ[k] = hi.z;
  n.child[k] = ref;
}

gpu::BvhWideNode emptyWideNode() {
  gpu::BvhWideNode n{};
  for (int k = 0; k < 4; ++k) setSlot(n, k, glm::vec3(kInf), glm::vec3(kInf), gpu::kBvhEmptyRef);
  return n;
}

bool isInner(std::uint32_t ref) { return (ref & gpu::kBvhLeafBit) == 0; }

}  // namespace

BvhWide packBvhWideNodes(const std::vector<gpu::BvhNode>& binary) {
  BvhWide out;
  out.nodes.push_back(emptyWideNode());
  out.depth = 1;
  if (binary.empty()) return out;
  struct Work {
    std::uint32_t binaryNode;  // binary node whose children this wide node collapses
    std::uint32_t wideIndex;   // where it goes in out.nodes
    int depth;                 // wide level, root = 1
    int stackBefore;           // stack entries the traversal may hold on arriving here
  };
  std::vector<Work> work{{0, 0, 1, 0}};
  // Every wide node starts from a distinct binary node, so binary.size() bounds the count: reserved
  // once (address space only; untouched pages cost no memory), the vector never reallocates.
  out.nodes.reserve(binary.size());
  while (!work.empty()) {
    const Work w = work.back();
    work.pop_back();
    // The binary node's non-empty children; then open the inner child of largest surface area until
    // there are four children or only leaves (left-to-right order kept).
    Slot kids[4];
    int count = 0;
    auto addChildren = [&](std::uint32_t node, int at) {
      if (node >= binary.size()) throw Error("bvh_wide.cpp: node ref out of range (internal error)");
      const gpu::BvhNode& b = binary[node];
      const Slot two[2] = {{b.lmin, b.lmax, b.left}, {b.rmin, b.rmax, b.right}};
      for (const Slot& c : two) {
        if (c.ref == gpu::kBvhEmptyRef) continue;
        for (int k = count; k > at; --k) kids[k] = kids[k - 1];
        kids[at++] = c;
        ++count;
      }
    };
    addChildren(w.binaryNode, 0);
    while (count < 4) {
      int best = -1;
      float bestArea = -1.0f;
      for (int k = 0; k < count; ++k)
        if (isInner(kids[k].ref) && surfaceArea(kids[k]) > bestArea) {
          bestArea = surfaceArea(kids[k]);
          best = k;
        }
      if (best < 0) break;
      const std::uint32_t opened = kids[best].ref;
      for (int k = best; k + 1 < count; ++k) kids[k] = kids[k + 1];  // remove it...
      --count;
      addChildren(opened, best);  // ...and put its two children in its place
    }
    // The traversal writes up to three stack slots from sp on at every inner node, then keeps count - 1.
    out.stackNeed = std::max(out.stackNeed, w.stackBefore + 3);
    out.depth = std::max(out.depth, w.depth);
    gpu::BvhWideNode n = emptyWideNode();
    int innerKids = 0;
    for (int k = 0; k < count; ++k) {
      std::uint32_t ref = kids[k].ref;
      if (isInner(ref)) {  // a binary inner node becomes a wide node, packed when its work item is popped
        work.push_back({ref, static_cast<std::uint32_t>(out.nodes.size()), w.depth + 1, w.stackBefore + count - 1});
        ref = static_cast<std::uint32_t>(out.nodes.size());
        out.nodes.push_back(emptyWideNode());
        ++innerKids;
      }
      setSlot(n, k, kids[k].lo, kids[k].hi, ref);
    }
    out.nodes[w.wideIndex] = n;
    // Depth-first: the first child's subtree next (its work item on top).
    std::reverse(work.end() - innerKids, work.end());
  }
  if (out.stackNeed > CAUSTICA_BVH_WIDE_STACK)
    throw Error("bvh_wide.cpp: the 4-wide traversal would need " + std::to_string(out.stackNeed) +
                " stack entries, more than CAUSTICA_BVH_WIDE_STACK");
  return out;
}

namespace {

// The four children's slab tests (intersectAabb per component, same operations as the GLSL's vec4
// form), then a sort by entry distance (misses last at kMissT). Returns how many children the ray enters.
int visitWide(const gpu::BvhWideNode& n, const glm::vec3& org, const glm::vec3& invDir, float tmax,
              std::uint32_t ref[4], float t[4]) {
  int hits = 0;
  for (int k = 0; k < 4; ++k) {
    const glm::vec3 lo(n.minX[k], n.minY[k], n.minZ[k]), hi(n.maxX[k], n.maxY[k], n.maxZ[k]);
    float tnear;
    const bool h = raybox::intersectAabb(org, invDir, lo, hi, tmax, tnear);
    t[k] = h ? tnear : kMissT;
    ref[k] = n.child[k];
    hits += h;
  }
  // Sorting network (0,1) (2,3) (0,2) (1,3) (1,2); a swap only when strictly nearer, as in the GLSL.
  auto cswap = [&](int a, int b) {
    if (t[b] < t[a]) {
      std::swap(t[a], t[b]);
      std::swap(ref[a], ref[b]);
    }
  };
  cswap(0, 1);
  cswap(2, 3);
  cswap(0, 2);
  cswap(1, 3);
  cswap(1, 2);
  return hits;
}

// Shared by closest and any hit, in the GLSL twin's order: the nearest entered child next, the others
// stacked nearest on top (refs only, as the twin: a popped subtree beyond the closest hit is entered and
// its node visit or leaf test finds nothing nearer, docs/benchmarks.md "Session 5"). The GLSL keeps the
// stack's top eight refs in registers and the rest in an array, one LIFO stack all the same.
template <bool kAnyHit>
Hit traverseWide(const std::vector<gpu::BvhWideNode>& nodes, const std::vector<gpu::TriGeom>& tris, const Ray& ray,
                 float tmax) {
  Hit hit;
  if (nodes.empty()) return hit;
  const glm::vec3 invDir = raybox::safeInverse(ray.dir);
  const RayShear rs = makeRayShear(ray.dir);
  float closest = tmax;
  std::uint32_t stackRef[CAUSTICA_BVH_WIDE_STACK];
  std::uint32_t sp = 0;
  std::uint32_t ref = 0;  // the root, an inner node
  auto pop = [&]() -> std::uint32_t { return sp > 0 ? stackRef[--sp] : gpu::kInvalidIndex; };
  for (;;) {
    if ((ref & gpu::kBvhLeafBit) == 0) {
      std::uint32_t r[4];
      float t[4];
      const int hits = visitWide(nodes[ref], ray.origin, invDir, closest, r, t);
      // packBvhWideNodes bounds the stack; the guard only protects memory.
      if (hits > 1 && sp + 3 <= CAUSTICA_BVH_WIDE_STACK) {
        for (int k = hits - 1; k >= 1; --k) {
          stackRef[sp] = r[k];
          ++sp;
        }
      }
      if (hits > 0) {
        ref = r[0];
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

Hit traceClosest(const std::vector<gpu::BvhWideNode>& nodes, const std::vector<gpu::TriGeom>& tris, const Ray& ray,
                 float tmax) {
  return traverseWide<false>(nodes, tris, ray, tmax);
}

bool traceOccluded(const std::vector<gpu::BvhWideNode>& nodes, const std::vector<gpu::TriGeom>& tris, const Ray& ray,
                   float tmax) {
  return traverseWide<true>(nodes, tris, ray, tmax).found();
}

}  // namespace caustica
