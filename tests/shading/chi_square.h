// chi_square.h — Pearson's chi-square test for the sampler tests (tests/shading): the statistic over
// histogram bins and the limit it must stay under.
#pragma once
#include <cmath>
#include <cstddef>
#include <vector>

namespace caustica::test {

// Pearson chi-square statistic; bins expecting fewer than 5 counts are merged into one. dof: the
// degrees of freedom of what was summed (bins used - 1).
inline double chiSquare(const std::vector<double>& observed, const std::vector<double>& expected, int& dof) {
  double chi = 0, restO = 0, restE = 0;
  dof = -1;
  for (std::size_t i = 0; i < observed.size(); ++i) {
    if (expected[i] < 5.0) {
      restO += observed[i];
      restE += expected[i];
      continue;
    }
    chi += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
    ++dof;
  }
  if (restE >= 5.0) {
    chi += (restO - restE) * (restO - restE) / restE;
    ++dof;
  }
  return chi;
}

// Upper bound of the chi-square distribution at a very small significance (Wilson–Hilferty, z = 4.5:
// a false alarm about once in 300,000 runs).
inline double chiSquareLimit(int dof) {
  double k = dof, z = 4.5;
  double t = 1.0 - 2.0 / (9.0 * k) + z * std::sqrt(2.0 / (9.0 * k));
  return k * t * t * t;
}

// Upper-tail probability of the chi-square distribution with dof degrees of freedom at chi (Wilson–Hilferty
// normal approximation): the p-value the tests print.
inline double chiSquarePValue(double chi, int dof) {
  double k = dof, v = 2.0 / (9.0 * k);
  double z = (std::cbrt(chi / k) - (1.0 - v)) / std::sqrt(v);
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

}  // namespace caustica::test
