// light_trace_test.comp — GPU test entry: where light subpaths leave (sampleLtEmission, lib/light_trace.glsl)
// and the density ltEmissionPdf claims for them, over a scene bound as the renderer binds it, so that
// tests/gpu/light_trace_gpu_test.cpp can hold the one's histogram against the other (chi-square). The host
// passes the scene's feature defines. World space; directions unit vectors.
#include "../lib/bindings.glsl"
#include "../lib/rng.glsl"
#include "../lib/sampling.glsl"
#include "../lib/spawn.glsl"
#include "../lib/intersect.glsl"
#include "../lib/traverse.glsl"
#include "../lib/textures.glsl"
#include "../lib/spectral.glsl"
#include "../lib/microfacet.glsl"
#include "../lib/materials.glsl"
#include "../lib/lights.glsl"
#include "../lib/casters.glsl"

layout(local_size_x = 64) in;

#include "../lib/surface.glsl"
#include "../lib/light_trace.glsl"

// The scene's arrays are read through buffer textures, so SSBO bindings 0 and 1 are free here (as in
// caustic_photons.comp); the host binds them after the scene.
// kIntegrate: per point one vec4: (barycentrics b1, b2 of the point, triangle bits, 0).
layout(std430, binding = 0) readonly buffer InBuffer { vec4 inRec[]; };
// kSample: per sample two vec4: (barycentrics b1, b2 of the point, triangle bits or ~0u: nothing left, 0),
// (w, pdf). kIntegrate: per point and direction bin one float. kTriangle: per triangle two floats.
layout(std430, binding = 1) writeonly buffer OutBuffer { float outFloat[]; };

layout(location = 0) uniform uint count;  // kSample: samples; kIntegrate: points x bins; kTriangle: triangles
layout(location = 1) uniform uint function;
layout(location = 2) uniform uint seed;
layout(location = 3) uniform uvec3 grid;  // kIntegrate: bins in z (cos of the angle to +z) and in phi; x y subdivisions per bin

const uint kSample = 0u;     // sampleLtEmission with the numbers startSubpath draws
const uint kIntegrate = 1u;  // the integral of ltEmissionPdf over one direction bin at one point
const uint kTriangle = 2u;   // triangle i's material index (bits) and area

// Barycentrics (b1, b2) of point p in triangle tri (TriGeom order).
vec2 barycentricsOf(uint tri, vec3 p) {
  TriGeom g = triGeomAt(tri);
  vec3 e1 = g.v1.xyz - g.v0.xyz, e2 = g.v2.xyz - g.v0.xyz, d = p - g.v0.xyz;
  float d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2), d1 = dot(d, e1), d2 = dot(d, e2);
  float det = d11 * d22 - d12 * d12;
  return vec2(d22 * d1 - d12 * d2, d11 * d2 - d12 * d1) / det;
}

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  if (function == kSample) {
    uvec4 rng = rngSeed(i, 0u, seed);
    float uCaster = rand01(rng);  // in startSubpath's order
    float uSelect = rand01(rng);
    vec2 uTri = rand2(rng);
    vec2 uDir = rand2(rng);
    LightSample ls;
    uint tri;
    vec3 w;
    float pdf;
    bool ok = sampleLtEmission(uCaster, uSelect, uTri, uDir, ls, tri, w, pdf);
    vec4 o[2] = vec4[2](vec4(ok ? barycentricsOf(tri, ls.p) : vec2(0.0), uintBitsToFloat(ok ? tri : ~0u), 0.0), vec4(w, pdf));
    for (uint k = 0u; k < 8u; ++k) outFloat[8u * i + k] = o[k / 4u][k % 4u];
    return;
  }
  if (function == kTriangle) {
    TriGeom g = triGeomAt(i);
    outFloat[2u * i] = g.v0.w;
    outFloat[2u * i + 1u] = 0.5 * length(cross(g.v1.xyz - g.v0.xyz, g.v2.xyz - g.v0.xyz));
    return;
  }
  // kIntegrate: point i / bins, bin i % bins; a midpoint rule over grid.z x grid.z equal solid angles.
  uint bins = grid.x * grid.y, bin = i % bins;
  vec4 rec = inRec[i / bins];
  uint tri = floatBitsToUint(rec.z);
  TriGeom g = triGeomAt(tri);
  vec3 y = (1.0 - rec.x - rec.y) * g.v0.xyz + rec.x * g.v1.xyz + rec.y * g.v2.xyz;
  vec3 n = normalize(cross(g.v1.xyz - g.v0.xyz, g.v2.xyz - g.v0.xyz));
  bool twoSided = (materialAt(floatBitsToUint(g.v0.w)).tex.z & kMatDoubleSided) != 0u;
  uint iz = bin / grid.y, iphi = bin % grid.y;
  float sum = 0.0;
  for (uint a = 0u; a < grid.z; ++a) {
    float z = -1.0 + 2.0 * (float(iz) + (float(a) + 0.5) / float(grid.z)) / float(grid.x);
    float r = sqrt(max(0.0, 1.0 - z * z));
    for (uint b = 0u; b < grid.z; ++b) {
      float phi = 2.0 * PI * (float(iphi) + (float(b) + 0.5) / float(grid.z)) / float(grid.y);
      sum += ltEmissionPdf(tri, y, n, twoSided, vec3(r * cos(phi), r * sin(phi), z));
    }
  }
  outFloat[i] = sum * (4.0 * PI / float(bins * grid.z * grid.z));
}
