// sampling.glsl — sampling routines and small geometry helpers. Each has a C++ twin of the same
// name in app/shading/sampling.h, used by the tests (chi-square and moment tests).

const float PI = 3.14159265358979323846;
const float INV_PI = 0.31830988618379067154;

float luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }
float maxComponent(vec3 c) { return max(c.x, max(c.y, c.z)); }

// Orthonormal basis around a unit vector (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
void orthonormalBasis(vec3 n, out vec3 t, out vec3 b) {
  float s = n.z >= 0.0 ? 1.0 : -1.0;
  float a = -1.0 / (s + n.z);
  float c = n.x * n.y * a;
  t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
  b = vec3(c, s + n.y * n.y * a, -n.y);
}

// Cosine-weighted direction about +z (local space); pdf = cos(theta) / pi per steradian.
vec3 sampleCosineHemisphere(vec2 u) {
  float r = sqrt(u.x);
  float phi = 2.0 * PI * u.y;
  return vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u.x)));
}

// Uniform point on a triangle: barycentrics (b1, b2) of p1 and p2; pdf = 1 / area.
vec2 sampleTriangleUniform(vec2 u) {
  float su = sqrt(u.x);
  return vec2(1.0 - su, u.y * su);
}

// Power heuristic (beta = 2) weight of technique a against technique b (pdfs in the same measure).
// Written as a ratio so that large pdfs (small lights, grazing angles) cannot overflow a^2 to Inf.
float powerHeuristic(float a, float b) {
  if (!(a > 0.0)) return 0.0;
  float r = b / a;
  return 1.0 / (1.0 + r * r);
}

// Unpolarised Fresnel reflectance of a smooth dielectric interface. cosI = |cos| of the incident
// angle, eta = n_transmitted / n_incident. Total internal reflection returns 1.
float fresnelDielectric(float cosI, float eta) {
  cosI = clamp(cosI, 0.0, 1.0);
  float sin2T = (1.0 - cosI * cosI) / (eta * eta);
  if (sin2T >= 1.0) return 1.0;
  float cosT = sqrt(max(0.0, 1.0 - sin2T));
  float rs = (cosI - eta * cosT) / (cosI + eta * cosT);
  float rp = (eta * cosI - cosT) / (eta * cosI + cosT);
  return 0.5 * (rs * rs + rp * rp);
}

// Refraction of incident direction d (unit, towards the surface) through normal n (unit, facing
// against d), eta = n_incident / n_transmitted. Returns false on total internal reflection.
bool refractDir(vec3 d, vec3 n, float eta, out vec3 t) {
  float cosI = -dot(d, n);
  float sin2T = eta * eta * max(0.0, 1.0 - cosI * cosI);
  if (sin2T >= 1.0) {
    t = vec3(0.0);
    return false;
  }
  float cosT = sqrt(1.0 - sin2T);
  t = normalize(eta * d + (eta * cosI - cosT) * n);
  return true;
}
