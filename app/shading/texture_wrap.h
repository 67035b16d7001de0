// texture_wrap.h — texel coordinates wrapped into a texture (glTF sampler wrap modes); twins of
// glsl/lib/texture_wrap.glsl, same arithmetic (tests/gpu/twins_gpu_test.cpp).
#pragma once

namespace caustica {

// i mod n in [0, n), floored, through two float quotients and two corrections (no integer division on
// the GPU); equal to ((i % n) + n) % n for |i| <= 2^24 and 0 < n <= 2^20 (tests/shading/texture_wrap_test.cpp).
int floorMod(int i, int n);
// Texel index i wrapped into [0, n): mirrored repeat (taking precedence over repeat), repeat, or clamp.
int wrapCoord(int i, int n, bool repeat, bool mirror);

}  // namespace caustica
