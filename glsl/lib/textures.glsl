// textures.glsl — bilinear lookup of RGBA8 sRGB textures stored in one buffer, read as a buffer texture
// (see TexInfo in gpu_layout.h). Texels are decoded to linear before filtering. uv in glTF convention (v down).

vec3 srgbToLinear(vec3 c) {
  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}

#include "texture_wrap.glsl"  // wrapCoord

// srgb: colour textures (base colour, emission) are sRGB-encoded; data textures (metallicRoughness,
// normal) are linear and are read as stored.
vec4 fetchTexel(TexInfo info, int x, int y, bool srgb) {
  uint w = info.width, h = info.height;
  x = wrapCoord(x, int(w), (info.flags & 1u) != 0u, (info.flags & 4u) != 0u);
  y = wrapCoord(y, int(h), (info.flags & 2u) != 0u, (info.flags & 8u) != 0u);
  vec4 c = unpackUnorm4x8(texelFetch(texelWords, int(info.offset + uint(y) * w + uint(x))).x);
  return srgb ? vec4(srgbToLinear(c.rgb), c.a) : c;
}

vec4 sampleTextureAs(uint index, vec2 uv, bool srgb) {
  TexInfo info = texInfoAt(index);  // split_buffers.glsl
  uv = vec2(dot(info.uvRow0.xyz, vec3(uv, 1.0)), dot(info.uvRow1.xyz, vec3(uv, 1.0)));  // KHR_texture_transform
  // Keep the coordinate bounded before converting to int (huge uv would overflow).
  vec2 st = uv * vec2(float(info.width), float(info.height));
  st = clamp(st, vec2(-1.0e7), vec2(1.0e7));
  // Nearest filtering is the bilinear sum with zero weights on the neighbours (exact: mix(a, b, 0.0) = a
  // for finite texels), so both filters share one path: llvmpipe would run a separate nearest path too.
  bool nearest = (info.flags & 16u) != 0u;
  vec2 s0 = nearest ? st : st - 0.5;
  vec2 f = nearest ? vec2(0.0) : fract(s0);
  int x0 = int(floor(s0.x)), y0 = int(floor(s0.y));
  vec4 a = mix(fetchTexel(info, x0, y0, srgb), fetchTexel(info, x0 + 1, y0, srgb), f.x);
  vec4 b = mix(fetchTexel(info, x0, y0 + 1, srgb), fetchTexel(info, x0 + 1, y0 + 1, srgb), f.x);
  return mix(a, b, f.y);
}

// Linear RGB and alpha of colour texture `index` at uv (decoded from sRGB).
vec4 sampleTexture(uint index, vec2 uv) { return sampleTextureAs(index, uv, true); }

// The stored values of data texture `index` at uv, in [0, 1] (no sRGB decoding).
vec4 sampleDataTexture(uint index, vec2 uv) { return sampleTextureAs(index, uv, false); }
