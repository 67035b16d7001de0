// manifold_chain.cpp — the caster chain and its Newton solve, twin of glsl/lib/manifold.glsl.
#include "accel/manifold_chain.h"

#include <cmath>

#include "accel/bvh_wide.h"
#include "accel/spawn.h"
#include "shading/manifold.h"
#include "shading/microfacet.h"
#include "shading/oct_normal.h"
#include "shading/sampling.h"

namespace caustica {

namespace {

glm::vec3 xyz(const glm::vec4& v) { return glm::vec3(v); }

// surfaceOn (surface.glsl) without textures: what a chain vertex needs of its hit.
struct ChainSurface {
  glm::vec3 p, pError, ngFront, ng, ns;
  bool front = false;
  gpu::Material m{};
  NormalDiff nd;
};

bool chainSurface(const ManifoldScene& s, const Hit& hit, const glm::vec3& dir, ChainSurface& sf) {
  const gpu::TriGeom& g = s.scene->triGeom[hit.tri];
  glm::vec3 p0 = xyz(g.v0), p1 = xyz(g.v1), p2 = xyz(g.v2);
  glm::vec3 n0 = shadeNormal(*s.scene, hit.tri, 0), n1 = shadeNormal(*s.scene, hit.tri, 1),
            n2 = shadeNormal(*s.scene, hit.tri, 2);
  float b0 = 1.0f - hit.u - hit.v;
  sf.p = b0 * p0 + hit.u * p1 + hit.v * p2;
  sf.pError = hitPointError(b0, hit.u, hit.v, p0, p1, p2);
  glm::vec3 cr = glm::cross(p1 - p0, p2 - p0);
  float crLen = glm::length(cr);
  if (!(crLen > 0.0f)) return false;
  sf.ngFront = cr / crLen;
  sf.front = glm::dot(dir, sf.ngFront) < 0.0f;
  sf.ng = sf.front ? sf.ngFront : -sf.ngFront;
  glm::vec3 nsRaw = b0 * n0 + hit.u * n1 + hit.v * n2;
  float nsLen = glm::length(nsRaw);
  glm::vec3 ns = nsLen > 1.0e-12f ? nsRaw / nsLen : sf.ngFront;
  if (glm::dot(ns, sf.ngFront) < 0.0f) ns = -ns;
  sf.m = s.scene->materials[glm::floatBitsToUint(g.v0.w)];
  sf.ns = sf.front ? ns : -ns;
  sf.nd = normalDiffOn(p0, p1, p2, n0, n1, n2, hit.u, hit.v, sf.ns);
  return true;
}

// pickWavelength (spectral.glsl).
void pickWavelength(float u, bool spectral, float& lambda, glm::vec3& filt) {
  const float lambdaMin = 380.0f, lambdaMax = 780.0f;
  if (spectral) {
    lambda = lambdaMin + (lambdaMax - lambdaMin) * u;
    filt = channelSensitivity(lambda) * (lambdaMax - lambdaMin);
    return;
  }
  const float channel[3] = {610.0f, 545.0f, 460.0f};
  int c = std::min(static_cast<int>(u * 3.0f), 2);
  lambda = channel[c];
  filt = glm::vec3(0.0f);
  filt[c] = 3.0f;
}

}  // namespace

unsigned casterOwning(const gpu::CasterParams& casters, const glm::vec3& p) {
  unsigned owner = CAUSTICA_MAX_CASTERS;
  for (unsigned i = 0; i < CAUSTICA_MAX_CASTERS && i < casters.count.x; ++i) {
    glm::vec3 d = p - xyz(casters.sphere[i]);
    if (owner == CAUSTICA_MAX_CASTERS && glm::dot(d, d) <= casters.sphere[i].w * casters.sphere[i].w) owner = i;
  }
  return owner;
}

RayDiff chainStartRay(const ManifoldQuery& q, const glm::vec2& ab, float& wLen) {
  glm::vec3 t, b;
  orthonormalBasis(q.axis, t, b);
  glm::vec3 wRaw = q.axis + ab.x * t + ab.y * b;
  wLen = glm::length(wRaw);
  RayDiff r;
  r.o = q.x;
  r.d = wRaw / wLen;
  r.oA = glm::vec3(0.0f);
  r.oB = glm::vec3(0.0f);
  r.dA = (t - r.d * glm::dot(r.d, t)) / wLen;
  r.dB = (b - r.d * glm::dot(r.d, b)) / wLen;
  return r;
}

bool chainEvent(const ManifoldScene& s, const ManifoldQuery& q, bool refractive, RayDiff& r, glm::vec3& org,
                glm::vec3& sigma, ManifoldResult& res) {
  Hit hit = traceClosest(*s.nodes, s.scene->triGeom, Ray{org, r.d}, 3.0e38f);
  if (!hit.found()) return false;
  ChainSurface sf;
  if (!chainSurface(s, hit, r.d, sf) || casterOwning(s.casters, sf.p) != q.caster) return false;
  res.throughput *= glm::exp(-sigma * hit.t);
  glm::vec3 pA = transferDiff(r.oA, r.dA, r.d, hit.t, sf.ng);
  glm::vec3 pB = transferDiff(r.oB, r.dB, r.d, hit.t, sf.ng);
  glm::vec3 nA = normalDerivative(sf.nd, sf.ns, pA);
  glm::vec3 nB = normalDerivative(sf.nd, sf.ns, pB);
  float metal = sf.m.params.x, rough = sf.m.params.y;
  glm::vec3 color = glm::vec3(sf.m.baseColor);
  bool isSmooth = rough * rough < kDeltaAlpha;
  glm::vec3 dNew, dA, dB;
  if (refractive) {
    float weight = (1.0f - metal) * sf.m.params.z;
    float ior = sf.m.params.w;
    if ((sf.m.tex.z & gpu::kMatDispersive) != 0u) {
      if (res.lambda == 0.0f) pickWavelength(q.uLambda, s.spectral, res.lambda, res.filt);
      ior = cauchyIor(ior, sf.m.absorption.w, res.lambda);
    }
    float eta = sf.front ? ior : 1.0f / ior;
    if (!(weight > 0.0f) || !(isSmooth || ior == 1.0f) ||
        !refractDiff(r.d, sf.ns, 1.0f / eta, dNew, r.dA, nA, dA, r.dB, nB, dB) || glm::dot(dNew, sf.ng) >= 0.0f)
      return false;
    float fresnel = fresnelDielectric(-glm::dot(r.d, sf.ns), eta);
    res.eventProb *= weight * (1.0f - fresnel);
    res.throughput *= color * (weight * (1.0f - fresnel) / (eta * eta));
    sigma = sf.front && (sf.m.tex.z & gpu::kMatHasVolume) != 0u ? xyz(sf.m.absorption) : glm::vec3(0.0f);
    org = offsetRayOrigin(sf.p, sf.pError, -sf.ng);
    res.ngLast = -sf.ng;
  } else {
    float weight = metal;
    dNew = glm::reflect(r.d, sf.ns);
    if (!(weight > 0.0f) || !isSmooth || glm::dot(dNew, sf.ng) <= 0.0f) return false;
    dA = reflectDiff(r.d, sf.ns, r.dA, nA);
    dB = reflectDiff(r.d, sf.ns, r.dB, nB);
    res.eventProb *= weight;
    res.throughput *= color * weight;
    org = offsetRayOrigin(sf.p, sf.pError, sf.ng);
    res.ngLast = sf.ng;
  }
  r.o = sf.p;
  r.oA = pA;
  r.oB = pB;
  r.d = dNew;
  r.dA = dA;
  r.dB = dB;
  res.pLast = sf.p;
  res.pLastError = sf.pError;
  return true;
}

bool chainResidual(const ManifoldScene& s, const ManifoldQuery& q, const RayDiff& r, float wLen, ManifoldResult& res,
                   glm::vec2& F, glm::mat2& J, bool& converged) {
  converged = false;
  F = glm::vec2(0.0f);
  J = glm::mat2(1.0f);
  glm::vec3 e = r.o - q.y;
  glm::vec3 nP = glm::normalize(xyz(s.casters.sphere[q.caster]) - q.y);
  float dn = glm::dot(r.d, nP);
  if (!(dn < 0.0f)) return false;
  float tL = -glm::dot(e, nP) / dn;
  if (!(tL > 0.0f)) return false;
  glm::vec3 uL, vL;
  orthonormalBasis(nP, uL, vL);
  glm::vec3 diff = e + tL * r.d;
  glm::vec3 qA = transferDiff(r.oA, r.dA, r.d, tL, nP);
  glm::vec3 qB = transferDiff(r.oB, r.dB, r.d, tL, nP);
  F = glm::vec2(glm::dot(diff, uL), glm::dot(diff, vL));
  J = glm::mat2(glm::dot(qA, uL), glm::dot(qA, vL), glm::dot(qB, uL), glm::dot(qB, vL));
  res.dLast = r.d;
  // dA on the light's triangle (normal nL) per solid angle at x: dA on the plane per d(ab), projected
  // along d from the plane onto the triangle's, times d(ab)/d(omega) = |w|^3 (gnomonic).
  float detJ = std::abs(J[0][0] * J[1][1] - J[1][0] * J[0][1]);
  res.areaPerSolidAngle = detJ * wLen * wLen * wLen * std::abs(dn) / std::abs(glm::dot(r.d, q.nL));
  converged = glm::length(diff) <= kManifoldTolerance * glm::length(e);
  return true;
}

bool traceManifoldChain(const ManifoldScene& s, const ManifoldQuery& q, const glm::vec2& ab, ManifoldResult& res,
                        glm::vec2& F, glm::mat2& J, bool& converged) {
  converged = false;
  F = glm::vec2(0.0f);
  J = glm::mat2(1.0f);
  float wLen;
  RayDiff r = chainStartRay(q, ab, wLen);
  res.w = r.d;
  res.ab = ab;
  res.throughput = glm::vec3(1.0f);
  res.eventProb = 1.0f;
  bool refractive = (s.casters.count.y & (1u << q.caster)) != 0u;
  unsigned events = refractive ? 2u : 1u;
  glm::vec3 org = q.xOrg, sigma = q.sigma;
  bool ok = true;
  for (unsigned k = 0; k < events && ok; ++k) ok = chainEvent(s, q, refractive, r, org, sigma, res);
  return ok && chainResidual(s, q, r, wLen, res, F, J, converged);
}

ManifoldResult manifoldSolve(const ManifoldScene& s, const ManifoldQuery& q) {
  ManifoldResult res;
  res.lambda = q.lambda;
  glm::vec2 ab = q.seed, step(0.0f);
  float stepScale = 1.0f;
  float residual = 3.0e38f;  // |F| at ab
  unsigned misses = 0;       // halvings of the current step
  bool haveChain = false;
  unsigned it = 0;
  do {
    glm::vec2 trial = ab - stepScale * step;
    ManifoldResult cand = res;
    glm::vec2 F;
    glm::mat2 J;
    bool done;
    if (traceManifoldChain(s, q, trial, cand, F, J, done) && glm::length(F) < residual) {
      ab = trial;
      res = cand;
      residual = glm::length(F);
      haveChain = true;
      if (done) {
        res.ok = true;
        break;
      }
      float det = J[0][0] * J[1][1] - J[1][0] * J[0][1];
      if (!(std::abs(det) > 0.0f)) break;
      step = glm::vec2(J[1][1] * F.x - J[1][0] * F.y, -J[0][1] * F.x + J[0][0] * F.y) / det;
      stepScale = 1.0f;
      misses = 0;
    } else {
      if (!haveChain || ++misses > 3u) break;
      stepScale *= 0.5f;
    }
  } while (++it < kManifoldIterations);
  res.iterations = it + (it < kManifoldIterations ? 1u : 0u);
  return res;
}

}  // namespace caustica
