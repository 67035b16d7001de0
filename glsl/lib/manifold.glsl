// manifold.glsl — manifold next-event estimation (MNEE) through caustic casters: at a path's first
// diffuse vertex x, the light sample y is joined to x through the picked caster by a chain of specular
// events (a glass caster: two refractions, in and out; a mirror caster: one reflection), found by
// Newton's method on the direction leaving x; the path's own bounces into the caster stay the other
// technique of a multiple-importance-sampled pair (docs/path-tracer.md, "Manifold next-event
// estimation"). World space; directions unit; pdfs per steradian at x unless said. C++ twins of the
// arithmetic in app/shading/manifold.h. Needs surface.glsl, casters.glsl, lights.glsl, path_state.glsl.

const uint kManifoldIterations = 10u;         // Newton steps (each traces the chain once) before giving up
const float kManifoldTolerance = 1.0e-5;      // converged: the chain ends this close to y, relative to |v_k - y|
const float kManifoldSameSolution = 1.0e-3;   // a bounce is the solution's path: direction parameters this close

// A ray and its derivatives with respect to the two parameters (a, b) of the direction leaving x.
struct RayDiff {
  vec3 o, d;       // origin (on the last surface, not offset) and unit direction
  vec3 oA, dA;     // d(o)/da, d(d)/da
  vec3 oB, dB;     // d(o)/db, d(d)/db
};

// The derivative of a hit's unit shading normal (surfaceOn's sf.ns, before any normal map) as the hit
// point moves by dp in the triangle's plane: the barycentric gradients gu, gv of the triangle, the
// vertex-normal differences n1 - n0, n2 - n0 and the sign of sf.ns over the length of the interpolated normal.
struct NormalDiff {
  vec3 gu, gv, dn1, dn2;
  float scale;  // +-1 / |interpolated normal|; 0 where the normal is the geometric one (constant)
};

NormalDiff normalDiffOn(Hit hit, HitTriangle h, vec3 ns) {
  NormalDiff nd;
  vec3 e1 = h.g.v1.xyz - h.g.v0.xyz, e2 = h.g.v2.xyz - h.g.v0.xyz;
  vec3 n = cross(e1, e2);
  float inv = 1.0 / dot(n, n);
  nd.gu = cross(e2, n) * inv;
  nd.gv = cross(n, e1) * inv;
  nd.dn1 = h.n1 - h.n0;
  nd.dn2 = h.n2 - h.n0;
  vec3 raw = (1.0 - hit.u - hit.v) * h.n0 + hit.u * h.n1 + hit.v * h.n2;
  float len = length(raw);
  nd.scale = len > 1.0e-12 ? (dot(raw, ns) >= 0.0 ? 1.0 : -1.0) / len : 0.0;
  return nd;
}

vec3 normalDerivative(NormalDiff nd, vec3 ns, vec3 dp) {
  vec3 raw = nd.dn1 * dot(nd.gu, dp) + nd.dn2 * dot(nd.gv, dp);
  return (raw - ns * dot(ns, raw)) * nd.scale;
}

// Carries a differential of the ray origin along unit direction d to the plane with normal ng that the
// ray meets at distance t (Igehy 1999): the change of the hit point.
vec3 transferDiff(vec3 dO, vec3 dD, vec3 d, float t, vec3 ng) {
  vec3 q = dO + t * dD;
  return q - d * (dot(q, ng) / dot(d, ng));
}

// Refraction of unit d through unit normal n (facing against d) with r = n_incident / n_transmitted,
// and of its differential dD given the normal's differential dN. False on total internal reflection.
bool refractDiff(vec3 d, vec3 n, float r, out vec3 dOut, vec3 dD, vec3 dN, out vec3 dDOut, vec3 dD2, vec3 dN2,
                 out vec3 dDOut2) {
  float cosI = -dot(d, n);
  float sin2T = r * r * max(0.0, 1.0 - cosI * cosI);
  dOut = d;
  dDOut = dD;
  dDOut2 = dD2;
  if (!(cosI > 0.0) || sin2T >= 1.0) return false;
  float cosT = sqrt(1.0 - sin2T);
  float mu = r * cosI - cosT;
  dOut = r * d + mu * n;
  float dCosI = -(dot(dD, n) + dot(d, dN));
  float dMu = r * dCosI - r * r * cosI * dCosI / cosT;
  dDOut = r * dD + mu * dN + dMu * n;
  float dCosI2 = -(dot(dD2, n) + dot(d, dN2));
  float dMu2 = r * dCosI2 - r * r * cosI * dCosI2 / cosT;
  dDOut2 = r * dD2 + mu * dN2 + dMu2 * n;
  return true;
}

// Reflection of unit d about unit normal n and of its differentials.
vec3 reflectDiff(vec3 d, vec3 n, vec3 dD, vec3 dN) {
  float cosI = -dot(d, n);
  return dD + 2.0 * (-(dot(dD, n) + dot(d, dN))) * n + 2.0 * cosI * dN;
}

// What manifoldSolve is asked: the chain from x through caster `caster` (index into CasterParams;
// axis: the unit direction from x to its centre, casterCone's), ending on the plane of the light
// triangle (unit normal nL of its front face) at y.
struct ManifoldQuery {
  vec3 x, xOrg;     // the diffuse vertex and the origin of rays leaving it (offset off its surface)
  vec3 sigma;       // absorption coefficient of the medium around x
  vec3 axis;        // unit direction from x to the caster's centre (casterCone)
  uint caster;      // its index in CasterParams
  vec3 y, nL;       // the light point and its triangle's unit front normal
  float lambda;     // wavelength the path carries (0: all); a dispersive chain picks one with uLambda
  float uLambda;
  vec2 seed;        // direction parameters the Newton steps start from
};

struct ManifoldResult {
  bool ok;          // converged to a chain that reaches y's plane at y (visibility of y not tested)
  vec2 ab;          // the solution's direction parameters (gnomonic, about the caster's axis)
  vec3 w;           // the direction leaving x
  vec3 throughput;  // expected throughput of the chain's events (lobe choice, Fresnel, tint, eta^2, absorption)
  float eventProb;  // probability that a path's own bounces choose these events (lobe and Fresnel choices)
  float areaPerSolidAngle;  // dA(y) / d(omega at x): the chain's generalised geometry term, inverted
  vec3 pLast, pLastError, ngLast;  // the last chain vertex, its error bound and geometric normal on the exit side
  vec3 dLast;       // the direction leaving it (towards y)
  float lambda;     // the wavelength chosen (or given), with its filter
  vec3 filt;
};

// The ray leaving x along the direction of parameters ab (gnomonic about the caster's axis, its
// basis t, b) and its derivatives with respect to ab; wLen: the length of the unnormalised direction.
RayDiff chainStartRay(ManifoldQuery q, vec2 ab, out float wLen) {
  vec3 t, b;
  orthonormalBasis(q.axis, t, b);
  vec3 wRaw = q.axis + ab.x * t + ab.y * b;
  wLen = length(wRaw);
  RayDiff r;
  r.o = q.x;
  r.d = wRaw / wLen;
  r.oA = vec3(0.0);
  r.oB = vec3(0.0);
  r.dA = (t - r.d * dot(r.d, t)) / wLen;
  r.dB = (b - r.d * dot(r.d, b)) / wLen;
  return r;
}

// One specular event of the chain: r (leaving org, in a medium of absorption sigma) meets the caster
// and refracts (a glass caster) or reflects (a mirror) through its smooth lobe; r, org and sigma move
// past the event and res gathers its throughput and probability. False when r misses the caster or
// the surface there cannot make the event.
bool chainEvent(ManifoldQuery q, bool refractive, inout RayDiff r, inout vec3 org, inout vec3 sigma,
                inout ManifoldResult res) {
  Hit hit;
  if (!traceClosest(org, r.d, 3.0e38, hit)) return false;
  HitTriangle h = hitTriangle(hit);
  Surface sf;
  if (!surfaceOn(hit, h, r.d, false, sf) || casterOwning(sf.p) != q.caster) return false;
#ifdef CAUSTICA_VOLUME
  res.throughput *= exp(-sigma * hit.t);
#endif
  NormalDiff nd = normalDiffOn(hit, h, sf.ns);
  vec3 pA = transferDiff(r.oA, r.dA, r.d, hit.t, sf.ng);
  vec3 pB = transferDiff(r.oB, r.dB, r.d, hit.t, sf.ng);
  vec3 nA = normalDerivative(nd, sf.ns, pA);
  vec3 nB = normalDerivative(nd, sf.ns, pB);
  vec2 metalRough = materialMetalRough(sf.m, sf.uv);
  vec3 color = materialBaseColor(sf.m, sf.uv, sf.color).rgb;
  bool isSmooth = metalRough.y * metalRough.y < kDeltaAlpha;
  vec3 dNew, dA, dB;
  if (refractive) {
    float weight = (1.0 - metalRough.x) * sf.m.params.z;  // the glass lobe's probability
    float ior = sf.m.params.w;
#ifdef CAUSTICA_DISPERSION
    if ((sf.m.tex.z & kMatDispersive) != 0u) {
      if (res.lambda == 0.0) pickWavelength(q.uLambda, res.lambda, res.filt);
      ior = cauchyIor(ior, sf.m.absorption.w, res.lambda);
    }
#endif
    float eta = sf.front ? ior : 1.0 / ior;
    if (!(weight > 0.0) || !(isSmooth || ior == 1.0) ||
        !refractDiff(r.d, sf.ns, 1.0 / eta, dNew, r.dA, nA, dA, r.dB, nB, dB) || dot(dNew, sf.ng) >= 0.0)
      return false;
    float fresnel = fresnelDielectric(-dot(r.d, sf.ns), eta);
    res.eventProb *= weight * (1.0 - fresnel);
    res.throughput *= color * (weight * (1.0 - fresnel) / (eta * eta));
#ifdef CAUSTICA_VOLUME
    sigma = mediumBeyond(sf);
#endif
    org = offsetRayOrigin(sf.p, sf.pError, -sf.ng);
    res.ngLast = -sf.ng;
  } else {
    float weight = metalRough.x;  // the mirror lobe's probability
    dNew = reflect(r.d, sf.ns);
    if (!(weight > 0.0) || !isSmooth || dot(dNew, sf.ng) <= 0.0) return false;
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

// The chain's exit ray r on the plane through y facing the caster (normal nP): F = its point minus y,
// in the plane's basis (better conditioned than the light triangle's own plane, which may face
// anywhere), its Jacobian J, the solution's area per solid angle at x (wLen: chainStartRay's) and
// whether it converged. False when r does not reach the plane.
bool chainResidual(ManifoldQuery q, RayDiff r, float wLen, inout ManifoldResult res, out vec2 F, out mat2 J,
                   out bool converged) {
  converged = false;
  F = vec2(0.0);
  J = mat2(1.0);
  vec3 e = r.o - q.y;
  vec3 nP = normalize(casters.sphere[q.caster].xyz - q.y);
  float dn = dot(r.d, nP);
  if (!(dn < 0.0)) return false;
  float tL = -dot(e, nP) / dn;
  if (!(tL > 0.0)) return false;
  vec3 uL, vL;
  orthonormalBasis(nP, uL, vL);
  vec3 diff = e + tL * r.d;
  vec3 qA = transferDiff(r.oA, r.dA, r.d, tL, nP);
  vec3 qB = transferDiff(r.oB, r.dB, r.d, tL, nP);
  F = vec2(dot(diff, uL), dot(diff, vL));
  J = mat2(dot(qA, uL), dot(qA, vL), dot(qB, uL), dot(qB, vL));
  res.dLast = r.d;
  // dA on the light's triangle (normal nL) per solid angle at x: dA on the plane per d(ab), projected
  // along d from the plane onto the triangle's, times d(ab)/d(omega) = |w|^3 (gnomonic).
  float detJ = abs(J[0][0] * J[1][1] - J[1][0] * J[0][1]);
  res.areaPerSolidAngle = detJ * wLen * wLen * wLen * abs(dn) / abs(dot(r.d, q.nL));
  converged = length(diff) <= kManifoldTolerance * length(e);
  return true;
}

// Traces the chain from x along the direction of parameters ab about the caster's axis, with the
// derivatives of everything with respect to ab (chainStartRay, then chainEvent per specular event,
// then chainResidual); returns the chain's end on y's plane in res and the residual F and its
// Jacobian J (in the light plane's orthonormal basis), and in `converged` whether the chain ends at
// y. False when the chain leaves the caster, meets a surface that is not the expected smooth
// specular one, or misses the plane.
bool traceManifoldChain(ManifoldQuery q, vec2 ab, inout ManifoldResult res, out vec2 F, out mat2 J, out bool converged) {
  converged = false;
  F = vec2(0.0);
  J = mat2(1.0);
  float wLen;
  RayDiff r = chainStartRay(q, ab, wLen);
  res.w = r.d;
  res.ab = ab;
  res.throughput = vec3(1.0);
  res.eventProb = 1.0;
  bool refractive = (casters.count.y & (1u << q.caster)) != 0u;
  uint events = refractive ? 2u : 1u;
  vec3 org = q.xOrg;
  vec3 sigma = q.sigma;
  bool ok = true;
  uint k = 0u;
  do {
    ok = chainEvent(q, refractive, r, org, sigma, res);
  } while (ok && ++k < events);
  return ok && chainResidual(q, r, wLen, res, F, J, converged);
}

// Newton's method on the direction leaving x, from the caster's centre (ab = 0): each step traces the
// chain once; a step whose chain breaks is halved. Deterministic in (x, y, caster, wavelength), so the
// path it finds is a function of those: the set of paths manifold NEE produces, which a bounce
// reaching y compares itself against (manifoldClaims).
ManifoldResult manifoldSolve(ManifoldQuery q, bool wanted) {
  ManifoldResult res;
  res.ok = false;
  res.lambda = q.lambda;
  res.filt = vec3(1.0);
  res.ab = vec2(0.0);
  res.w = vec3(0.0);
  res.throughput = vec3(0.0);
  res.eventProb = 0.0;
  res.areaPerSolidAngle = 0.0;
  res.pLast = res.pLastError = res.ngLast = res.dLast = vec3(0.0);
  if (!wanted) return res;
  vec2 ab = q.seed, step = vec2(0.0);
  float stepScale = 1.0;
  float residual = 3.0e38;  // |F| at ab
  uint misses = 0u;         // halvings of the current step
  bool haveChain = false;
  uint it = 0u;
  do {
    vec2 trial = ab - stepScale * step;
    ManifoldResult cand = res;
    vec2 F;
    mat2 J;
    bool done;
    if (traceManifoldChain(q, trial, cand, F, J, done) && length(F) < residual) {
      ab = trial;
      res = cand;
      residual = length(F);
      haveChain = true;
      if (done) {
        res.ok = true;
        break;
      }
      float det = J[0][0] * J[1][1] - J[1][0] * J[0][1];
      if (!(abs(det) > 0.0)) break;
      step = vec2(J[1][1] * F.x - J[1][0] * F.y, -J[0][1] * F.x + J[0][0] * F.y) / det;
      stepScale = 1.0;
      misses = 0u;
    } else {  // the step breaks the chain or does not bring it closer: halve it, a few times
      if (!haveChain || ++misses > 3u) break;
      stepScale *= 0.5;
    }
  } while (++it < kManifoldIterations);
  return res;
}
