// light_tree.cpp — builds the light tree over the emissive triangles and holds the C++ twins of
// glsl/lib/light_tree.glsl (lightImportance, sampleLightTree, lightTreePdf).
#include "accel/light_tree.h"

#include <algorithm>
#include <cmath>

#include "util/error.h"

namespace caustica {
namespace {

constexpr double kPiD = 3.14159265358979323846;
constexpr int kBuckets = 12;

// The build depends only on the emitters' geometry up to scale and translation, not on rounding: a scene
// scaled or moved gets its vertices, so its centroids, extents and normals, rounded differently (about
// 1e-7 of its coordinates; normals of a small lamp's coplanar triangles come out 1e-5 apart), and its
// items arrive in another (BVH) order. So the items are taken in their source order and every partition
// keeps it; a centroid's place along an axis is taken relative to the node's centroid bounds and snapped
// to kSnap, so that a centroid on a bucket boundary (symmetric emitters) stays on its side; two costs,
// or two extents, within kTie of each other are a tie, which the first candidate (axis x before y
// before z, lower bucket first) wins; and nearly parallel normals widen a cone rather than open it to
// the whole sphere (unionCone).
constexpr double kSnap = 65536.0;  // 2^16 steps over the centroid bounds (rounding moves a centroid ~1e-6)
constexpr double kTie = 1e-3;      // relative: above the rounding noise of costs (1e-5..1e-4 on small triangles)

// Bounds of a set of emitters: box, power, and the cone of normals (axis, half angle theta_o) beyond
// which light leaves within theta_e (pi/2 for every triangle: cosine emission).
struct Bounds {
  glm::dvec3 lo{1e300}, hi{-1e300};
  double power = 0.0;
  glm::dvec3 axis{0.0};
  double thetaO = -1.0;  // < 0: empty cone
  bool twoSided = false;
  bool empty() const { return thetaO < 0.0; }
};

double angleBetween(const glm::dvec3& a, const glm::dvec3& b) {
  // Numerically stable for nearly equal and nearly opposite vectors.
  if (glm::dot(a, b) < 0.0) return kPiD - 2.0 * std::asin(std::min(1.0, glm::length(a + b) / 2.0));
  return 2.0 * std::asin(std::min(1.0, glm::length(b - a) / 2.0));
}

// The smallest cone (about) that holds both cones; a small pad keeps it conservative under rounding.
void unionCone(glm::dvec3& axis, double& theta, const glm::dvec3& axisB, double thetaB) {
  if (theta < 0.0) {
    axis = axisB;
    theta = thetaB;
    return;
  }
  if (thetaB < 0.0) return;
  double d = angleBetween(axis, axisB);
  if (std::min(d + thetaB, kPiD) <= theta) return;
  if (std::min(d + theta, kPiD) <= thetaB) {
    axis = axisB;
    theta = thetaB;
    return;
  }
  double thetaNew = (theta + d + thetaB) / 2.0 + 1e-5;
  glm::dvec3 rotAxis = glm::cross(axis, axisB);
  if (thetaNew >= kPiD) {
    theta = kPiD;  // the whole sphere
    return;
  }
  if (glm::dot(rotAxis, rotAxis) < 1e-24) {
    // Axes too nearly parallel to rotate between: keep this axis, widened to hold the other cone
    // (nearly opposite axes: the whole sphere). Rounding leaves coplanar triangles' normals this close.
    theta = d < kPiD / 2.0 ? std::min(std::max(theta, d + thetaB) + 1e-5, kPiD) : kPiD;
    return;
  }
  rotAxis = glm::normalize(rotAxis);
  double r = thetaNew - theta - 1e-5;  // rotate the axis towards axisB by this angle (Rodrigues)
  axis = axis * std::cos(r) + glm::cross(rotAxis, axis) * std::sin(r) + rotAxis * glm::dot(rotAxis, axis) * (1.0 - std::cos(r));
  axis = glm::normalize(axis);
  theta = thetaNew;
}

void grow(Bounds& b, const Bounds& o) {
  if (o.empty()) return;
  b.lo = glm::min(b.lo, o.lo);
  b.hi = glm::max(b.hi, o.hi);
  b.power += o.power;
  b.twoSided = b.twoSided || o.twoSided;
  unionCone(b.axis, b.thetaO, o.axis, o.thetaO);
}

// Orientation measure of a cone of normals theta_o with emission spread theta_e = pi/2 (Conty & Kulla).
double orientationMeasure(double thetaO) {
  double thetaW = std::min(thetaO + kPiD / 2.0, kPiD);
  return 2.0 * kPiD * (1.0 - std::cos(thetaO)) +
         kPiD / 2.0 * (2.0 * thetaW * std::sin(thetaO) - std::cos(thetaO - 2.0 * thetaW) - 2.0 * thetaO * std::sin(thetaO) +
                       std::cos(thetaO));
}

double surfaceArea(const Bounds& b) {
  glm::dvec3 d = glm::max(b.hi - b.lo, glm::dvec3(0.0));
  return 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
}

double splitCost(const Bounds& b, double kr) {
  if (b.empty()) return 0.0;
  return b.power * orientationMeasure(b.thetaO) * std::max(surfaceArea(b), 1e-30) * kr;
}

struct Item {
  Bounds b;
  glm::dvec3 centroid;
  std::uint32_t tri;
  std::uint32_t instance;  // LightTreeItem::instance
  std::uint32_t source;    // LightTreeItem::source
};

class Builder {
 public:
  explicit Builder(LightTree& t) : tree_(t) {}

  void build(std::vector<Item>& items, std::size_t begin, std::size_t end, std::uint32_t nodeIndex, int depth,
             std::uint32_t trail) {
    Bounds b;
    for (std::size_t i = begin; i < end; ++i) grow(b, items[i].b);
    gpu::LightNode& node = tree_.nodes[nodeIndex];
    node.boundsMin = glm::vec4(glm::vec3(b.lo), static_cast<float>(b.power));
    node.boundsMax = glm::vec4(glm::vec3(b.hi), static_cast<float>(std::cos(b.thetaO)));
    node.axis = glm::vec4(glm::vec3(b.axis), 0.0f);  // cos(theta_e) = cos(pi/2): cosine emission
    node.link = glm::uvec4(0u, b.twoSided ? gpu::kLightNodeTwoSided : 0u, 0u, 0u);
    if (end - begin == 1) {
      node.link.x = items[begin].tri;
      node.link.y |= gpu::kLightNodeLeaf | items[begin].instance << gpu::kLightNodeInstanceShift;
      node.link.z = trail;
      node.link.w = static_cast<std::uint32_t>(depth);
      tree_.leafOf[items[begin].tri] = nodeIndex;
      leaves_.push_back({items[begin].source, nodeIndex});
      tree_.maxDepth = std::max(tree_.maxDepth, depth);
      return;
    }
    std::size_t mid = split(items, begin, end, b, depth);
    auto left = static_cast<std::uint32_t>(tree_.nodes.size());
    tree_.nodes.resize(tree_.nodes.size() + 2);
    tree_.nodes[nodeIndex].link.x = left;  // (node may have moved with the resize)
    build(items, begin, mid, left, depth + 1, trail);
    build(items, mid, end, left + 1, depth + 1, trail | (1u << depth));
  }

 private:
  // Returns the first item of the right child; both sides non-empty. Keeps the items' order on each side.
  std::size_t split(std::vector<Item>& items, std::size_t begin, std::size_t end, const Bounds& b, int depth) {
    std::size_t n = end - begin;
    glm::dvec3 cLo(1e300), cHi(-1e300);
    for (std::size_t i = begin; i < end; ++i) {
      cLo = glm::min(cLo, items[i].centroid);
      cHi = glm::max(cHi, items[i].centroid);
    }
    glm::dvec3 ext = b.hi - b.lo;
    double maxExt = std::max({ext.x, ext.y, ext.z});
    double bestCost = 1e300;
    int bestAxis = -1, bestBucket = 0;
    for (int a = 0; a < 3; ++a) {
      double lo = cLo[a], hi = cHi[a];
      if (!(hi > lo)) continue;
      Bounds bucket[kBuckets];
      for (std::size_t i = begin; i < end; ++i) grow(bucket[bucketOf(items[i].centroid[a], lo, hi)], items[i].b);
      double kr = ext[a] > 0.0 ? maxExt / ext[a] : 1.0;
      for (int s = 0; s + 1 < kBuckets; ++s) {
        Bounds l, r;
        for (int k = 0; k <= s; ++k) grow(l, bucket[k]);
        for (int k = s + 1; k < kBuckets; ++k) grow(r, bucket[k]);
        if (l.empty() || r.empty()) continue;
        double cost = splitCost(l, kr) + splitCost(r, kr);
        if (cost < bestCost * (1.0 - kTie)) {
          bestCost = cost;
          bestAxis = a;
          bestBucket = s;
        }
      }
    }
    std::size_t mid = begin;
    if (bestAxis >= 0) {
      double lo = cLo[bestAxis], hi = cHi[bestAxis];
      auto it = std::stable_partition(items.begin() + static_cast<std::ptrdiff_t>(begin),
                                      items.begin() + static_cast<std::ptrdiff_t>(end),
                                      [&](const Item& it2) { return bucketOf(it2.centroid[bestAxis], lo, hi) <= bestBucket; });
      mid = static_cast<std::size_t>(it - items.begin());
    }
    // Depth guard: every leaf below must stay within the trail's bits. A side with m items needs
    // ceil(log2 m) more levels at least; if the best split leaves too few, halve by count instead,
    // along the widest axis, in the order of the snapped centroids (ties: the items' order).
    auto levels = [](std::size_t m) { int l = 0; while ((std::size_t(1) << l) < m) ++l; return l; };
    int budget = CAUSTICA_LIGHT_TREE_DEPTH - (depth + 1);
    if (mid == begin || mid == end || levels(mid - begin) > budget || levels(end - mid) > budget) {
      int axis = 0;
      for (int a = 1; a < 3; ++a)
        if (ext[a] > ext[axis] * (1.0 + kTie)) axis = a;
      mid = begin + n / 2;
      const double lo = cLo[axis], hi = cHi[axis];
      std::stable_sort(items.begin() + static_cast<std::ptrdiff_t>(begin), items.begin() + static_cast<std::ptrdiff_t>(end),
                       [&](const Item& x, const Item& y) {
                         return snapped(x.centroid[axis], lo, hi) < snapped(y.centroid[axis], lo, hi);
                       });
    }
    return mid;
  }

  // A centroid's place in [lo, hi] as a fraction, snapped to 1/kSnap (0 where lo == hi).
  static double snapped(double c, double lo, double hi) {
    if (!(hi > lo)) return 0.0;
    return std::round(std::clamp((c - lo) / (hi - lo), 0.0, 1.0) * kSnap) / kSnap;
  }
  static int bucketOf(double c, double lo, double hi) {
    return std::min(static_cast<int>(kBuckets * snapped(c, lo, hi)), kBuckets - 1);
  }

  LightTree& tree_;

 public:
  std::vector<std::pair<std::uint32_t, std::uint32_t>> leaves_;  // (source, leaf node)
};

float cosSubClamped(float sinA, float cosA, float sinB, float cosB) {  // cos(max(0, a - b))
  if (cosA > cosB) return 1.0f;
  return cosA * cosB + sinA * sinB;
}
float sinSubClamped(float sinA, float cosA, float sinB, float cosB) {  // sin(max(0, a - b))
  if (cosA > cosB) return 0.0f;
  return sinA * cosB - cosA * sinB;
}
float safeSqrt(float x) { return std::sqrt(std::max(x, 0.0f)); }

}  // namespace

LightTree buildLightTree(std::vector<LightTreeItem> in, std::size_t triangleCount) {
  LightTree tree;
  tree.leafOf.assign(triangleCount, gpu::kInvalidIndex);
  if (in.empty()) return tree;
  std::vector<Item> items;
  items.reserve(in.size());
  for (const LightTreeItem& t : in) {
    Item it;
    glm::dvec3 a(t.v[0]), b(t.v[1]), c(t.v[2]);
    it.b.lo = glm::min(a, glm::min(b, c));
    it.b.hi = glm::max(a, glm::max(b, c));
    it.b.power = t.power;
    glm::dvec3 nrm = glm::cross(b - a, c - a);
    double len = glm::length(nrm);
    it.b.axis = len > 0.0 ? nrm / len : glm::dvec3(0, 0, 1);
    it.b.thetaO = len > 0.0 ? 0.0 : kPiD;
    it.b.twoSided = t.twoSided;
    it.centroid = (it.b.lo + it.b.hi) * 0.5;
    it.tri = t.tri;
    it.instance = t.instance;
    it.source = t.source;
    if (t.instance >= (1u << (32 - gpu::kLightNodeInstanceShift)))
      throw Error("light_tree.cpp: more than 2^30 instances");
    items.push_back(it);
  }
  // The source order, not the caller's (a BVH's, which rounding can change): partitions keep it.
  std::stable_sort(items.begin(), items.end(), [](const Item& x, const Item& y) { return x.source < y.source; });
  tree.nodes.reserve(2 * items.size());
  tree.nodes.resize(1);
  Builder builder(tree);
  builder.build(items, 0, items.size(), 0, 0, 0u);
  std::stable_sort(builder.leaves_.begin(), builder.leaves_.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  tree.leavesBySource.reserve(builder.leaves_.size());
  for (const auto& l : builder.leaves_) tree.leavesBySource.push_back(l.second);
  return tree;
}

float lightImportance(const gpu::LightNode& node, const glm::vec3& p, const glm::vec3& n) {
  float power = node.boundsMin.w;
  if (!(power > 0.0f)) return 0.0f;
  glm::vec3 lo(node.boundsMin), hi(node.boundsMax);
  glm::vec3 centre = 0.5f * (lo + hi);
  glm::vec3 d = p - centre;  // from the node's centre to p
  float d2 = glm::dot(d, d);
  glm::vec3 diag = hi - lo;
  float r2 = 0.25f * glm::dot(diag, diag);  // squared radius of the sphere around the box
  float invD = d2 > 0.0f ? 1.0f / std::sqrt(d2) : 0.0f;
  // Angle from the cone axis to p (theta_w), reduced by the cone (theta_o) and by the angle the
  // bounding sphere subtends from p (theta_b): the smallest emission angle any triangle below can have.
  float cosW = glm::dot(glm::vec3(node.axis), d) * invD;
  if ((node.link.y & gpu::kLightNodeTwoSided) != 0u) cosW = std::abs(cosW);
  float sinW = safeSqrt(1.0f - cosW * cosW);
  float cosB = d2 > r2 ? safeSqrt(1.0f - r2 / d2) : -1.0f;  // -1: p inside the sphere, every direction
  float sinB = safeSqrt(1.0f - cosB * cosB);
  float cosO = node.boundsMax.w;
  float sinO = safeSqrt(1.0f - cosO * cosO);
  float cosX = cosSubClamped(sinW, cosW, sinO, cosO);
  float sinX = sinSubClamped(sinW, cosW, sinO, cosO);
  float cosP = cosSubClamped(sinX, cosX, sinB, cosB);
  if (cosP <= node.axis.w) return 0.0f;
  float importance = power * cosP / std::max(d2, r2);
  if (glm::dot(n, n) > 0.0f) {  // the receiver's cosine, bounded the same way (either side of the surface)
    float cosI = d2 > 0.0f ? std::abs(glm::dot(d, n)) * invD : 1.0f;
    float sinI = safeSqrt(1.0f - cosI * cosI);
    importance *= cosSubClamped(sinI, cosI, sinB, cosB);
  }
  return std::max(importance, 0.0f);
}

bool sampleLightTree(const std::vector<gpu::LightNode>& nodes, const glm::vec3& p, const glm::vec3& n, float u,
                     std::uint32_t& tri, float& pmf) {
  pmf = 0.0f;
  if (nodes.empty()) return false;
  std::uint32_t i = 0;
  float prob = 1.0f;
  if ((nodes[0].link.y & gpu::kLightNodeLeaf) != 0u) {
    if (!(lightImportance(nodes[0], p, n) > 0.0f)) return false;
  }
  for (int depth = 0; depth <= CAUSTICA_LIGHT_TREE_DEPTH; ++depth) {
    const gpu::LightNode& node = nodes[i];
    if ((node.link.y & gpu::kLightNodeLeaf) != 0u) {
      tri = node.link.x;
      pmf = prob;
      return true;
    }
    float il = lightImportance(nodes[node.link.x], p, n);
    float ir = lightImportance(nodes[node.link.x + 1u], p, n);
    if (!(il + ir > 0.0f)) return false;
    float pl = il / (il + ir);
    if (u < pl) {
      u = std::min(u / pl, 0x1.fffffep-1f);
      prob *= pl;
      i = node.link.x;
    } else {
      u = std::min((u - pl) / (1.0f - pl), 0x1.fffffep-1f);
      prob *= 1.0f - pl;
      i = node.link.x + 1u;
    }
  }
  return false;
}

float lightTreePdf(const std::vector<gpu::LightNode>& nodes, const glm::vec3& p, const glm::vec3& n, std::uint32_t leaf) {
  if (leaf >= nodes.size()) return 0.0f;
  std::uint32_t trail = nodes[leaf].link.z, depth = nodes[leaf].link.w;
  if (depth == 0u) return lightImportance(nodes[0], p, n) > 0.0f ? 1.0f : 0.0f;
  std::uint32_t i = 0;
  float prob = 1.0f;
  for (std::uint32_t k = 0; k < depth; ++k) {
    const gpu::LightNode& node = nodes[i];
    float il = lightImportance(nodes[node.link.x], p, n);
    float ir = lightImportance(nodes[node.link.x + 1u], p, n);
    if (!(il + ir > 0.0f)) return 0.0f;
    float pl = il / (il + ir);
    if (((trail >> k) & 1u) != 0u) {
      prob *= 1.0f - pl;
      i = node.link.x + 1u;
    } else {
      prob *= pl;
      i = node.link.x;
    }
  }
  return prob;
}

}  // namespace caustica
