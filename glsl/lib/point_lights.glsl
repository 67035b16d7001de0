// point_lights.glsl — the point lights of the raster and Whitted modes (PointLights UBO, gpu_layout.h):
// emissive triangles grouped at their power-weighted centres (app/scene/light_groups.h).
// Include gpu_layout.h first (bindings.glsl does).
#include "punctual.glsl"  // spotFalloff (its UBO only under CAUSTICA_PUNCTUAL)

layout(std140, binding = CAUSTICA_BINDING_POINT_LIGHTS) uniform PointLightBlock { PointLights pointLights; };

// Radiant intensity (W sr^-1 per channel) of light l towards unit direction w leaving it.
vec3 pointLightIntensity(PointLight l, vec3 w) {
  if (l.cone.z > 0.5) return l.intensity.rgb * spotFalloff(dot(l.axis.xyz, w), l.cone.x, l.cone.y);
  return l.intensity.rgb * (max(0.0, dot(l.axis.xyz, w)) + l.position.w);
}

// The roughness that sets a material's Phong highlight: its own where it has a specular layer (glTF
// dielectrics, Material.specular.w = F90 > 0), else 1 (no highlight: a purely Lambertian base).
float phongRoughness(Material m) { return m.specular.w > 0.0 ? m.params.y : 1.0; }

// Phong BRDF of a material at a diffuse vertex (per steradian): Lambert base / pi plus a normalised
// Blinn-Phong highlight (Fresnel 0.04 of a dielectric) whose exponent follows the roughness; rough 1: none.
vec3 phongBrdf(vec3 base, float roughness, vec3 n, vec3 wl, vec3 wv) {
  vec3 f = base * 0.31830988618379067154;
  if (roughness < 1.0) {
    float shininess = min(2.0 / max(roughness * roughness, 1.0e-4) - 2.0, 4096.0);
    vec3 h = normalize(wl + wv);
    f += vec3(0.04 * (shininess + 8.0) / (8.0 * 3.14159265358979323846) * pow(max(dot(n, h), 0.0), shininess));
  }
  return f;
}
