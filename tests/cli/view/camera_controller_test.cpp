// camera_controller_test.cpp — properties of the viewer's orbit / pan / dolly / fly camera math:
// the target stays put when it should, image-space motion follows the cursor, limits hold.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include <glm/gtc/constants.hpp>

#include "cli/view/camera_controller.h"

using namespace caustica;

namespace {

// A camera 5 units in front of a unit box at the origin, looking down -Z (as glTF cameras do).
Camera frontCamera() {
  Camera c;
  c.position = {0.0f, 0.0f, 5.0f};
  c.forward = {0.0f, 0.0f, -1.0f};
  c.up = {0.0f, 1.0f, 0.0f};
  c.yfov = 0.8f;
  return c;
}

Bounds unitBox() {
  Bounds b;
  b.grow({-1.0f, -1.0f, -1.0f});
  b.grow({1.0f, 1.0f, 1.0f});
  return b;
}

// Pinhole projection of a world point, written independently of the controller: image position in
// fractions of the image height from the centre, x to the right, y downwards.
glm::vec2 project(const Camera& c, const glm::vec3& p) {
  glm::vec3 f = glm::normalize(c.forward);
  glm::vec3 r = glm::normalize(glm::cross(f, c.up));
  glm::vec3 u = glm::cross(r, f);
  glm::vec3 d = p - c.position;
  float depth = glm::dot(d, f);
  float h = 2.0f * std::tan(0.5f * c.yfov) * depth;  // image height at that depth
  return {glm::dot(d, r) / h, -glm::dot(d, u) / h};
}

float polar(const CameraController& cc) { return std::acos(glm::clamp(glm::dot(cc.camera().forward, cc.worldUp()), -1.0f, 1.0f)); }

void checkOrthonormal(const Camera& c) {
  CHECK(glm::length(c.forward) == doctest::Approx(1.0f).epsilon(1e-5));
  CHECK(glm::length(c.up) == doctest::Approx(1.0f).epsilon(1e-5));
  CHECK(std::abs(glm::dot(c.forward, c.up)) < 1e-5f);
  CHECK(std::isfinite(c.position.x));
  CHECK(std::isfinite(c.position.y));
  CHECK(std::isfinite(c.position.z));
}

void checkNear(const glm::vec3& a, const glm::vec3& b, float tol = 1e-4f) {
  CHECK(glm::length(a - b) < tol);
}

}  // namespace

TEST_CASE("camera controller: starts at the home camera with the target at the scene centre's depth") {
  CameraController cc(frontCamera(), unitBox());
  checkNear(cc.camera().position, frontCamera().position, 0.0f + 1e-7f);
  CHECK(cc.targetDistance() == doctest::Approx(5.0f));
  checkNear(cc.target(), glm::vec3(0.0f));
  CHECK(cc.sceneSize() == doctest::Approx(std::sqrt(12.0f)));
  checkNear(cc.worldUp(), glm::vec3(0, 1, 0), 1e-7f);
}

TEST_CASE("camera controller: world up is the axis nearest the camera's up even when pitched") {
  Camera c = frontCamera();
  c.forward = glm::normalize(glm::vec3(0.0f, -0.5f, -1.0f));
  c.up = glm::normalize(glm::cross(glm::cross(c.forward, glm::vec3(0, 1, 0)), c.forward));
  CameraController cc(c, unitBox());
  checkNear(cc.worldUp(), glm::vec3(0, 1, 0), 1e-7f);
  Camera z = frontCamera();
  z.position = {0, -5, 0};
  z.forward = {0, 1, 0};
  z.up = {0, 0, 1};  // a Z-up scene
  CameraController cz(z, unitBox());
  checkNear(cz.worldUp(), glm::vec3(0, 0, 1), 1e-7f);
}

TEST_CASE("camera controller: orbit keeps the target centred and the distance") {
  CameraController cc(frontCamera(), unitBox());
  glm::vec3 target = cc.target();
  std::uint64_t rev = cc.revision();
  cc.orbit(0.7f, 0.3f);
  CHECK(cc.revision() > rev);
  checkNear(cc.target(), target);
  CHECK(glm::length(cc.camera().position - target) == doctest::Approx(5.0f).epsilon(1e-5));
  glm::vec2 centre = project(cc.camera(), target);
  CHECK(std::abs(centre.x) < 1e-5f);
  CHECK(std::abs(centre.y) < 1e-5f);
  checkOrthonormal(cc.camera());
}

TEST_CASE("camera controller: orbit directions") {
  CameraController cc(frontCamera(), unitBox());
  cc.orbit(0.0f, 0.4f);  // raise the camera: it goes up and looks down at the target
  CHECK(cc.camera().position.y > 0.5f);
  CHECK(cc.camera().forward.y < -0.3f);
  CHECK(std::abs(cc.camera().position.x) < 1e-5f);
  CameraController cy(frontCamera(), unitBox());
  cy.orbit(glm::half_pi<float>(), 0.0f);  // a quarter turn counter-clockwise seen from above: +Z to +X
  checkNear(cy.camera().position, glm::vec3(5.0f, 0.0f, 0.0f));
  checkNear(cy.camera().forward, glm::vec3(-1.0f, 0.0f, 0.0f));
  checkNear(cy.camera().up, glm::vec3(0.0f, 1.0f, 0.0f));
}

TEST_CASE("camera controller: a full turn of yaw in small steps comes back") {
  CameraController cc(frontCamera(), unitBox());
  cc.orbit(0.0f, 0.25f);
  Camera before = cc.camera();
  for (int i = 0; i < 360; ++i) cc.orbit(glm::two_pi<float>() / 360.0f, 0.0f);
  checkNear(cc.camera().position, before.position, 1e-3f);
  checkNear(cc.camera().forward, before.forward, 1e-4f);
}

TEST_CASE("camera controller: pitch stops short of the poles and never flips the view") {
  for (float pitch : {10.0f, -10.0f, 1.5f, -1.5f}) {
    CAPTURE(pitch);
    CameraController cc(frontCamera(), unitBox());
    for (int i = 0; i < 5; ++i) cc.orbit(0.1f, pitch);
    float theta = polar(cc);
    CHECK(theta >= CameraController::kPoleMargin - 1e-4f);
    CHECK(theta <= glm::pi<float>() - CameraController::kPoleMargin + 1e-4f);
    CHECK(glm::dot(cc.camera().up, cc.worldUp()) > 0.0f);  // not upside down
    CHECK(glm::length(cc.camera().position - cc.target()) == doctest::Approx(5.0f).epsilon(1e-4));
    checkOrthonormal(cc.camera());
  }
  // Starting straight down at the pole, moving away is still possible.
  Camera down = frontCamera();
  down.position = {0, 5, 0};
  down.forward = {0, -1, 0};
  down.up = {0, 0, -1};
  CameraController cd(down, unitBox());
  float before = polar(cd);
  cd.orbit(0.0f, -0.3f);  // lower the camera: leaves the pole
  CHECK(polar(cd) < before - 0.2f);
  cd.reset();
  cd.orbit(0.0f, 0.3f);  // raise further: blocked
  CHECK(polar(cd) >= before - 1e-6f);
}

TEST_CASE("camera controller: pan moves the target point with the cursor") {
  CameraController cc(frontCamera(), unitBox());
  cc.orbit(0.5f, 0.2f);
  glm::vec3 oldTarget = cc.target();
  glm::vec3 forward = cc.camera().forward;
  cc.pan(0.1f, -0.05f);
  glm::vec2 p = project(cc.camera(), oldTarget);
  CHECK(p.x == doctest::Approx(0.1f).epsilon(1e-4));
  CHECK(p.y == doctest::Approx(-0.05f).epsilon(1e-4));
  checkNear(cc.camera().forward, forward, 1e-6f);
  CHECK(cc.targetDistance() == doctest::Approx(5.0f));
  checkNear(cc.target() - oldTarget, cc.camera().position - (oldTarget - forward * 5.0f), 1e-5f);
}

TEST_CASE("camera controller: dolly approaches the target and never passes it") {
  CameraController cc(frontCamera(), unitBox());
  glm::vec3 target = cc.target();
  cc.dolly(1.0f);
  CHECK(cc.targetDistance() < 5.0f);
  CHECK(cc.targetDistance() > 3.0f);
  checkNear(cc.target(), target);
  checkNear(cc.camera().forward, glm::vec3(0, 0, -1), 1e-6f);
  cc.dolly(-1.0f);
  CHECK(cc.targetDistance() == doctest::Approx(5.0f).epsilon(1e-5));
  cc.dolly(1000.0f);
  CHECK(cc.targetDistance() > 0.0f);
  CHECK(cc.camera().position.z > 0.0f);  // still in front of the target
  checkNear(cc.target(), target);
}

TEST_CASE("camera controller: fly look turns in place while move translates camera and target") {
  CameraController cc(frontCamera(), unitBox());
  glm::vec3 pos = cc.camera().position;
  cc.look(0.0f, 0.3f);  // look up
  checkNear(cc.camera().position, pos, 1e-6f);
  CHECK(cc.camera().forward.y == doctest::Approx(std::sin(0.3f)).epsilon(1e-4));
  cc.look(glm::half_pi<float>(), -0.3f);  // then turn left by a quarter and level out
  checkNear(cc.camera().forward, glm::vec3(-1, 0, 0), 1e-4f);
  checkNear(cc.camera().position, pos, 1e-6f);
  glm::vec3 target = cc.target();
  cc.move(0.0f, 0.0f, 2.0f);  // forward
  checkNear(cc.camera().position, pos + glm::vec3(-2, 0, 0), 1e-4f);
  checkNear(cc.target(), target + glm::vec3(-2, 0, 0), 1e-4f);
  cc.move(1.0f, 0.5f, 0.0f);  // right is -Z when looking down -X (Y up); up is world up
  checkNear(cc.camera().position, pos + glm::vec3(-2, 0.5f, -1.0f), 1e-4f);
}

TEST_CASE("camera controller: reset restores the home camera exactly after any motion") {
  CameraController cc(frontCamera(), unitBox());
  cc.orbit(1.0f, 0.5f);
  cc.pan(0.2f, 0.1f);
  cc.dolly(3.0f);
  cc.look(-0.4f, 0.2f);
  cc.move(1, 2, 3);
  std::uint64_t rev = cc.revision();
  cc.reset();
  CHECK(cc.revision() > rev);
  CHECK(cc.camera().position == frontCamera().position);
  CHECK(cc.camera().forward == frontCamera().forward);
  CHECK(cc.camera().up == frontCamera().up);
  CHECK(cc.camera().yfov == frontCamera().yfov);
  CHECK(cc.targetDistance() == doctest::Approx(5.0f));
}

TEST_CASE("camera controller: no motion means no change") {
  CameraController cc(frontCamera(), unitBox());
  std::uint64_t rev = cc.revision();
  cc.orbit(0, 0);
  cc.look(0, 0);
  cc.pan(0, 0);
  cc.dolly(0);
  cc.move(0, 0, 0);
  CHECK(cc.revision() == rev);
  CHECK(cc.camera().position == frontCamera().position);
}

TEST_CASE("camera controller: long random sequences stay orthonormal and finite within the limits") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  Camera tilted = frontCamera();
  tilted.up = glm::normalize(glm::vec3(0.2f, 1.0f, 0.0f));  // rolled camera
  CameraController cc(tilted, unitBox());
  for (int i = 0; i < 2000; ++i) {
    switch (i % 5) {
      case 0: cc.orbit(u(rng), 2.0f * u(rng)); break;
      case 1: cc.look(u(rng), 2.0f * u(rng)); break;
      case 2: cc.pan(u(rng), u(rng)); break;
      case 3: cc.dolly(3.0f * u(rng)); break;
      default: cc.move(u(rng), u(rng), u(rng)); break;
    }
  }
  checkOrthonormal(cc.camera());
  CHECK(polar(cc) >= CameraController::kPoleMargin - 1e-3f);
  CHECK(polar(cc) <= glm::pi<float>() - CameraController::kPoleMargin + 1e-3f);
  CHECK(cc.targetDistance() > 0.0f);
}
