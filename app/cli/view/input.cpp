// input.cpp — maps the viewer's keys and mouse to camera motion and to the controls they toggle.
// Mouse motion in screen coordinates, keyboard motion in scene units per second.
#include "cli/view/input.h"

#include <iostream>

#ifdef CAUSTICA_HAVE_GLFW
#include <algorithm>
#include <cstdint>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "cli/view/camera_controller.h"
#include "platform/glfw_window.h"
#endif

namespace caustica {

const char* const kViewerControls =
    "controls:\n"
    "  left drag            orbit around the target (fly mode: look around)\n"
    "  middle / shift-drag  pan\n"
    "  wheel                dolly toward / away from the target\n"
    "  W A S D, Q E         move forward, left, back, right, down, up (shift: faster, ctrl: slower)\n"
    "  F                    toggle fly mode (left drag looks around instead of orbiting)\n"
    "  R                    reset to the scene camera\n"
    "  M                    render mode: path -> whitted -> raster (docs/render-modes.md)\n"
    "  I                    integrator: mis / naive\n"
    "  C                    mis: caster aiming (bounces aimed at glass and mirrors) on / off\n"
    "  L                    dispersion: rgb / spectral (hero wavelength)\n"
    "  [ ]                  max depth down / up\n"
    "  + -  (0)             exposure +/- 0.5 stop (reset)\n"
    "  T                    tone curve: aces / clamp\n"
    "  space                pause / resume sampling (changes apply on resume)\n"
    "  P                    screenshot as shown: caustica-SCENE-Nspp[-denoised].png and .exr, at the end of the pass in flight\n"
    "  G                    stop refining at the target relMSE (--target-error, default 0.01) on / off\n"
    "  N                    denoiser on (default) / off: the denoised or the raw image (path mode; docs/denoising.md)\n"
    "  H                    print these controls\n"
    "  Esc                  quit\n";

#ifdef CAUSTICA_HAVE_GLFW

namespace {

const int kDepthSteps[] = {1, 2, 3, 4, 5, 6, 8, 10, 12, 16, 24, 32, 48, 64, 96, 128, 256, 512, 1024};

// The next depth step above (up) or below `depth`; `depth` itself at either end.
int stepDepth(int depth, bool up) {
  const int n = static_cast<int>(sizeof kDepthSteps / sizeof kDepthSteps[0]);
  if (up) {
    for (int i = 0; i < n; ++i)
      if (kDepthSteps[i] > depth) return kDepthSteps[i];
  } else {
    for (int i = n - 1; i >= 0; --i)
      if (kDepthSteps[i] < depth) return kDepthSteps[i];
  }
  return depth;
}

void applyKeys(GlfwWindow& window, CameraController& controller, ViewControls& c, float casterProbabilityOn) {
  for (const KeyPress& k : window.keyPresses()) {
    if (k.repeat && k.key != GLFW_KEY_R) continue;
    switch (k.key) {
      case GLFW_KEY_ESCAPE: window.requestClose(); break;
      case GLFW_KEY_SPACE: c.paused = !c.paused; break;
      case GLFW_KEY_R: controller.reset(); break;
      case GLFW_KEY_F: c.fly = !c.fly; break;
      case GLFW_KEY_M:
        c.wanted.mode = nextRenderMode(c.wanted.mode, c.instancedScene);
        std::cout << "caustica: render mode " << renderModeName(c.wanted.mode) << "\n" << std::flush;
        break;
      case GLFW_KEY_I:
        c.wanted.integrator = c.wanted.integrator == Integrator::Mis ? Integrator::Naive : Integrator::Mis;
        break;
      case GLFW_KEY_C: c.wanted.casterProbability = c.wanted.casterProbability > 0.0f ? 0.0f : casterProbabilityOn; break;
      case GLFW_KEY_L:
        c.wanted.dispersion = c.wanted.dispersion == DispersionMode::Rgb ? DispersionMode::Spectral : DispersionMode::Rgb;
        break;
      case GLFW_KEY_T:
        c.tone.curve = c.tone.curve == ToneCurve::Aces ? ToneCurve::Clamp : ToneCurve::Aces;
        c.redraw = true;
        break;
      case GLFW_KEY_P: c.screenshotPending = true; break;
      case GLFW_KEY_G: c.stopAtTarget = !c.stopAtTarget; break;
      case GLFW_KEY_N:
        c.denoise = !c.denoise;
        c.redraw = true;
        std::cout << "caustica: denoiser " << (c.denoise ? "on" : "off (raw image)") << "\n" << std::flush;
        break;
      case GLFW_KEY_H: std::cout << kViewerControls << std::flush; break;
      default: break;
    }
  }
}

void applyCharacters(const GlfwWindow& window, ViewControls& c, float exposure0) {
  for (unsigned ch : window.characters()) {
    if (ch == '+' || ch == '=') c.tone.exposureStops += 0.5f;
    else if (ch == '-' || ch == '_') c.tone.exposureStops -= 0.5f;
    else if (ch == '0') c.tone.exposureStops = exposure0;
    else if (ch == '[' || ch == ']') c.wanted.maxDepth = stepDepth(c.wanted.maxDepth, ch == ']');
    else continue;
    c.redraw = true;
  }
}

}  // namespace

ViewerInput::ViewerInput(const ViewControls& initial, double spinRadians)
    : casterProbabilityOn_(initial.wanted.casterProbability > 0.0f ? initial.wanted.casterProbability
                                                                   : RenderSettings{}.casterProbability),
      exposure0_(initial.tone.exposureStops),
      spinRadians_(spinRadians) {}

bool ViewerInput::apply(GlfwWindow& window, CameraController& controller, ViewControls& controls, double dt) {
  std::uint64_t revision = controller.revision();
  applyKeys(window, controller, controls, casterProbabilityOn_);
  applyCharacters(window, controls, exposure0_);

  // Mouse: cursor motion since the last call, in screen coordinates (y down).
  double x = 0.0, y = 0.0;
  window.cursor(x, y);
  double dx = x - lastX_, dy = y - lastY_;
  setCursor(x, y);
  int ww = 0, wh = 0;
  window.windowSize(ww, wh);
  float height = static_cast<float>(std::max(wh, 1));  // the image fills the window's height
  bool left = window.mouseDown(GLFW_MOUSE_BUTTON_LEFT), middle = window.mouseDown(GLFW_MOUSE_BUTTON_MIDDLE);
  bool shift = window.keyDown(GLFW_KEY_LEFT_SHIFT) || window.keyDown(GLFW_KEY_RIGHT_SHIFT);
  bool ctrl = window.keyDown(GLFW_KEY_LEFT_CONTROL) || window.keyDown(GLFW_KEY_RIGHT_CONTROL);
  float fdx = static_cast<float>(dx), fdy = static_cast<float>(dy);
  if (middle || (left && shift)) {
    controller.pan(fdx / height, fdy / height);
  } else if (left) {
    float k = 3.14159265f / height;  // a drag over the window's height turns half a revolution
    if (controls.fly) controller.look(-fdx * k, -fdy * k);
    else controller.orbit(-fdx * k, fdy * k);
  }
  if (window.wheel() != 0.0) controller.dolly(static_cast<float>(window.wheel()));

  // Keyboard motion: a quarter of the scene size per second.
  auto held = [&](int key) { return window.keyDown(key) ? 1.0f : 0.0f; };
  float step = 0.25f * controller.sceneSize() * static_cast<float>(dt) * (shift ? 4.0f : 1.0f) * (ctrl ? 0.25f : 1.0f);
  float fwd = held(GLFW_KEY_W) - held(GLFW_KEY_S), right = held(GLFW_KEY_D) - held(GLFW_KEY_A),
        up = held(GLFW_KEY_E) - held(GLFW_KEY_Q);
  controller.move(right * step, up * step, fwd * step);

  if (spinRadians_ != 0.0) controller.orbit(static_cast<float>(spinRadians_), 0.0f);
  return controller.revision() != revision;
}

#endif  // CAUSTICA_HAVE_GLFW

}  // namespace caustica
