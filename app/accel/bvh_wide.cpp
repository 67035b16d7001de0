// bvh_wide.cpp — collapse of the binary SAH tree into 4-wide nodes, and the C++ twin of the GLSL
// 4-wide traversal (glsl/lib/traverse.glsl); keep the two in step.
#include "accel/bvh_wide.h"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <memory>
#include <sstream>
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

// The SAH-optimal collapse (WideCollapseOptions::Method::Sah): over the binary tree, bottom-up (a
// node's children have larger indices than the node), best[n][j] = the least SAH cost of binary inner
// node n's subtree when it fills at most j (1..4) slots of its wide parent: one slot as a wide node or
// (at most maxLeafSize triangles) as one merged leaf, or n opened and its two children sharing the j
// slots. Costs are surface areas (not divided by the root's) times costNode per wide node,
// costLeaf + count * costTriangle per leaf. The same idea as Ylitie, Karras, Laine (2017), section 3.
class SahCollapse {
 public:
  SahCollapse(const std::vector<gpu::BvhNode>& b, const WideCollapseOptions& o) : bin_(b), opt_(o) {
    const std::size_t n = b.size();
    area_.resize(n);
    first_.assign(n, 0);
    count_.assign(n, 0);
    best_.assign(n, {});
    split_.assign(n, {});
    merge_.assign(n, 0);
    wideSplit_.assign(n, 1);
    area_[0] = area(glm::min(b[0].lmin, b[0].rmin), glm::max(b[0].lmax, b[0].rmax));
    for (std::size_t i = 0; i < n; ++i) {  // each inner node's box's area, the box as stored in its parent
      if (isInner(b[i].left)) check(b[i].left, i), area_[b[i].left] = area(b[i].lmin, b[i].lmax);
      if (isInner(b[i].right)) check(b[i].right, i), area_[b[i].right] = area(b[i].rmin, b[i].rmax);
    }
    for (std::size_t i = n; i-- > 0;) solve(std::uint32_t(i));
  }

  // The slots of the wide node made from binary inner node n (its children sharing four slots).
  int slotsOf(std::uint32_t n, Slot out[4]) const {
    int count = 0;
    const gpu::BvhNode& b = bin_[n];
    emit({b.lmin, b.lmax, b.left}, wideSplit_[n], out, count);
    emit({b.rmin, b.rmax, b.right}, 4 - wideSplit_[n], out, count);
    return count;
  }

 private:
  static float area(const glm::vec3& lo, const glm::vec3& hi) {
    const glm::vec3 e = hi - lo;
    return e.x * e.y + e.y * e.z + e.z * e.x;
  }
  void check(std::uint32_t child, std::size_t parent) const {
    if (child >= bin_.size() || child <= parent) throw Error("bvh_wide.cpp: binary child ref out of order (internal error)");
  }
  static std::uint32_t leafCount(std::uint32_t ref) { return (ref >> gpu::kBvhCountShift) & 15u; }
  float leafCost(float a, std::uint32_t count) const { return a * (opt_.costLeaf + opt_.costTriangle * float(count)); }
  // Least cost of child ref c (box lo..hi) in at most j slots.
  float childCost(std::uint32_t c, const glm::vec3& lo, const glm::vec3& hi, int j) const {
    return isInner(c) ? best_[c][j] : leafCost(area(lo, hi), leafCount(c));
  }
  void solve(std::uint32_t n) {
    const gpu::BvhNode& b = bin_[n];
    // The subtree's triangles: contiguous in leaf order when the two ranges touch.
    std::uint32_t f[2], c[2];
    const std::uint32_t refs[2] = {b.left, b.right};
    for (int k = 0; k < 2; ++k) {
      if (isInner(refs[k])) f[k] = first_[refs[k]], c[k] = count_[refs[k]];
      else f[k] = refs[k] & gpu::kBvhFirstMask, c[k] = leafCount(refs[k]);
    }
    const bool contiguous = c[0] != 0 && c[1] != 0 && c[0] != ~0u && c[1] != ~0u && f[0] + c[0] == f[1];
    first_[n] = f[0];
    count_[n] = contiguous ? c[0] + c[1] : ~0u;  // ~0u: not one range (never for buildBvh's trees)
    float pair[5];  // pair[j]: both children sharing at most j slots; pairSplit[j]: the left child's share
    int pairSplit[5] = {1, 1, 1, 1, 1};
    for (int j = 2; j <= 4; ++j) {
      pair[j] = std::numeric_limits<float>::infinity();
      for (int k0 = 1; k0 < j; ++k0) {
        const float v = childCost(b.left, b.lmin, b.lmax, k0) + childCost(b.right, b.rmin, b.rmax, j - k0);
        if (v < pair[j]) pair[j] = v, pairSplit[j] = k0;
      }
    }
    wideSplit_[n] = pairSplit[4];
    const float asWide = area_[n] * opt_.costNode + pair[4];
    const bool canMerge = contiguous && count_[n] <= std::uint32_t(opt_.maxLeafSize);
    const float asLeaf = canMerge ? leafCost(area_[n], count_[n]) : std::numeric_limits<float>::infinity();
    merge_[n] = asLeaf < asWide;
    best_[n][1] = std::min(asWide, asLeaf);
    split_[n][1] = 0;
    for (int j = 2; j <= 4; ++j) {
      best_[n][j] = best_[n][1];
      split_[n][j] = 0;
      if (pair[j] < best_[n][j]) best_[n][j] = pair[j], split_[n][j] = pairSplit[j];
    }
  }
  // Appends child `c` given at most j slots, as solve() chose.
  void emit(const Slot& c, int j, Slot out[4], int& count) const {
    if (c.ref == gpu::kBvhEmptyRef) return;
    if (!isInner(c.ref) || split_[c.ref][j] == 0) {
      Slot s = c;
      if (isInner(c.ref) && merge_[c.ref])
        s.ref = gpu::kBvhLeafBit | count_[c.ref] << gpu::kBvhCountShift | first_[c.ref];
      out[count++] = s;
      return;
    }
    const gpu::BvhNode& b = bin_[c.ref];
    const int k0 = split_[c.ref][j];
    emit({b.lmin, b.lmax, b.left}, k0, out, count);
    emit({b.rmin, b.rmax, b.right}, j - k0, out, count);
  }

  const std::vector<gpu::BvhNode>& bin_;
  const WideCollapseOptions& opt_;
  std::vector<float> area_;                      // inner node's box's surface area (box as stored in its parent; root: both children's)
  std::vector<std::uint32_t> first_, count_;     // inner node's triangles (count ~0u: not contiguous)
  std::vector<std::array<float, 5>> best_;       // [n][j], j = 1..4 (all these: ~40 B per binary node, freed after the collapse)
  std::vector<std::array<std::uint8_t, 5>> split_;  // [n][j]: left child's share of j slots; 0: n takes one slot
  std::vector<std::uint8_t> merge_;              // n in one slot: a merged leaf (else a wide node)
  std::vector<std::uint8_t> wideSplit_;          // n as a wide node: its left child's share of the four slots
};

}  // namespace

BvhWide packBvhWideNodes(const std::vector<gpu::BvhNode>& binary, const WideCollapseOptions& options) {
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
  if (options.maxLeafSize < 0 || options.maxLeafSize > int(gpu::kBvhMaxLeafSize))
    throw Error("bvh_wide.cpp: WideCollapseOptions::maxLeafSize must be in [0, " + std::to_string(gpu::kBvhMaxLeafSize) + "]");
  // The DP needs a tree without empty slots (a one-leaf or empty tree has them; the greedy keeps those right).
  std::unique_ptr<SahCollapse> sah;
  if (options.method == WideCollapseOptions::Method::Sah && binary[0].left != gpu::kBvhEmptyRef &&
      binary[0].right != gpu::kBvhEmptyRef)
    sah = std::make_unique<SahCollapse>(binary, options);
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
    if (sah) {
      count = sah->slotsOf(w.binaryNode, kids);
    } else {
      addChildren(w.binaryNode, 0);
    }
    while (!sah && count < 4) {
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
    // The traversal writes up to three stack slots from sp on at every inner node, then keeps count - 1
    // (the GLSL moves four entries from its registers to its array only when it holds six or more, so
    // the total it holds is the same).
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
// its node visit or leaf test finds nothing nearer; docs/architecture.md, "Traversal"). The GLSL keeps the
// stack's top eight refs in registers and the rest in an array, one LIFO stack all the same.
template <bool kAnyHit>
Hit traverseWide(const std::vector<gpu::BvhWideNode>& nodes, const std::vector<gpu::TriGeom>& tris, const Ray& ray,
                 float tmax) {
  Hit hit;
  if (nodes.empty()) return hit;
  const glm::vec3 invDir = raybox::safeInverse(ray.dir);
  const RayShear rs = makeRayShear(ray.dir);
  // At most 3e38, as the shaders' tmax: an empty slot's box at +inf is entered by an infinite tmax, which
  // would stack more than stackNeed.
  float closest = std::min(tmax, 3.0e38f);
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

BvhShape bvhShapeFromEnv() {
  const char* env = std::getenv("CAUSTICA_BVH_SHAPE");
  return parseBvhShape(env ? env : "");
}

BvhShape parseBvhShape(const std::string& spec) {
  BvhShape shape;
  std::stringstream list(spec);
  std::string item;
  while (std::getline(list, item, ',')) {
    const std::size_t eq = item.find('=');
    const std::string key = item.substr(0, eq), value = eq == std::string::npos ? "" : item.substr(eq + 1);
    auto number = [&]() {
      char* end = nullptr;
      const double v = std::strtod(value.c_str(), &end);
      if (value.empty() || *end != '\0') throw Error("CAUSTICA_BVH_SHAPE: bad value in '" + item + "'");
      return v;
    };
    if (key == "collapse" && (value == "greedy" || value == "sah"))
      shape.collapse.method = value == "sah" ? WideCollapseOptions::Method::Sah : WideCollapseOptions::Method::Greedy;
    else if (key == "wideleaf") shape.collapse.maxLeafSize = int(number());
    else if (key == "cn") shape.collapse.costNode = float(number());
    else if (key == "cl") shape.collapse.costLeaf = float(number());
    else if (key == "ct") shape.collapse.costTriangle = float(number());
    else if (key == "leaf") shape.build.maxLeafSize = int(number());
    else if (key == "bct") shape.build.costTraversal = float(number());
    else if (key == "bci") shape.build.costIntersect = float(number());
    else if (key == "bins") shape.build.bins = int(number());
    else if (key == "bins2") shape.build.secondBins = int(number());
    else throw Error("CAUSTICA_BVH_SHAPE: unknown item '" + item + "'");
  }
  return shape;
}

}  // namespace caustica
