// casters.glsl — diffuse bounce directions aimed at caustic casters (bounding spheres of glass and
// mirror objects, CasterParams in gpu_layout.h) mixed with cosine sampling. Twins in app/shading/sampling.h.
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

// The cones of the casters usable from the current diffuse vertex (prepareCasters), kept for the
// pdf evaluations that follow at the same vertex: usable ones first.
uint gCasterUsable = 0u;                        // how many casters are usable from the vertex
uint gCasterPick = 0u;                          // index into gCasterAxis of the uniformly picked one
vec3 gCasterAxis[CAUSTICA_MAX_CASTERS];         // unit axis of the cone
float gCasterInvSolidAngle[CAUSTICA_MAX_CASTERS];  // 1 / solid angle of the cone (per steradian)
float gCasterOneMinusCos[CAUSTICA_MAX_CASTERS];    // 1 - cos of the half angle

// Finds the casters usable from p (unit normal n) and picks one of them uniformly with u.
void prepareCasters(vec3 p, vec3 n, float u) {
  gCasterUsable = 0u;
  gCasterPick = 0u;
  for (uint i = 0u; i < uint(CAUSTICA_MAX_CASTERS); ++i) {
    if (i >= casters.count.x) break;
    vec3 axis;
    float omc;
    if (!casterCone(p, n, casters.sphere[i], axis, omc)) continue;
    if ((casters.count.y & (1u << i)) != 0u && !casterFacesLights(p, axis, omc, casters.lights, casters.params.y))
      continue;
    uint k = gCasterUsable++;
    gCasterAxis[k] = axis;
    gCasterOneMinusCos[k] = omc;
    gCasterInvSolidAngle[k] = 1.0 / (2.0 * PI * omc);
  }
  if (gCasterUsable > 0u) gCasterPick = min(uint(u * float(gCasterUsable)), gCasterUsable - 1u);
}

// Density of sampleDiffuseDirection at w (per steradian): (1 - a) cos/pi + a * (mean over the usable
// casters of [w in cone] / solid angle), a = casters.params.x when some caster is usable, else 0.
float diffuseDirectionPdf(vec3 n, vec3 w) {
  float cosPdf = max(dot(n, w), 0.0) * INV_PI;
  if (gCasterUsable == 0u) return cosPdf;
  float sum = 0.0;
  for (uint k = 0u; k < uint(CAUSTICA_MAX_CASTERS); ++k) {
    if (k >= gCasterUsable) break;
    if (inCone(w, gCasterAxis[k], gCasterOneMinusCos[k])) sum += gCasterInvSolidAngle[k];
  }
  float a = casters.params.x;
  return (1.0 - a) * cosPdf + a * sum / float(gCasterUsable);
}

// Diffuse bounce direction at the prepared vertex (unit normal n): with probability casters.params.x
// (when a caster is usable) a uniform direction in the picked caster's cone, else a cosine-weighted one.
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
  }
  float s = sqrt(cone ? max(0.0, omcT * (2.0 - omcT)) : u.x);  // sin(theta)
  float z = cone ? 1.0 - omcT : sqrt(max(0.0, 1.0 - u.x));      // cos(theta)
  float phi = 2.0 * PI * u.y;
  vec3 t, b;
  orthonormalBasis(axis, t, b);
  return normalize(s * cos(phi) * t + s * sin(phi) * b + z * axis);
}
