// camera_controller.h — interactive camera motion for the viewer: orbit around a target, pan, dolly,
// fly (look in place + move). Pure math on caustica::Camera: world space, scene units, radians.
#pragma once
#include <cstdint>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace caustica {

class CameraController {
 public:
  // `home` is the scene camera (reset() returns to it exactly); `bounds` (world space) set the
  // initial orbit target (at the depth of the scene centre, on the view axis) and sceneSize().
  CameraController(const Camera& home, const Bounds& bounds);

  const Camera& camera() const { return camera_; }
  const Camera& home() const { return home_; }
  glm::vec3 target() const { return camera_.position + camera_.forward * distance_; }  // orbit centre
  float targetDistance() const { return distance_; }  // camera to target, scene units
  float sceneSize() const { return sceneSize_; }       // bounds diagonal in scene units (1 if empty)
  glm::vec3 worldUp() const { return worldUp_; }       // the world axis nearest the home camera's up
  std::uint64_t revision() const { return revision_; } // grows on every change of camera()

  void reset();  // back to the home camera and its target

  // Rotates the camera around the target: `yaw` about the world up axis (positive turns the camera
  // counter-clockwise seen from above), `pitch` raises the camera (it then looks further down).
  // Radians. The view direction stays at least kPoleMargin away from straight up or down.
  void orbit(float yaw, float pitch);
  // Turns the camera in place (fly mode): same axes, signs and limit; positive pitch looks up.
  void look(float yaw, float pitch);
  // Moves camera and target in the image plane so that the point at target depth follows a cursor
  // moving by (dx, dy): fractions of the image height, x to the right, y downwards.
  void pan(float dx, float dy);
  // Moves toward the target by `steps` wheel notches, each 1/8 of the remaining distance (negative:
  // away). The camera never reaches or passes the target.
  void dolly(float steps);
  // Moves camera and target by `right` along the camera's right axis, `up` along the world up axis
  // and `forward` along the view direction. Scene units.
  void move(float right, float up, float forward);

  static constexpr float kPoleMargin = 0.035f;  // radians (about 2 degrees)

 private:
  void turn(float yaw, float raise, bool aroundTarget);
  void rotate(const glm::vec3& axis, float angle, bool aroundTarget);
  void orthonormalize();
  float clampPitch(float pitch) const;  // limits a raise of the view direction's elevation

  Camera home_, camera_;
  float homeDistance_ = 1.0f, distance_ = 1.0f;
  float sceneSize_ = 1.0f;
  glm::vec3 worldUp_{0.0f, 1.0f, 0.0f};
  std::uint64_t revision_ = 0;
};

}  // namespace caustica
