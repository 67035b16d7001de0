// oct_normal_test.cpp — octahedral normals (app/shading/oct_normal.*): the angle between a unit vector
// and its decoded word over many directions, the octants' seams and poles, and the zero-normal word.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "shading/oct_normal.h"
#include "shared/gpu_layout.h"

using namespace caustica;

TEST_CASE("octahedral normals: decoded within 5e-5 rad of the input, unit length, zero kept") {
  std::mt19937 rng(7);
  std::normal_distribution<float> g(0.0f, 1.0f);
  double worst = 0.0, sum = 0.0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    glm::vec3 v(g(rng), g(rng), g(rng));
    if (glm::length(v) < 1e-3f) continue;
    v = glm::normalize(v);
    const glm::vec3 d = octDecode(octEncode(v));
    CHECK(std::fabs(glm::length(d) - 1.0f) < 1e-6f);
    const double angle = std::atan2(double(glm::length(glm::cross(v, d))), double(glm::dot(v, d)));
    worst = std::max(worst, angle);
    sum += angle;
  }
  MESSAGE("octahedral normals: worst " << worst << " rad, mean " << sum / n << " rad");
  // Measured: worst 4.3e-5 rad, mean 2.1e-5 rad (16-bit snorm per coordinate: grid step 3e-5 of the
  // square). Rounding each coordinate to the nearest grid point, without octEncode's search of the four
  // around it, gives worst 6.4e-5 rad (and 1.25e-4 when that search compared float dot products), which fails.
  CHECK(worst < 5e-5);
  CHECK(sum / n < 2.5e-5);
  for (glm::vec3 v : {glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::vec3(1, 0, 0), glm::vec3(0, -1, 0),
                      glm::vec3(1, 1, -1), glm::vec3(-1, 1e-7f, -1e-7f)}) {
    CAPTURE(v);
    const glm::vec3 d = octDecode(octEncode(v));
    CHECK(glm::dot(d, glm::normalize(v)) > 0.0f);
    CHECK(glm::length(glm::cross(d, glm::normalize(v))) < 5e-5f);
  }
  CHECK(octEncode(glm::vec3(0.0f)) == gpu::kOctZeroNormal);
  CHECK(octEncode(glm::vec3(NAN, 0.0f, 1.0f)) == gpu::kOctZeroNormal);
  CHECK(octDecode(gpu::kOctZeroNormal) == glm::vec3(0.0f));
}
