// input.h — the viewer's keys and mouse: camera motion for the CameraController, and the toggles
// (render mode, integrator, casters, dispersion, depth, exposure, tone curve, pause, fly, screenshot,
// denoiser) they set.
#pragma once
#include "gpu/render_settings.h"
#include "image/tonemap.h"

namespace caustica {

class CameraController;
class GlfwWindow;

// The controls, as H prints them and `caustica view --help` lists them.
extern const char* const kViewerControls;

// What the keys change besides the camera.
struct ViewControls {
  RenderSettings wanted;  // what the renderer should use, width and height aside (the viewer picks those)
  ToneMapSettings tone;
  bool paused = false;             // sampling paused: settings apply on resume
  bool fly = false;                // left drag looks around instead of orbiting
  bool screenshotPending = false;  // P: write a screenshot pair at the end of the pass in flight
  bool redraw = true;              // the shown image is out of date (restart, exposure, damage...)
  bool stopAtTarget = false;       // G: stop refining once the estimated relMSE reaches targetError
  double targetError = 0.01;       // relMSE (--target-error; G toggles stopping there)
  bool instancedScene = false;     // M skips the modes that draw flat scenes only (RenderModeSpec::instancedScenes)
  bool denoise = true;             // N: show the denoised image (path mode; the raw one otherwise)
};

class ViewerInput {
 public:
  // `initial`: the starting controls (0 returns to its exposure; C turns casters back on at its
  // caster probability, or the default when it starts off). `spinRadians`: orbit per call (--spin).
  ViewerInput(const ViewControls& initial, double spinRadians);
  // Applies the input the window gathered in its last poll to `controls` and `controller`. `dt`:
  // seconds since the last call (keyboard motion). Returns true when the camera changed.
  bool apply(GlfwWindow& window, CameraController& controller, ViewControls& controls, double dt);
  // Cursor position the next mouse motion is measured from (screen coordinates).
  void setCursor(double x, double y) {
    lastX_ = x;
    lastY_ = y;
  }

 private:
  float casterProbabilityOn_;
  float exposure0_;
  double spinRadians_;
  double lastX_ = 0.0, lastY_ = 0.0;
};

}  // namespace caustica
