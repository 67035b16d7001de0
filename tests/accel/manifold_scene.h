// manifold_scene.h — the small caustic scene the manifold NEE tests share (accel/manifold_chain_test.cpp,
// gpu/manifold_twins_gpu_test.cpp): a diffuse floor, a small square lamp, a tessellated glass sphere and a
// mirror sphere with interpolated vertex normals, and a flat mirror; packed as the renderer packs a flat
// scene, with the caster UBO it uploads. Also an independent forward tracer of a caster's chain (the
// photon's way, lamp to floor) that makes queries whose chain exists. World space, scene units, y up.
#pragma once
#include <array>
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "accel/bvh_wide.h"
#include "accel/gpu_scene.h"
#include "accel/manifold_chain.h"
#include "accel/spawn.h"
#include "shading/sampling.h"
#include "../gpu/scene_builder.h"

namespace caustica::test {

// The largest of an error measured over many queries (a NaN sticks), and over how many.
struct WorstError {
  explicit WorstError(std::string w) : what(std::move(w)) {}
  std::string what;
  double value = 0;
  int count = 0;
  void add(double v) {
    ++count;
    if (!(v <= value)) value = v;
  }
  std::string text() const {
    std::ostringstream s;
    s << what << ": worst " << value << " over " << count;
    return s.str();
  }
};

struct ManifoldTestScene {
  Scene scene;
  GpuScene g;
  std::vector<gpu::BvhWideNode> wide;
  ManifoldScene ms;
  std::uint32_t floorMaterial = 0;
  unsigned glass = 0, mirrorBall = 0, flatMirror = 0;  // caster indices
  // The lamp: a square of half side lampHalf centred at lampCentre, facing -y (its front normal lampN).
  glm::vec3 lampCentre{0.0f, 2.0f, 0.0f}, lampN{0.0f, -1.0f, 0.0f};
  float lampHalf = 0.05f;
  float mirrorX = 1.5f;  // the flat mirror lies in the plane x = mirrorX, facing -x
  glm::vec3 mirrorColor{0.9f, 0.8f, 0.7f};
  float glassIor = 1.5f;
  float lampArea() const { return 4.0f * lampHalf * lampHalf; }
  // A point of the lamp from u in [0, 1)^2.
  glm::vec3 lampPoint(glm::vec2 u) const {
    return lampCentre + glm::vec3((2.0f * u.x - 1.0f) * lampHalf, 0.0f, (2.0f * u.y - 1.0f) * lampHalf);
  }
  bool onLamp(const glm::vec3& p) const {
    return std::abs(p.x - lampCentre.x) <= lampHalf && std::abs(p.z - lampCentre.z) <= lampHalf;
  }
};

// Builds the scene; the BVH, GpuScene and 4-wide nodes as Renderer::buildScene makes them for a flat
// scene, and the caster UBO's spheres, refraction bits and parameters as Renderer::casterParams fills them
// (not its photon-pass, guide and aim masks, which the chain code does not read). dispersiveGlass: the glass disperses
// (Abbe number 30) and absorbs (KHR_materials_volume), which the forward tracer below does not follow.
inline ManifoldTestScene makeManifoldTestScene(bool dispersiveGlass = false) {
  ManifoldTestScene t;
  Scene& s = t.scene;
  t.floorMaterial = addMaterial(s, diffuseMaterial(0.5f));
  std::uint32_t lamp = addMaterial(s, emitterMaterial(20.0f));
  Material glassM = glassMaterial(t.glassIor);
  if (dispersiveGlass) {
    glassM.dispersion = 20.0f / 30.0f;
    glassM.attenuationColor = glm::vec3(0.6f, 0.8f, 0.95f);
    glassM.attenuationDistance = 0.3f;
  }
  std::uint32_t glass = addMaterial(s, glassM);
  std::uint32_t mirror = addMaterial(s, metalMaterial(t.mirrorColor));
  const float S = 2.0f, h = t.lampHalf, Y = t.lampCentre.y, X = t.mirrorX;
  addQuad(s, {-S, 0, -S}, {-S, 0, S}, {S, 0, S}, {S, 0, -S}, t.floorMaterial);  // faces +y
  addQuad(s, {-h, Y, -h}, {h, Y, -h}, {h, Y, h}, {-h, Y, h}, lamp);              // faces -y
  addSphere(s, {-0.6f, 0.45f, 0.0f}, 0.3f, 12, glass);
  addSphere(s, {0.4f, 0.4f, -0.9f}, 0.25f, 12, mirror);
  addQuad(s, {X, 0.2f, -0.3f}, {X, 0.2f, 0.3f}, {X, 1.2f, 0.3f}, {X, 1.2f, -0.3f}, mirror);  // faces -x
  finishBounds(s);
  const BvhShape shape = bvhShapeFromEnv();
  Bvh bvh = buildBvh(s.triangles, shape.build);
  t.g = packScene(s, bvh);
  t.wide = packBvhWideNodes(t.g.nodes, shape.collapse).nodes;
  gpu::CasterParams& cp = t.ms.casters;
  cp = gpu::CasterParams{};
  cp.count.x = static_cast<std::uint32_t>(std::min<size_t>(t.g.casters.size(), CAUSTICA_MAX_CASTERS));
  cp.params = glm::vec4(0.5f, kCasterLightMargin, 0.0f, 0.0f);
  cp.lights = t.g.emitterSphere;
  for (std::uint32_t i = 0; i < cp.count.x; ++i) {
    cp.sphere[i] = t.g.casters[i].sphere;
    if (t.g.casters[i].refractive) cp.count.y |= 1u << i;
    glm::vec3 c(cp.sphere[i]);
    if (t.g.casters[i].refractive) t.glass = i;
    else if (c.x > 1.0f) t.flatMirror = i;
    else t.mirrorBall = i;
  }
  t.ms.nodes = &t.wide;
  t.ms.scene = &t.g;
  return t;
}

// A ray's hit as the chain sees it, computed here without the twin: the point, its error bound, the
// triangle's front normal, the unit interpolated shading normal turned to the front, the material.
struct ForwardHit {
  glm::vec3 p, pError, ngFront, ns;
  gpu::Material m;
  std::uint32_t material = 0, tri = 0;
};

inline bool forwardHit(const ManifoldTestScene& t, const glm::vec3& org, const glm::vec3& d, ForwardHit& fh) {
  Hit hit = traceClosest(t.wide, t.g.triGeom, Ray{org, d}, 3.0e38f);
  if (!hit.found()) return false;
  const gpu::TriGeom& tri = t.g.triGeom[hit.tri];
  glm::vec3 p0(tri.v0), p1(tri.v1), p2(tri.v2);
  float b0 = 1.0f - hit.u - hit.v;
  fh.p = b0 * p0 + hit.u * p1 + hit.v * p2;
  fh.pError = hitPointError(b0, hit.u, hit.v, p0, p1, p2);
  fh.ngFront = glm::normalize(glm::cross(p1 - p0, p2 - p0));
  glm::vec3 n = b0 * shadeNormal(t.g, hit.tri, 0) + hit.u * shadeNormal(t.g, hit.tri, 1) + hit.v * shadeNormal(t.g, hit.tri, 2);
  fh.ns = glm::length(n) > 0.0f ? glm::normalize(n) : fh.ngFront;
  if (glm::dot(fh.ns, fh.ngFront) < 0.0f) fh.ns = -fh.ns;
  fh.material = glm::floatBitsToUint(tri.v0.w);
  fh.tri = hit.tri;
  fh.m = t.g.materials[fh.material];
  return true;
}

// One specular event of a caster at hit fh for unit direction d (Snell with the shading normal, or the
// mirror): the new direction and the ray origin beyond the surface. False on total internal reflection.
inline bool forwardEvent(const ManifoldTestScene& t, const ForwardHit& fh, bool refractive, glm::vec3& d, glm::vec3& org) {
  bool front = glm::dot(d, fh.ngFront) < 0.0f;
  glm::vec3 ng = front ? fh.ngFront : -fh.ngFront, ns = front ? fh.ns : -fh.ns;
  glm::vec3 next;
  if (refractive) {
    float r = front ? 1.0f / t.glassIor : t.glassIor;  // n_incident / n_transmitted
    if (!refractDir(d, ns, r, next) || glm::dot(next, ng) >= 0.0f) return false;
    org = offsetRayOrigin(fh.p, fh.pError, -ng);
  } else {
    next = glm::reflect(d, ns);
    if (glm::dot(next, ng) <= 0.0f) return false;
    org = offsetRayOrigin(fh.p, fh.pError, ng);
  }
  d = next;
  return true;
}

// The chain of caster `caster` from lamp point y along unit dir, as a photon goes, to the floor: the
// landing point x, its error bound, and the unit direction from x back along the last segment.
inline bool forwardPhoton(const ManifoldTestScene& t, unsigned caster, const glm::vec3& y, glm::vec3 dir,
                          glm::vec3& x, glm::vec3& xError, glm::vec3& back) {
  bool refractive = (t.ms.casters.count.y & (1u << caster)) != 0u;
  glm::vec3 org = offsetRayOrigin(y, glm::vec3(1e-6f), t.lampN);
  for (unsigned k = 0; k < (refractive ? 2u : 1u); ++k) {
    ForwardHit fh;
    if (!forwardHit(t, org, dir, fh) || casterOwning(t.ms.casters, fh.p) != caster) return false;
    if (!forwardEvent(t, fh, refractive, dir, org)) return false;
  }
  ForwardHit fh;
  if (!forwardHit(t, org, dir, fh) || fh.material != t.floorMaterial || fh.p.y != 0.0f) return false;
  x = fh.p;
  xError = fh.pError;
  back = -dir;
  return true;
}

// The query manifold NEE makes at floor point x (error bound xError) towards lamp point y through `caster`:
// its axis the direction to the caster's centre, Newton from the axis.
inline ManifoldQuery floorQuery(const ManifoldTestScene& t, unsigned caster, const glm::vec3& x, const glm::vec3& xError,
                                const glm::vec3& y) {
  ManifoldQuery q;
  q.x = x;
  q.xOrg = offsetRayOrigin(x, xError, glm::vec3(0.0f, 1.0f, 0.0f));
  q.sigma = glm::vec3(0.0f);
  q.axis = glm::normalize(glm::vec3(t.ms.casters.sphere[caster]) - x);
  q.caster = caster;
  q.y = y;
  q.nL = t.lampN;
  q.lambda = 0.0f;
  q.uLambda = 0.5f;
  q.seed = glm::vec2(0.0f);
  return q;
}

// Queries whose chain exists: photons from uniform lamp points towards uniform points of the caster's
// sphere, traced to the floor; each query asks for the chain from the landing point back to the lamp
// point (`back`: the photon's own direction at x, one solution). The axis Newton starts from: towards the
// caster's centre, or with nearAxis > 0 the photon's direction tilted by up to nearAxis (tangent) in each
// of two directions, as a caustic cell's mean photon direction seeds the renderer's solve.
struct ChainQuery {
  ManifoldQuery q;
  glm::vec3 back;
};
inline std::vector<ChainQuery> photonQueries(const ManifoldTestScene& t, unsigned caster, int count, std::uint32_t seed,
                                            float nearAxis = 0.0f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f), sym(-1.0f, 1.0f);
  std::vector<ChainQuery> out;
  glm::vec4 sphere = t.ms.casters.sphere[caster];
  for (int tries = 0; static_cast<int>(out.size()) < count && tries < 200 * count; ++tries) {
    glm::vec3 y = t.lampPoint({u(rng), u(rng)});
    glm::vec3 v(sym(rng), sym(rng), sym(rng));
    if (glm::dot(v, v) > 1.0f) continue;
    glm::vec3 dir = glm::normalize(glm::vec3(sphere) + 0.95f * sphere.w * v - y);
    glm::vec3 x, xError, back;
    if (!forwardPhoton(t, caster, y, dir, x, xError, back)) continue;
    ChainQuery cq{floorQuery(t, caster, x, xError, y), back};
    if (nearAxis > 0.0f) {  // the axis a cell's mean photon direction gives: near the solution
      glm::vec3 tt, bb;
      orthonormalBasis(back, tt, bb);
      cq.q.axis = glm::normalize(back + nearAxis * (sym(rng) * tt + sym(rng) * bb));
    }
    out.push_back(cq);
  }
  return out;
}

}  // namespace caustica::test
