// camera_controller.cpp — orbit / pan / dolly / fly camera motion for the viewer (no GL, no window).
// All vectors are world space; lengths in scene units; angles in radians.
#include "cli/view/camera_controller.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>

namespace caustica {

namespace {

// Rodrigues rotation of v about the unit axis a by `angle` (right-handed).
glm::vec3 rotateAbout(const glm::vec3& v, const glm::vec3& a, float angle) {
  float c = std::cos(angle), s = std::sin(angle);
  return v * c + glm::cross(a, v) * s + a * glm::dot(a, v) * (1.0f - c);
}

// Angle between the view direction and the world up axis: 0 looks straight up, pi straight down.
float polarAngle(const glm::vec3& forward, const glm::vec3& up) {
  return std::acos(std::clamp(glm::dot(forward, up), -1.0f, 1.0f));
}

}  // namespace

CameraController::CameraController(const Camera& home, const Bounds& bounds) : home_(home) {
  // Guard against cameras that are not exactly orthonormal.
  camera_ = home_;
  orthonormalize();
  home_ = camera_;
  // World up: the coordinate axis nearest the home camera's up vector (glTF scenes are Y-up).
  glm::vec3 a = glm::abs(home_.up);
  int axis = a.x > a.y && a.x > a.z ? 0 : (a.y >= a.z ? 1 : 2);
  worldUp_ = glm::vec3(0.0f);
  worldUp_[axis] = home_.up[axis] < 0.0f ? -1.0f : 1.0f;
  if (!bounds.empty()) {
    glm::vec3 diag = bounds.max - bounds.min;
    sceneSize_ = std::max(glm::length(diag), 1e-6f);
    glm::vec3 centre = 0.5f * (bounds.min + bounds.max);
    // Target on the view axis at the depth of the scene centre (or a little ahead if it is behind).
    homeDistance_ = std::max(glm::dot(centre - home_.position, home_.forward), 0.05f * sceneSize_);
  }
  distance_ = homeDistance_;
}

void CameraController::reset() {
  camera_ = home_;
  distance_ = homeDistance_;
  ++revision_;
}

void CameraController::orthonormalize() {
  glm::vec3 f = glm::normalize(camera_.forward);
  glm::vec3 r = glm::cross(f, camera_.up);
  if (glm::dot(r, r) < 1e-12f) r = glm::cross(f, std::abs(f.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0));
  r = glm::normalize(r);
  camera_.forward = f;
  camera_.up = glm::cross(r, f);
}

void CameraController::rotate(const glm::vec3& axis, float angle, bool aroundTarget) {
  glm::vec3 pivot = target();
  camera_.forward = rotateAbout(camera_.forward, axis, angle);
  camera_.up = rotateAbout(camera_.up, axis, angle);
  orthonormalize();
  // Around the target the camera stays at the same distance behind it; in place nothing moves.
  if (aroundTarget) camera_.position = pivot - camera_.forward * distance_;
}

float CameraController::clampPitch(float raise) const {
  // `raise` lifts the view direction's elevation: the polar angle theta becomes theta - raise.
  // Keep theta in [margin, pi - margin], but never block a motion away from a pole we are already near.
  float theta = polarAngle(camera_.forward, worldUp_);
  float lo = std::min(theta - (glm::pi<float>() - kPoleMargin), 0.0f);
  float hi = std::max(theta - kPoleMargin, 0.0f);
  return std::clamp(raise, lo, hi);
}

void CameraController::turn(float yaw, float raise, bool aroundTarget) {
  if (yaw == 0.0f && raise == 0.0f) return;
  if (yaw != 0.0f) rotate(worldUp_, yaw, aroundTarget);
  if (raise != 0.0f) {
    // Elevation changes about the horizontal right axis, so the polar angle changes by exactly `raise`.
    glm::vec3 axis = glm::cross(camera_.forward, worldUp_);
    float len = glm::length(axis);
    if (len > 1e-6f) {
      rotate(axis / len, clampPitch(raise), aroundTarget);
    } else if (glm::dot(camera_.forward, worldUp_) < 0.0f ? raise > 0.0f : raise < 0.0f) {
      // Looking straight down (up): only raising (lowering) the view leaves the pole. Tilt about the
      // camera's right axis, which turns the view toward the screen's up (down) direction.
      rotate(glm::normalize(glm::cross(camera_.forward, camera_.up)), raise, aroundTarget);
    }
  }
  ++revision_;
}

void CameraController::orbit(float yaw, float pitch) { turn(yaw, -pitch, true); }

void CameraController::look(float yaw, float pitch) { turn(yaw, pitch, false); }

void CameraController::pan(float dx, float dy) {
  if (dx == 0.0f && dy == 0.0f) return;
  glm::vec3 right = glm::normalize(glm::cross(camera_.forward, camera_.up));
  // One image height at the target depth spans 2 tan(yfov/2) * distance scene units (orthographic:
  // twice its half height, at any depth).
  float span = camera_.orthographic() ? 2.0f * camera_.orthoHeight : 2.0f * std::tan(0.5f * camera_.yfov) * distance_;
  camera_.position += (-dx * right + dy * camera_.up) * span;
  ++revision_;
}

void CameraController::dolly(float steps) {
  if (steps == 0.0f) return;
  glm::vec3 pivot = target();
  float minDistance = 1e-4f * sceneSize_;
  const float before = distance_;
  distance_ = std::max(distance_ * std::pow(7.0f / 8.0f, steps), minDistance);
  camera_.position = pivot - camera_.forward * distance_;
  if (camera_.orthographic()) camera_.orthoHeight *= distance_ / before;  // parallel rays: zoom instead
  ++revision_;
}

void CameraController::move(float right, float up, float forward) {
  if (right == 0.0f && up == 0.0f && forward == 0.0f) return;
  glm::vec3 r = glm::normalize(glm::cross(camera_.forward, camera_.up));
  camera_.position += r * right + worldUp_ * up + camera_.forward * forward;
  ++revision_;
}

}  // namespace caustica
