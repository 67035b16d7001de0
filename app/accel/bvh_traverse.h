// bvh_traverse.h — the C++ twin of the stack traversal over binary nodes (gpu::BvhNode) in
// glsl/lib/traverse.glsl: closest and any hit; world space, t in units of |ray.dir|.
#pragma once
#include <limits>
#include <vector>

#include "accel/intersect.h"
#include "shared/gpu_layout.h"

namespace caustica {

// Closest hit with t in (0, tmax) over the binary nodes: the reference for the 4-wide twin (bvh_wide.h)
// and the visiting order of bvhVisitNode() in traverse.glsl (used by traverse_instanced.glsl).
Hit traceClosest(const std::vector<gpu::BvhNode>& nodes, const std::vector<gpu::TriGeom>& tris,
                 const Ray& ray, float tmax = std::numeric_limits<float>::infinity());

// Any hit with t in (0, tmax) over the binary nodes (see traceClosest above).
bool traceOccluded(const std::vector<gpu::BvhNode>& nodes, const std::vector<gpu::TriGeom>& tris,
                   const Ray& ray, float tmax);

}  // namespace caustica
