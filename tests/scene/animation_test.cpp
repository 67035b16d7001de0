// animation_test.cpp — glTF animation against poses computed by hand (docs/animation.md): each
// interpolation (STEP, LINEAR, slerp along the shorter arc, CUBICSPLINE with its tangents), clamping
// outside the keys, the animated files of tests/data/animated (node TRS, an animated camera, choice of
// animation, morph weights, a two-joint skin with its normals, instanced and flat loads alike), a key
// time equal to the static file with that pose, and bad animations refused by name. No GL.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "scene/animation.h"
#include "scene/assets.h"
#include "scene/scene.h"
#include "util/error.h"

using namespace caustica;

namespace {

std::string animated(const std::string& name) { return sourceDir() + "/tests/data/animated/" + name; }

Scene load(const std::string& name, double time, const std::string& animation = "", bool instances = false) {
  LoadOptions o;
  o.keepInstances = instances;
  ScenePose pose;
  pose.time = time;
  pose.animation = animation;
  return loadScene(animated(name), o, pose);
}

// A rotation by `degrees` about a unit axis, written out (Rodrigues), not through a quaternion.
glm::dvec3 rotate(const glm::dvec3& v, const glm::dvec3& axis, double degrees) {
  const double a = degrees * 3.14159265358979323846 / 180.0, c = std::cos(a), s = std::sin(a);
  return v * c + glm::cross(axis, v) * s + axis * glm::dot(axis, v) * (1.0 - c);
}

// The unit cube's 36 corners as the loader stores its 12 triangles (make-animated-gltf's cube()).
std::vector<glm::dvec3> cubeCorners() {
  std::vector<glm::dvec3> out;
  for (int axis = 0; axis < 3; ++axis)
    for (double sign : {-1.0, 1.0}) {
      glm::dvec3 n(0.0), u(0.0), v(0.0);
      n[axis] = sign;
      u[(axis + 1) % 3] = 1.0;
      v[(axis + 2) % 3] = 1.0;
      const double ab[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
      glm::dvec3 q[4];
      for (int k = 0; k < 4; ++k) q[k] = 0.5 * (n + ab[k][0] * u + ab[k][1] * v);
      const int quad[6] = {0, 1, 2, 0, 2, 3}, flipped[6] = {0, 2, 1, 0, 3, 2};
      for (int k = 0; k < 6; ++k) out.push_back(q[sign > 0 ? quad[k] : flipped[k]]);
    }
  return out;
}

// Checks triangles [first, first + 12) of `s` against the cube placed by T * R(axis Y, degrees) * S.
void checkCube(const Scene& s, std::size_t first, const glm::dvec3& t, double degrees, double scale) {
  const std::vector<glm::dvec3> corners = cubeCorners();
  REQUIRE(s.triangles.size() >= first + 12);
  for (std::size_t i = 0; i < 36; ++i) {
    const glm::dvec3 expected = t + rotate(scale * corners[i], glm::dvec3(0, 1, 0), degrees);
    const glm::vec3 got = s.triangles[first + i / 3].p[i % 3];
    CAPTURE(i);
    CHECK(got.x == doctest::Approx(expected.x).epsilon(1e-6));
    CHECK(got.y == doctest::Approx(expected.y).epsilon(1e-6));
    CHECK(got.z == doctest::Approx(expected.z).epsilon(1e-6));
  }
}

void checkNear(const glm::vec3& got, const glm::dvec3& expected, double tolerance = 1e-6) {
  CHECK(got.x == doctest::Approx(expected.x).epsilon(tolerance));
  CHECK(got.y == doctest::Approx(expected.y).epsilon(tolerance));
  CHECK(got.z == doctest::Approx(expected.z).epsilon(tolerance));
}

// The corner of `s`'s triangles [first, first + count) nearest to `p` (the tests find vertices by place).
glm::vec3 vertexNear(const Scene& s, std::size_t first, std::size_t count, const glm::dvec3& p, glm::vec3* normal = nullptr) {
  double best = 1e30;
  glm::vec3 out(0.0f);
  for (std::size_t t = first; t < first + count; ++t)
    for (int k = 0; k < 3; ++k) {
      const double d = glm::length(glm::dvec3(s.triangles[t].p[k]) - p);
      if (d < best) {
        best = d;
        out = s.triangles[t].p[k];
        if (normal) *normal = s.triangles[t].normal(k);
      }
    }
  return out;
}

}  // namespace

TEST_CASE("animation: each interpolation against values computed by hand") {
  KeyframeCurve c;
  c.times = {1.0, 2.0, 4.0};
  c.values = {0.0, 10.0, 20.0, 30.0, 40.0, 60.0};  // two components a key
  c.components = 2;
  c.interpolation = Interpolation::Linear;
  CHECK(sampleCurve(c, 0.0) == std::vector<double>{0.0, 10.0});    // before the first key: the first
  CHECK(sampleCurve(c, 1.5) == std::vector<double>{10.0, 20.0});
  CHECK(sampleCurve(c, 3.0) == std::vector<double>{30.0, 45.0});   // half way through a 2-second interval
  CHECK(sampleCurve(c, 9.0) == std::vector<double>{40.0, 60.0});   // after the last: the last
  c.interpolation = Interpolation::Step;
  CHECK(sampleCurve(c, 1.99) == std::vector<double>{0.0, 10.0});
  CHECK(sampleCurve(c, 2.0) == std::vector<double>{20.0, 30.0});   // a key holds from its own time
  CHECK(sampleCurve(c, 3.99) == std::vector<double>{20.0, 30.0});

  // CUBICSPLINE, one component: keys (t, value, in-tangent, out-tangent) = (0, 1, -, 3), (2, 5, -1, -).
  KeyframeCurve h;
  h.times = {0.0, 2.0};
  h.values = {0.0, 1.0, 3.0, -1.0, 5.0, 0.0};  // in, value, out for each key
  h.components = 1;
  h.interpolation = Interpolation::CubicSpline;
  // p(s) = (2s^3 - 3s^2 + 1) 1 + 2 (s^3 - 2s^2 + s) 3 + (-2s^3 + 3s^2) 5 + 2 (s^3 - s^2) (-1), s = t / 2.
  for (double t : {0.0, 0.25, 0.5, 1.0, 1.5, 2.0}) {
    const double s = t / 2.0;
    const double p = (2 * s * s * s - 3 * s * s + 1) * 1.0 + 2.0 * (s * s * s - 2 * s * s + s) * 3.0 +
                     (-2 * s * s * s + 3 * s * s) * 5.0 + 2.0 * (s * s * s - s * s) * -1.0;
    CAPTURE(t);
    CHECK(sampleCurve(h, t)[0] == doctest::Approx(p).epsilon(1e-12));
  }
  // Its slope at the keys is the tangent given (units per second), not per interval.
  CHECK((sampleCurve(h, 1e-6)[0] - 1.0) / 1e-6 == doctest::Approx(3.0).epsilon(1e-4));
  CHECK((5.0 - sampleCurve(h, 2.0 - 1e-6)[0]) / 1e-6 == doctest::Approx(-1.0).epsilon(1e-4));
}

TEST_CASE("animation: rotations slerp along the shorter arc and stay unit") {
  const double c30 = std::cos(3.14159265358979323846 / 12), s30 = std::sin(3.14159265358979323846 / 12);
  KeyframeCurve r;
  r.times = {0.0, 1.0};
  r.components = 4;
  r.rotation = true;
  r.interpolation = Interpolation::Linear;
  // Identity to 60 degrees about +Z, the second key stored as -q: the shorter arc passes 30 degrees.
  const double h = std::sin(3.14159265358979323846 / 6), k = std::cos(3.14159265358979323846 / 6);
  r.values = {0, 0, 0, 1, 0, 0, -h, -k};
  std::vector<double> q = sampleCurve(r, 0.5);
  const double sign = q[3] < 0 ? -1.0 : 1.0;
  CHECK(sign * q[2] == doctest::Approx(s30).epsilon(1e-12));  // sin(15 deg): half the 30-degree rotation
  CHECK(sign * q[3] == doctest::Approx(c30).epsilon(1e-12));
  CHECK(q[0] == 0.0);
  // A quarter of the way: 15 degrees (slerp keeps a constant angular speed, unlike a normalised lerp).
  q = sampleCurve(r, 0.25);
  const double quarter = std::atan2(std::abs(q[2]), std::abs(q[3])) * 2.0 * 180.0 / 3.14159265358979323846;
  CHECK(quarter == doctest::Approx(15.0).epsilon(1e-9));
  // CUBICSPLINE rotations are normalised.
  r.interpolation = Interpolation::CubicSpline;
  r.values = {0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, h, k, 0, 0, 0, 0};
  q = sampleCurve(r, 0.5);
  CHECK(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] == doctest::Approx(1.0).epsilon(1e-12));
  // glm's quaternion slerp agrees with slerpShortest where both take the short way.
  const glm::dquat a(1, 0, 0, 0), b(k, 0, 0, h);
  const glm::dquat m = slerpShortest(a, b, 0.5);
  CHECK(m.w == doctest::Approx(c30).epsilon(1e-12));
}

TEST_CASE("animation: trs.gltf's nodes and camera at several times, against T * R * S by hand") {
  // Triangles in node order: floor (2), cube (12), box (12). Animation "move" (make-animated-gltf).
  {
    const Scene s = load("trs.gltf", 0.5);
    REQUIRE(s.triangles.size() == 26);
    REQUIRE(s.animations.size() == 2);
    CHECK(s.animations[0].name == "move");
    CHECK(s.animations[0].end == 2.0);
    CHECK(s.animations[1].end == 0.5);
    CHECK(s.animationsPlayed == std::vector<int>{0});
    // Linear translation half way from (-1, .5, 0) to (1, .5, 0); slerp: 30 deg of the 60 to key 1
    // (stored as -q); scale STEP: still 1.
    checkCube(s, 2, {0.0, 0.5, 0.0}, 30.0, 1.0);
    // Cubic spline, s = 1/4, d = 2: p = h00 v0 + d h10 b0 + h01 v1 + d h11 a1 per axis.
    const double t = 0.25, h00 = 2 * t * t * t - 3 * t * t + 1, h10 = t * t * t - 2 * t * t + t,
                 h01 = -2 * t * t * t + 3 * t * t, h11 = t * t * t - t * t;
    const glm::dvec3 box = h00 * glm::dvec3(0, 0.5, -1.5) + 2.0 * h10 * glm::dvec3(1, 2, 0) +
                           h01 * glm::dvec3(2, 0.5, -1.5) + 2.0 * h11 * glm::dvec3(1, -2, 0);
    checkCube(s, 14, box, 0.0, 1.0);
    REQUIRE(s.cameras.size() == 1);  // linear from (0, 1.5, 6) to (0.5, 1.5, 5)
    checkNear(s.cameras[0].position, {0.125, 1.5, 5.75});
    checkNear(s.cameras[0].forward, {0.0, 0.0, -1.0});
  }
  {
    // t = 1.5: translation half way from (1, .5, 0) to (1, 1.5, 0); slerp half way from 60 (as -q) to
    // 120 deg: 90; scale STEP reaches its second key (0.5) exactly at 1.5.
    const Scene s = load("trs.gltf", 1.5);
    checkCube(s, 2, {1.0, 1.0, 0.0}, 90.0, 0.5);
  }
  // Outside the keys: the first and the last pose.
  checkCube(load("trs.gltf", -3.0), 2, {-1.0, 0.5, 0.0}, 0.0, 1.0);
  checkCube(load("trs.gltf", 7.0), 2, {1.0, 1.5, 0.0}, 120.0, 0.5);
  checkCube(load("trs.gltf", 7.0), 14, {2.0, 0.5, -1.5}, 0.0, 1.0);
  {
    // Animation "spin" (by name, and by index): only the box turns (STEP to 90 deg at 0.5 s); the cube
    // keeps its node's own pose and the camera its node's place.
    for (const char* which : {"spin", "1"}) {
      const Scene s = load("trs.gltf", 0.75, which);
      CHECK(s.animationsPlayed == std::vector<int>{1});
      checkCube(s, 2, {-1.0, 0.5, 0.0}, 0.0, 1.0);
      checkCube(s, 14, {0.0, 0.5, -1.5}, 90.0, 1.0);
      checkNear(s.cameras[0].position, {0.0, 1.5, 6.0});
    }
    // "all": both at once; where both animate the box's translation the later animation ("spin", which
    // holds it at its node's value) wins over "move"'s spline.
    const Scene s = load("trs.gltf", 0.75, "all");
    CHECK(s.animationsPlayed == std::vector<int>{0, 1});
    checkCube(s, 14, {0.0, 0.5, -1.5}, 90.0, 1.0);
    checkCube(s, 2, {0.5, 0.5, 0.0}, 45.0, 1.0);  // the cube follows "move" (3/4 of the way to key 1)
  }
  CHECK_THROWS_WITH_AS(load("trs.gltf", 0.0, "walk"),
                       doctest::Contains("trs.gltf: --animation walk: no such animation (the file has 2: 0 'move', 1 'spin'; or 'all')"),
                       Error);
  CHECK_THROWS_WITH_AS(load("trs.gltf", 0.0, "2"), doctest::Contains("no such animation"), Error);
}

TEST_CASE("animation: by default every animation plays when none animates what another does") {
  // split.gltf: one motion written as one animation per node (as COLLADA2GLTF writes them).
  const Scene both = load("split.gltf", 0.5);
  CHECK(both.animationsPlayed == std::vector<int>{0, 1});
  checkCube(both, 0, {-1.5, 0.5, 0.0}, 0.0, 1.0);
  checkCube(both, 12, {1.5, 0.5, 0.0}, 0.0, 1.0);
  const Scene first = load("split.gltf", 0.5, "0");
  CHECK(first.animationsPlayed == std::vector<int>{0});
  checkCube(first, 12, {1.0, 0.5, 0.0}, 0.0, 1.0);  // "b" does not play: its node's own place
  // trs.gltf's "move" and "spin" both animate the box's translation: alternatives, the first plays.
  CHECK(load("trs.gltf", 0.5).animationsPlayed == std::vector<int>{0});
}

TEST_CASE("animation: a key time equals the static file with that pose, bit for bit") {
  // trs-at-1.gltf and morph-at-1.gltf hold the poses at t = 1 s in node TRS and vertices (exact values).
  for (const char* name : {"trs", "morph"}) {
    CAPTURE(name);
    const Scene a = load(std::string(name) + ".gltf", 1.0);
    const Scene b = loadScene(animated(std::string(name) + "-at-1.gltf"));
    REQUIRE(a.triangles.size() == b.triangles.size());
    for (std::size_t i = 0; i < a.triangles.size(); ++i) {
      CAPTURE(i);
      for (int k = 0; k < 3; ++k) {
        CHECK(a.triangles[i].p[k] == b.triangles[i].p[k]);
        CHECK(a.triangles[i].normalWord[k] == b.triangles[i].normalWord[k]);
      }
    }
    REQUIRE(a.cameras.size() == 1);
    CHECK(a.cameras[0].position == b.cameras[0].position);
    CHECK(a.cameras[0].forward == b.cameras[0].forward);
  }
}

TEST_CASE("animation: posed animations, skins and morph targets are not named in the 'not rendered' line") {
  for (const char* name : {"trs.gltf", "morph.gltf", "skin.gltf"}) {
    CAPTURE(std::string(name));
    const Scene s = load(name, 0.5);
    for (const std::string& w : s.warnings) {
      CAPTURE(w);
      CHECK(w.find("not rendered") == std::string::npos);
    }
  }
}

TEST_CASE("animation: morph-target weights blend positions and normals") {
  // Triangles: floor (2), then the strip (4). Weights go linearly from (0, 0) to (1, 0.5) over 0..1 s.
  const Scene s = load("morph.gltf", 0.5);  // weights (0.5, 0.25)
  REQUIRE(s.triangles.size() == 6);
  // Top-left vertex (-0.5, 2, 0): + 0.5 (0, 1, 0) + 0.25 (0.5, 0, 0), then the node's (0, 0, -0.5).
  glm::vec3 n;
  checkNear(vertexNear(s, 2, 4, {-0.375, 2.5, -0.5}, &n), {-0.375, 2.5, -0.5});
  checkNear(n, glm::normalize(glm::dvec3(0.0, 0.25, 1.0)), 1e-4);  // (0, 0, 1) + 0.5 (0, 0.5, 0), normalised
  // The bottom row moves with target 1 only.
  checkNear(vertexNear(s, 2, 4, {0.625, 0.0, -0.5}, &n), {0.625, 0.0, -0.5});
  checkNear(n, {0.0, 0.0, 1.0}, 1e-4);
  // At t = 0 the base shape (weights 0): exactly the file's vertices.
  const Scene base = load("morph.gltf", 0.0);
  CHECK(vertexNear(base, 2, 4, {-0.5, 2.0, -0.5}) == glm::vec3(-0.5f, 2.0f, -0.5f));
}

TEST_CASE("animation: a two-joint skin bends the strip, normals included; the mesh node's transform is ignored") {
  // The tip joint turns about +X by 90 deg over 0..1 s. Rows: y = 0 on the root, y = 1 half and half,
  // y = 2 on the tip; joint matrix of the tip: T(0, 1, 0) Rx(a) T(0, -1, 0).
  for (double t : {0.0, 0.5, 1.0}) {
    CAPTURE(t);
    const double a = 90.0 * t;
    const Scene s = load("skin.gltf", t);
    REQUIRE(s.triangles.size() == 6);
    auto tip = [&](const glm::dvec3& v) { return glm::dvec3(0, 1, 0) + rotate(v - glm::dvec3(0, 1, 0), {1, 0, 0}, a); };
    for (double x : {-0.25, 0.25}) {
      glm::vec3 n;
      // Root row: unmoved (and not moved by the node's translation (5, 0, 0)).
      checkNear(vertexNear(s, 2, 4, {x, 0, 0}, &n), {x, 0, 0});
      checkNear(n, {0, 0, 1}, 1e-4);
      // Tip row: the tip joint's rotation; the normal turns with it.
      const glm::dvec3 top = tip({x, 2, 0});
      checkNear(vertexNear(s, 2, 4, top, &n), top);
      checkNear(n, rotate({0, 0, 1}, {1, 0, 0}, a), 1e-4);
      // Middle row: half of each joint matrix; (I + Rx(a)) / 2 turns normals by a / 2.
      const glm::dvec3 mid = 0.5 * glm::dvec3(x, 1, 0) + 0.5 * tip({x, 1, 0});
      checkNear(vertexNear(s, 2, 4, mid, &n), mid);
      checkNear(n, rotate({0, 0, 1}, {1, 0, 0}, a / 2), 1e-4);
    }
  }
  CHECK(load("skin.gltf", 0.5).animations.at(0).skins);
}

TEST_CASE("animation: instanced loads pose like flat ones (posed meshes are stored once per placement)") {
  for (const char* name : {"trs.gltf", "morph.gltf", "skin.gltf"}) {
    CAPTURE(name);
    const Scene flat = load(name, 0.6);
    Scene inst = load(name, 0.6, "", true);
    CHECK_FALSE(inst.instances.empty());
    flattenInstances(inst);
    REQUIRE(inst.triangles.size() == flat.triangles.size());
    for (std::size_t i = 0; i < flat.triangles.size(); ++i)
      for (int k = 0; k < 3; ++k) checkNear(inst.triangles[i].p[k], glm::dvec3(flat.triangles[i].p[k]), 1e-6);
  }
}
