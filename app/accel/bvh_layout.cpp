// bvh_layout.cpp — what a built tree hands the GPU and how its packed nodes are read: triangle
// positions in leaf order (TriGeom), the tree's bounds and its SAH cost (world space).
#include "accel/bvh.h"

#include <cmath>
#include <limits>
#include <string>

#include "accel/intersect.h"
#include "util/error.h"

namespace caustica {

namespace {
constexpr float kInf = std::numeric_limits<float>::infinity();
}  // namespace

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

void appendTriGeom(const Triangle* triangles, std::size_t count, const Bvh& bvh, std::vector<gpu::TriGeom>& out) {
  if (bvh.order.size() != count)
    throw Error("bvh_layout.cpp: BVH was built for " + std::to_string(bvh.order.size()) + " triangles, got " +
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

}  // namespace caustica
