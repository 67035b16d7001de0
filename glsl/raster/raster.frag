// raster.frag — fragment stage of the raster mode: emission plus Blinn-Phong shading from the point
// lights (point_lights.glsl) with omnidirectional shadow maps (one depth cube per light holding the
// distance to the nearest occluder / far). Linear radiance out; alpha is coverage (blending).
#include "../shared/gpu_layout.h"
#include "../lib/point_lights.glsl"

in vec3 vPosition;
in vec3 vNormal;
in vec2 vUv;
in vec3 vGeomNormal;
in vec4 vColor;

layout(location = 2) uniform vec3 eye;          // world-space eye (mirrored for a mirror pass)
layout(location = 3) uniform vec4 baseColor;    // rgb: linear base colour; a: opacity
layout(location = 4) uniform vec4 emission;     // rgb: emitted radiance; w: 1 if double-sided
layout(location = 5) uniform vec4 params;       // x: metallic, y: roughness, z: transmission, w: ior
layout(location = 6) uniform int hasTexture;    // 1: base colour texture on unit 0
layout(location = 7) uniform int planarMirror;  // 1: this surface's reflection is drawn by a mirror pass
layout(location = 8) uniform float shadowTexels; // side of a shadow cube face in texels
layout(location = 9) uniform int vertexAlpha;   // 1: the vertex colour's alpha multiplies the opacity (BLEND, MASK)
layout(location = 10) uniform int vertexColors; // 1: the scene has vertex colours (else vColor, interpolated white, is not read)

layout(binding = 0) uniform sampler2D baseTexture;          // sRGB texture: sampled as linear
layout(binding = 1) uniform samplerCubeArray shadowMaps;    // layer = light index; distance / far

layout(location = 0) out vec4 outColor;

// 1 if the point p (unit geometric normal ng facing the light) sees light i, else 0.
float shadowVisibility(uint i, vec3 p, vec3 ng, float dist) {
  PointLight l = pointLights.light[i];
  // Normal offset of about one and a half shadow texels (a face spans 90 degrees: 2 * dist / texels)
  // and a 1 % depth bias keep surfaces from shadowing themselves.
  vec3 q = p + ng * (3.0 * dist / shadowTexels);
  vec3 d = q - l.position.xyz;
  float stored = texture(shadowMaps, vec4(d, float(i))).r * l.intensity.w;
  return length(d) <= stored * 1.01 + 1.0e-6 * l.intensity.w ? 1.0 : 0.0;
}

void main() {
  vec3 v = normalize(eye - vPosition);
  vec3 ngFront = normalize(vGeomNormal);
  bool front = dot(v, ngFront) >= 0.0;
  vec3 ng = front ? ngFront : -ngFront;
  vec3 ns = normalize(vNormal);
  if (!(dot(ns, ns) > 0.5)) ns = ngFront;
  if (dot(ns, ngFront) < 0.0) ns = -ns;
  if (!front) ns = -ns;

  vec4 base = baseColor;
  if (vertexColors != 0) {  // COLOR_0
    base.rgb *= vColor.rgb;
    if (vertexAlpha != 0) base.a *= vColor.a;
  }
  if (hasTexture != 0) base.rgb *= texture(baseTexture, vUv).rgb;
  float metal = params.x, trans = params.z;
  float diffuseWeight = (1.0 - metal) * (1.0 - trans);
  // Smooth metal and glass: a highlight stands in for the reflection of the lights (none where a
  // mirror pass draws the real reflection).
  vec3 highlight = (planarMirror != 0 ? 0.0 : metal) * base.rgb + vec3((1.0 - metal) * trans * 0.04);
  float shininess = min(2.0 / max(params.y * params.y, 1.0e-4) - 2.0, 256.0);

  vec3 color = (front || emission.w > 0.0) ? emission.rgb : vec3(0.0);
  for (uint i = 0u; i < pointLights.count.x; ++i) {
    PointLight l = pointLights.light[i];
    vec3 toLight = l.position.xyz - vPosition;
    float dist2 = dot(toLight, toLight);
    if (!(dist2 > 0.0)) continue;
    float dist = sqrt(dist2);
    vec3 wl = toLight / dist;
    float cosSurf = dot(ns, wl);
    if (cosSurf <= 0.0 || dot(ng, wl) <= 0.0) continue;
    float visible = shadowVisibility(i, vPosition, ng, dist);
    if (visible == 0.0) continue;
    vec3 e = pointLightIntensity(l, -wl) * (cosSurf / dist2);  // irradiance
    vec3 f = diffuseWeight * phongBrdf(base.rgb, params.y, ns, wl, v);
    vec3 h = normalize(wl + v);
    f += highlight * ((shininess + 8.0) / (8.0 * 3.14159265358979323846) * pow(max(dot(ns, h), 0.0), shininess));
    color += f * e;
  }
  // Transparency by blending (premultiplied): glass lets (1 - coverage) of what lies behind through.
  float coverage = base.a * (1.0 - 0.85 * (1.0 - metal) * trans);
  outColor = vec4(color * base.a, coverage);
}
