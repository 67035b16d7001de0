// image_compare.cpp — test helper: compares two linear images (.exr/.pfm) pixel by pixel.
// Exit 0 when they have the same size, carry signal and agree within float rounding; 1 otherwise.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "util/error.h"
#include "image/image_io.h"

int main(int argc, char** argv) {
  if (argc < 3 || argc > 4) {
    std::fprintf(stderr, "usage: viewer_image_compare A.exr B.exr [RELATIVE_TOLERANCE (default 1e-4)]\n");
    return 2;
  }
  double tolerance = argc == 4 ? std::atof(argv[3]) : 1e-4;
  try {
    caustica::Image a = caustica::readImage(argv[1]), b = caustica::readImage(argv[2]);
    if (a.width != b.width || a.height != b.height) {
      std::printf("sizes differ: %dx%d vs %dx%d\n", a.width, a.height, b.width, b.height);
      return 1;
    }
    // Radiance values: the tolerance is relative to the larger magnitude, with an absolute floor of
    // `tolerance` for values near zero (sums of the same samples in another order differ by rounding).
    double maxAbs = 0.0, meanA = 0.0, meanB = 0.0;
    size_t bad = 0, nonFinite = 0;
    for (size_t i = 0; i < a.rgb.size(); ++i) {
      double x = a.rgb[i], y = b.rgb[i];
      if (!std::isfinite(x) || !std::isfinite(y)) {
        ++nonFinite;
        continue;
      }
      double d = std::abs(x - y);
      maxAbs = std::max(maxAbs, d);
      if (d > tolerance * (1.0 + std::max(std::abs(x), std::abs(y)))) ++bad;
      meanA += x;
      meanB += y;
    }
    meanA /= static_cast<double>(a.rgb.size());
    meanB /= static_cast<double>(b.rgb.size());
    std::printf("%dx%d: mean %.6g vs %.6g, max |a-b| %.3g, %zu of %zu values beyond tolerance %.3g, %zu non-finite\n",
                a.width, a.height, meanA, meanB, maxAbs, bad, a.rgb.size(), tolerance, nonFinite);
    if (!(meanA > 1e-6) || !(meanB > 1e-6)) {
      std::printf("an image is black: nothing was compared\n");
      return 1;
    }
    return bad == 0 && nonFinite == 0 ? 0 : 1;
  } catch (const caustica::Error& e) {
    std::printf("error: %s\n", e.what());
    return 2;
  }
}
