// texture_wrap.cpp — twin of glsl/lib/texture_wrap.glsl.
#include "shading/texture_wrap.h"

#include <algorithm>
#include <cmath>

namespace caustica {

int floorMod(int i, int n) {
  const float fn = static_cast<float>(n);
  int m = i - n * static_cast<int>(std::floor(static_cast<float>(i) / fn));
  m -= n * static_cast<int>(std::floor(static_cast<float>(m) / fn));
  m += m < 0 ? n : 0;
  m -= m >= n ? n : 0;
  return m;
}

int wrapCoord(int i, int n, bool repeat, bool mirror) {
  if (!repeat && !mirror) return std::clamp(i, 0, n - 1);
  const int period = mirror ? 2 * n : n;
  const int m = floorMod(i, period);
  return mirror && m >= n ? period - 1 - m : m;
}

}  // namespace caustica
