// casters.glsl — diffuse bounce directions aimed at caustic casters (bounding spheres of glass and
// mirror objects, CasterParams in gpu_layout.h) and, with caster guiding, at vMF lobes fitted to their
// caustic photons, mixed with cosine sampling. Twins in app/shading/sampling.h.
// Directions are world-space unit vectors; pdfs are per steradian.

layout(std140, binding = CAUSTICA_BINDING_CASTERS) uniform CasterBlock { CasterParams casters; };

const float kCasterMinOneMinusCos = 1.0e-5;  // narrowest cone aimed at: 1 - cos(half angle)

// Whether unit direction w lies in the cone (unit axis, 1 - cos of the half angle), tested as
// 1 - cos(w, axis) = |w - axis|^2 / 2 without cancellation, with a relative slack of 1e-4 so that
// directions sampled at the rim are never rounded out of it.
bool inCone(vec3 w, vec3 axis, float oneMinusCos) {
  vec3 d = w - axis;
  return 0.5 * dot(d, d) <= oneMinusCos * 1.0001;
}

// The cone of directions from p towards sphere s (xyz centre, w radius): unit axis and 1 - cos of the
// half angle (computed without cancellation). False when p is inside the sphere, the
// whole cone lies below the plane of the unit normal n (no light can arrive from there), or the cone
// is so narrow (half angle below ~0.26 degrees) that float rounding would blur which directions are
// inside it: such a caster is not worth aiming at, and skipping it depends on p alone.
bool casterCone(vec3 p, vec3 n, vec4 s, out vec3 axis, out float oneMinusCos) {
  vec3 d = s.xyz - p;
  float dist2 = dot(d, d);
  float r2 = s.w * s.w;
  axis = vec3(0.0, 0.0, 1.0);
  oneMinusCos = 0.0;
  if (!(dist2 > r2 * 1.0001)) return false;
  float dist = sqrt(dist2);
  axis = d / dist;
  float sin2 = r2 / dist2;
  oneMinusCos = sin2 / (1.0 + sqrt(max(0.0, 1.0 - sin2)));
  return oneMinusCos >= kCasterMinOneMinusCos && dot(n, axis) > -sqrt(sin2);
}

// Whether the cone (unit axis, 1 - cos of the half angle) seen from p overlaps, within margin radians,
// the cone of the sphere around every emitter: p lies roughly in the shadow the caster casts.
bool casterFacesLights(vec3 p, vec3 axis, float oneMinusCos, vec4 lights, float margin) {
  vec3 d = lights.xyz - p;
  float dist2 = dot(d, d);
  if (!(lights.w >= 0.0)) return false;
  if (dist2 <= lights.w * lights.w) return true;
  float dist = sqrt(dist2);
  float angleLights = asin(min(1.0, lights.w / dist));
  float angleCaster = asin(sqrt(oneMinusCos * (2.0 - oneMinusCos)));  // sin^2 = (1 - cos)(1 + cos)
  float between = 2.0 * asin(min(1.0, 0.5 * length(axis - d / dist)));  // exact for small angles, unlike acos
  return between <= angleCaster + angleLights + margin;
}

// The index of the first caster whose sphere holds p (the caster a chain vertex belongs to), else
// CAUSTICA_MAX_CASTERS.
uint casterOwning(vec3 p) {
  uint owner = uint(CAUSTICA_MAX_CASTERS);
  for (uint i = 0u; i < uint(CAUSTICA_MAX_CASTERS); ++i) {
    if (i >= casters.count.x) break;
    vec3 d = p - casters.sphere[i].xyz;
    if (owner == uint(CAUSTICA_MAX_CASTERS) && dot(d, d) <= casters.sphere[i].w * casters.sphere[i].w) owner = i;
  }
  return owner;
}

// Uniform direction in the cone about `axis` with 1 - cos(half angle) = oneMinusCos; pdf 1 / (2 pi oneMinusCos).
vec3 sampleUniformCone(vec3 axis, float oneMinusCos, vec2 u) {
  float omcT = u.x * oneMinusCos;  // 1 - cos(theta), kept apart so narrow cones stay exact
  float cosT = 1.0 - omcT;
  float sinT = sqrt(max(0.0, omcT * (2.0 - omcT)));
  float phi = 2.0 * PI * u.y;
  vec3 t, b;
  orthonormalBasis(axis, t, b);
  return normalize(sinT * cos(phi) * t + sinT * sin(phi) * b + cosT * axis);
}

#ifdef CAUSTICA_GUIDING
uvec4 casterGuideCell(uint caster, uint cls, vec3 p);  // caustic_cells.glsl
const uint kMinGuidePhotons = 8u;       // photons a cell needs for a guide lobe
const float kMaxGuideKappa = 1.0e4;     // the narrowest guide lobe (vMF concentration)
const uint kGuideClasses = 2u;          // guide lobes per caster: photons of its own chain, of any other
#endif

// The cones of the casters usable from the current diffuse vertex (prepareCasters), kept for the
// pdf evaluations that follow at the same vertex: usable ones first.
uint gCasterUsable = 0u;                        // how many casters are usable from the vertex
uint gCasterPick = 0u;                          // index into gCasterAxis of the uniformly picked one
vec3 gCasterAxis[CAUSTICA_MAX_CASTERS];         // unit axis of the cone
float gCasterInvSolidAngle[CAUSTICA_MAX_CASTERS];  // 1 / solid angle of the cone (per steradian)
float gCasterOneMinusCos[CAUSTICA_MAX_CASTERS];    // 1 - cos of the half angle
#ifdef CAUSTICA_GUIDING
// Per usable caster k and photon class c, at [kGuideClasses * k + c]: the guide lobe, a vMF about the
// mean direction its photons came from in the vertex's cell, and its probability within the caster's
// share (the cone has the rest).
vec3 gGuideAxis[kGuideClasses * CAUSTICA_MAX_CASTERS];
float gGuideKappa[kGuideClasses * CAUSTICA_MAX_CASTERS];   // concentration
float gGuideNorm[kGuideClasses * CAUSTICA_MAX_CASTERS];    // kappa / (2 pi (1 - exp(-2 kappa))): the pdf at the axis
float gGuideWeight[kGuideClasses * CAUSTICA_MAX_CASTERS];  // 0: no lobe

// The guide lobe fitted to a guide cell (count x, summed direction yzw as int bits of kCellDirScale) at a
// vertex with unit normal n: a vMF about the photons' mean direction, its concentration from their mean
// resultant length r (Banerjee et al. 2005: kappa = r (3 - r^2) / (1 - r^2)). False without enough
// photons or when they came from below the surface.
bool guideLobe(uvec4 cell, vec3 n, out vec3 axis, out float kappa) {
  axis = n;
  kappa = 0.0;
  if (cell.x < kMinGuidePhotons) return false;
  vec3 sum = vec3(ivec3(cell.yzw)) / (float(cell.x) * kCellDirScale);
  float len = length(sum);
  if (!(len > 1.0e-3) || dot(sum, n) <= 0.0) return false;
  float r = min(len, 0.9999);
  kappa = min(r * (3.0 - r * r) / (1.0 - r * r), kMaxGuideKappa);
  axis = sum / len;
  return true;
}

// The guide lobe of caster i and photon class cls at p (unit normal n): guideLobe of p's guide cell.
bool casterGuide(uint i, uint cls, vec3 p, vec3 n, out vec3 axis, out float kappa) {
  return guideLobe(casterGuideCell(i, cls, p), n, axis, kappa);
}

// The vMF lobe of concentration kappa about a unit axis: its density at the axis (per steradian; the
// density at angle theta is that times exp(-kappa (1 - cos theta))), and 1 - cos theta of a direction
// drawn from it with u in [0, 1) (inverting its cdf; Jakob 2012), at most 2.
float vmfNorm(float kappa) { return kappa / (2.0 * PI * (1.0 - exp(-2.0 * kappa))); }
float vmfOneMinusCos(float kappa, float u) { return min(-log(u + (1.0 - u) * exp(-2.0 * kappa)) / kappa, 2.0); }

// The vMF density (per steradian) of lobe j at unit direction w, 1 - cos from |w - axis|^2 / 2.
float guidePdf(uint j, vec3 w) {
  vec3 d = w - gGuideAxis[j];
  return gGuideNorm[j] * exp(-gGuideKappa[j] * 0.5 * dot(d, d));
}
#endif

// Finds the casters usable from p (unit normal n): those whose cone may be aimed at, and with caster
// guiding those with a guide lobe at p; picks one of them uniformly with u.
void prepareCasters(vec3 p, vec3 n, float u) {
  gCasterUsable = 0u;
  gCasterPick = 0u;
  for (uint i = 0u; i < uint(CAUSTICA_MAX_CASTERS); ++i) {
    if (i >= casters.count.x) break;
    vec3 axis;
    float omc;
    bool cone = (casters.guide.z & (1u << i)) != 0u && casterCone(p, n, casters.sphere[i], axis, omc) &&
                ((casters.count.y & (1u << i)) == 0u || casterFacesLights(p, axis, omc, casters.lights, casters.params.y));
#ifdef CAUSTICA_GUIDING
    vec3 gAxis[kGuideClasses];
    float kappa[kGuideClasses];
    bool guide[kGuideClasses];
    uint guides = 0u;
    for (uint c = 0u; c < kGuideClasses; ++c) {
      guide[c] = casterGuide(i, c, p, n, gAxis[c], kappa[c]);
      if (guide[c]) ++guides;
    }
    if (!cone && guides == 0u) continue;
#else
    if (!cone) continue;
#endif
    uint k = gCasterUsable++;
    gCasterAxis[k] = cone ? axis : n;
    gCasterOneMinusCos[k] = cone ? omc : 0.0;
    gCasterInvSolidAngle[k] = cone ? 1.0 / (2.0 * PI * omc) : 0.0;
#ifdef CAUSTICA_GUIDING
    // The guide lobes share casters.params.z of the caster's part equally (all of it without a cone).
    float share = guides == 0u ? 0.0 : (cone ? casters.params.z : 1.0) / float(guides);
    for (uint c = 0u; c < kGuideClasses; ++c) {
      uint j = kGuideClasses * k + c;
      gGuideAxis[j] = gAxis[c];
      gGuideKappa[j] = kappa[c];
      gGuideNorm[j] = guide[c] ? vmfNorm(kappa[c]) : 0.0;
      gGuideWeight[j] = guide[c] ? share : 0.0;
    }
#endif
  }
  if (gCasterUsable > 0u) gCasterPick = min(uint(u * float(gCasterUsable)), gCasterUsable - 1u);
}

// Density of sampleDiffuseDirection at w (per steradian): (1 - a) cos/pi + a * (mean over the usable
// casters of their part's density: [w in cone] / solid angle, with caster guiding mixed with the guide
// lobes' vMF densities), a = casters.params.x when some caster is usable, else 0.
float diffuseDirectionPdf(vec3 n, vec3 w) {
  float cosPdf = max(dot(n, w), 0.0) * INV_PI;
  if (gCasterUsable == 0u) return cosPdf;
  float sum = 0.0;
  for (uint k = 0u; k < uint(CAUSTICA_MAX_CASTERS); ++k) {
    if (k >= gCasterUsable) break;
#ifdef CAUSTICA_GUIDING
    float coneWeight = 1.0;
    for (uint c = 0u; c < kGuideClasses; ++c) {
      uint j = kGuideClasses * k + c;
      coneWeight -= gGuideWeight[j];
      if (gGuideWeight[j] > 0.0) sum += gGuideWeight[j] * guidePdf(j, w);
    }
    if (coneWeight > 1.0e-6 && inCone(w, gCasterAxis[k], gCasterOneMinusCos[k])) sum += coneWeight * gCasterInvSolidAngle[k];
#else
    if (inCone(w, gCasterAxis[k], gCasterOneMinusCos[k])) sum += gCasterInvSolidAngle[k];
#endif
  }
  float a = casters.params.x;
  return (1.0 - a) * cosPdf + a * sum / float(gCasterUsable);
}

// Diffuse bounce direction at the prepared vertex (unit normal n): with probability casters.params.x
// (when a caster is usable) a uniform direction in the picked caster's cone (with caster guiding, or a
// direction from one of its guide lobes, by their weights), else a cosine-weighted one.
// sampleUniformCone and sampleCosineHemisphere written as one body with per-lane selected inputs (the
// same arithmetic for each: llvmpipe runs both sides of a branch, so two bodies cost two cos/sin pairs,
// two bases and two normalisations on every bounce).
vec3 sampleDiffuseDirection(vec3 n, float uPick, vec2 u) {
  bool cone = gCasterUsable > 0u && uPick < casters.params.x;
  vec3 axis = n;
  float omcT = 0.0;
  if (cone) {
    axis = gCasterAxis[gCasterPick];
    omcT = u.x * gCasterOneMinusCos[gCasterPick];  // 1 - cos(theta)
#ifdef CAUSTICA_GUIDING
    // A guide lobe instead, chosen with uPick rescaled to [0, 1) over the caster's part.
    float v = uPick / casters.params.x, run = 0.0;
    for (uint c = 0u; c < kGuideClasses; ++c) {
      uint j = kGuideClasses * gCasterPick + c;
      float w0 = run;
      run += gGuideWeight[j];
      if (v >= w0 && v < run) {
        axis = gGuideAxis[j];
        omcT = vmfOneMinusCos(gGuideKappa[j], u.x);
      }
    }
#endif
  }
  float s = sqrt(cone ? max(0.0, omcT * (2.0 - omcT)) : u.x);  // sin(theta)
  float z = cone ? 1.0 - omcT : sqrt(max(0.0, 1.0 - u.x));      // cos(theta)
  float phi = 2.0 * PI * u.y;
  vec3 t, b;
  orthonormalBasis(axis, t, b);
  return normalize(s * cos(phi) * t + s * sin(phi) * b + z * axis);
}
