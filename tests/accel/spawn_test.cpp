// spawn_test.cpp — robust ray spawning (accel/spawn.h with the watertight intersectTriangle): rays
// leaving a hit point never re-hit its triangle, and offset origins lie on the intended side, for
// triangles of any size anywhere from 1e-8 to 1e8 (after pbrt-v4's Reintersect test).
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <random>

#include "accel/bvh.h"
#include "accel/intersect.h"
#include "accel/spawn.h"

using namespace caustica;

namespace {

// A random triangle whose size and distance from the origin are log-uniform over 1e-8..1e8.
struct RandomTriangle {
  glm::vec3 p[3];
};

RandomTriangle randomTriangle(std::mt19937& g) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), e(-8.0f, 8.0f);
  const float centreScale = std::pow(10.0f, e(g)), size = std::pow(10.0f, e(g));
  const glm::vec3 c = centreScale * glm::vec3(u(g), u(g), u(g));
  RandomTriangle t;
  for (auto& p : t.p) p = c + size * glm::vec3(u(g), u(g), u(g));
  return t;
}

glm::vec3 randomDirection(std::mt19937& g) {
  std::normal_distribution<float> n;
  for (;;) {
    glm::vec3 d(n(g), n(g), n(g));
    float l = glm::length(d);
    if (l > 1e-6f) return d / l;
  }
}

}  // namespace

TEST_CASE("reintersect: rays spawned from a hit never hit their own triangle (1000 triangles x 1000 rays)") {
  std::mt19937 g(2024);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  int triangles = 0, selfHits = 0, wrongSide = 0;
  while (triangles < 1000) {
    RandomTriangle t = randomTriangle(g);
    const glm::dvec3 nd = glm::cross(glm::dvec3(t.p[1]) - glm::dvec3(t.p[0]), glm::dvec3(t.p[2]) - glm::dvec3(t.p[0]));
    if (!(glm::length(nd) > 0.0)) continue;
    const glm::vec3 ng = glm::vec3(glm::normalize(nd));
    if (ng.x == 0.0f && ng.y == 0.0f && ng.z == 0.0f) continue;
    // A ray from far away hits the triangle somewhere inside it.
    float b1 = u01(g), b2 = u01(g);
    if (b1 + b2 > 1.0f) { b1 = 1.0f - b1; b2 = 1.0f - b2; }
    const glm::vec3 target = (1.0f - b1 - b2) * t.p[0] + b1 * t.p[1] + b2 * t.p[2];
    const glm::vec3 from = target + randomDirection(g) * (glm::length(target) + 10.0f * glm::length(t.p[1] - t.p[0]) + 1.0f);
    Ray ray{from, glm::normalize(target - from)};
    float th, uh, vh;
    if (!intersectTriangle(ray, t.p[0], t.p[1], t.p[2], std::numeric_limits<float>::infinity(), th, uh, vh)) continue;
    ++triangles;
    const float b0h = 1.0f - uh - vh;
    const glm::vec3 p = b0h * t.p[0] + uh * t.p[1] + vh * t.p[2];
    const glm::vec3 pError = hitPointError(b0h, uh, vh, t.p[0], t.p[1], t.p[2]);
    for (int k = 0; k < 1000; ++k) {
      const glm::vec3 w = randomDirection(g);
      const glm::vec3 n = glm::dot(w, ng) > 0.0f ? ng : -ng;
      const glm::vec3 o = offsetRayOrigin(p, pError, n);
      // The origin is strictly on the side the ray leaves into (exact plane test in double).
      const double side = glm::dot(glm::dvec3(o) - glm::dvec3(t.p[0]), glm::dvec3(n));
      if (!(side > 0.0)) ++wrongSide;
      float t2, u2, v2;
      if (intersectTriangle(Ray{o, w}, t.p[0], t.p[1], t.p[2], std::numeric_limits<float>::infinity(), t2, u2, v2))
        ++selfHits;
    }
  }
  CHECK(selfHits == 0);
  CHECK(wrongSide == 0);
}

TEST_CASE("spawn: error bounds scale with the coordinates, and float steps move the right way") {
  const glm::vec3 p0(1e5f, 0, 0), p1(1e5f, 1, 0), p2(1e5f, 0, 1);
  const glm::vec3 e = hitPointError(0.2f, 0.3f, 0.5f, p0, p1, p2);
  CHECK(e.x == doctest::Approx(gammaBound(7) * 1e5f));
  CHECK(e.x > 0.0f);
  const glm::vec3 tiny = hitPointError(0.2f, 0.3f, 0.5f, p0 * 1e-12f, p1 * 1e-12f, p2 * 1e-12f);
  CHECK(tiny.x < 1e-12f * e.x * 1.001f);
  for (float v : {-3.0f, -1e-30f, 0.0f, 1e-30f, 2.5f, 1e20f}) {
    CHECK(nextFloatUp(v) > v);
    CHECK(nextFloatDown(v) < v);
    CHECK(nextFloatUp(nextFloatDown(v)) == v);
  }
  CHECK(std::abs(gammaBound(3) / (3.0 * std::ldexp(1.0, -24)) - 1.0) < 1e-6);  // relative: the value is ~2e-7
}

