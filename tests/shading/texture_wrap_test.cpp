// texture_wrap_test.cpp — floorMod and wrapCoord (app/shading/texture_wrap.*, twins of
// glsl/lib/texture_wrap.glsl) against integer arithmetic: every i near the multiples of n, the extremes
// of the clamped texel coordinate (+-1e7 + 1) and random values, for small and large n (up to the claimed 2^20).
#include <doctest/doctest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "shading/texture_wrap.h"

using namespace caustica;

namespace {
int intMod(int i, int n) { return ((i % n) + n) % n; }
int intWrap(int i, int n, bool repeat, bool mirror) {  // the former integer-division wrapCoord
  if (mirror) {
    const int period = 2 * n, m = intMod(i, period);
    return m < n ? m : period - 1 - m;
  }
  if (repeat) return intMod(i, n);
  return std::clamp(i, 0, n - 1);
}
}  // namespace

TEST_CASE("floorMod and wrapCoord equal the integer-division forms, also at the multiples and the extremes") {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> any(-10000001, 10000001);
  int checked = 0, wrong = 0;
  for (int n : {1, 2, 3, 7, 64, 255, 256, 1000, 1023, 4096, 16383, 16384, (1 << 19) + 1, (1 << 20) - 1, 1 << 20}) {
    std::vector<int> is = {0, -1, 1, 10000001, -10000001, 10000000, -10000000, 9999999, -9999999};
    for (int k = -40; k <= 40; ++k)
      for (int d = -2; d <= 2; ++d) is.push_back(k * n + d);
    for (int k : {1000, 9999, 10000000 / n})
      for (int d = -2; d <= 2; ++d) is.push_back(k * n + d), is.push_back(-k * n + d);
    for (int r = 0; r < 20000; ++r) is.push_back(any(rng));
    for (int i : is) {
      if (i > 10000001 || i < -10000001) continue;
      ++checked;
      wrong += floorMod(i, n) != intMod(i, n);
      for (int mode = 0; mode < 3; ++mode) wrong += wrapCoord(i, n, mode == 1, mode == 2) != intWrap(i, n, mode == 1, mode == 2);
    }
  }
  MESSAGE(checked, " coordinates checked");
  CHECK(wrong == 0);
}
