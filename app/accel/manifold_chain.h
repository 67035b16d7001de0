// manifold_chain.h — C++ twin of glsl/lib/manifold.glsl's Newton solve over a flat scene: the caster
// chain traced through the 4-wide BVH (bvh_wide.h) with its ray differentials (shading/manifold.h),
// the residual on the light's plane and the step, as the shader does them. For the tests (GLSL
// against C++, convergence, the Jacobian against finite differences) and experiments; not used to render.
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "accel/gpu_scene.h"
#include "shared/gpu_layout.h"

namespace caustica {

// What the chain tracer reads: a flat scene's 4-wide nodes, triangles, shading words and materials
// (GpuScene) and the caster UBO.
struct ManifoldScene {
  const std::vector<gpu::BvhWideNode>* nodes = nullptr;
  const GpuScene* scene = nullptr;
  gpu::CasterParams casters{};
  bool spectral = false;  // CAUSTICA_SPECTRAL: a dispersive chain picks a hero wavelength, else an RGB channel
};

constexpr unsigned kManifoldIterations = 10;     // twins of manifold.glsl's constants
constexpr float kManifoldTolerance = 1.0e-5f;
constexpr float kManifoldSameSolution = 1.0e-3f;

struct ManifoldQuery {
  glm::vec3 x{0.0f}, xOrg{0.0f}, sigma{0.0f}, axis{0.0f, 0.0f, 1.0f};
  unsigned caster = 0;
  glm::vec3 y{0.0f}, nL{0.0f, 0.0f, 1.0f};
  float lambda = 0.0f, uLambda = 0.0f;
  glm::vec2 seed{0.0f};  // direction parameters the Newton steps start from
};

struct ManifoldResult {
  bool ok = false;
  glm::vec2 ab{0.0f};
  glm::vec3 w{0.0f}, throughput{0.0f};
  float eventProb = 0.0f, areaPerSolidAngle = 0.0f;
  glm::vec3 pLast{0.0f}, pLastError{0.0f}, ngLast{0.0f}, dLast{0.0f};
  float lambda = 0.0f;
  glm::vec3 filt{1.0f};
  unsigned iterations = 0;  // chains traced
};

// The first caster whose sphere holds p (manifold.glsl), else CAUSTICA_MAX_CASTERS.
unsigned casterOwning(const gpu::CasterParams& casters, const glm::vec3& p);
// A ray leaving a chain vertex and its derivatives with respect to the direction parameters ab.
struct RayDiff {
  glm::vec3 o{0.0f}, d{0.0f};    // origin (on the last surface, not offset) and unit direction
  glm::vec3 oA{0.0f}, dA{0.0f};  // d(o)/da, d(d)/da
  glm::vec3 oB{0.0f}, dB{0.0f};  // d(o)/db, d(d)/db
};
// The named steps of traceManifoldChain, as in manifold.glsl: the ray leaving x at ab (wLen: the
// unnormalised direction's length); one specular event through the caster (r, org, sigma move past
// it); the exit ray's residual on the plane through y, its Jacobian and area per solid angle.
RayDiff chainStartRay(const ManifoldQuery& q, const glm::vec2& ab, float& wLen);
bool chainEvent(const ManifoldScene& s, const ManifoldQuery& q, bool refractive, RayDiff& r, glm::vec3& org,
                glm::vec3& sigma, ManifoldResult& res);
bool chainResidual(const ManifoldScene& s, const ManifoldQuery& q, const RayDiff& r, float wLen, ManifoldResult& res,
                   glm::vec2& F, glm::mat2& J, bool& converged);
// One trace of the chain at direction parameters ab: false when the chain breaks; else the residual F
// on the light's plane, its Jacobian J (column-major, J[c][r] = dF_r / d(ab)_c) and whether it converged.
bool traceManifoldChain(const ManifoldScene& s, const ManifoldQuery& q, const glm::vec2& ab, ManifoldResult& res,
                        glm::vec2& F, glm::mat2& J, bool& converged);
ManifoldResult manifoldSolve(const ManifoldScene& s, const ManifoldQuery& q);

}  // namespace caustica
