// oct_normal.glsl — unit normals stored in 32 bits (octahedral map, two 16-bit snorm values); the
// decoder of the TriShade words. Twin: app/shading/oct_normal.cpp (tests/gpu/twins_gpu_test.cpp).

// The unit normal of an octahedral word (packSnorm2x16); vec3(0) for kOctZeroNormal.
vec3 octDecode(uint w) {
  if (w == kOctZeroNormal) return vec3(0.0);
  vec2 p = unpackSnorm2x16(w);
  vec3 n = vec3(p, 1.0 - abs(p.x) - abs(p.y));
  float t = max(-n.z, 0.0);
  n.x += n.x >= 0.0 ? -t : t;
  n.y += n.y >= 0.0 ? -t : t;
  return normalize(n);
}

// The tangent of a TriShade tangent word (oct_normal.h's tangentWord): xyz unit, w the bitangent's
// sign (bit 0 set: -1); vec4(0) for kOctZeroNormal (none).
vec4 tangentDecode(uint w) {
  if (w == kOctZeroNormal) return vec4(0.0);
  return vec4(octDecode(w), (w & 1u) != 0u ? -1.0 : 1.0);
}
