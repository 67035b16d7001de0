// viewer.h — `caustica view`'s window: owns the window, renderer and camera controller and runs the
// loop (input, path tracing in row bands within a GPU time budget, presentation, title, screenshots).
#pragma once
#include <limits>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "cli/cli_common.h"
#include "image/tonemap.h"

#ifdef CAUSTICA_HAVE_GLFW
#include "cli/view/camera_controller.h"
#include "cli/view/frame_pacer.h"
#include "cli/view/input.h"
#include "cli/view/presenter.h"
#include "platform/glfw_window.h"
#endif

namespace caustica::cli {

struct ViewConfig {
  bool quiet = false;
  int frameLimit = 0;          // scripted run: frames to render, 0 = interactive
  std::string screenshotPath;  // written at exit ("" = none)
  double budgetMs = 30.0;      // path-tracing GPU time per frame, milliseconds
  int maxSpp = 0;              // stop refining here; 0 = never
  double targetError = 0.0;    // --target-error: stop refining once the estimated relMSE is at most this; 0 = off
  bool vsync = true;
  bool preview = true;         // lower resolution while the camera moves, when full passes do not fit
  double spinRadians = 0.0;    // orbit per frame
  bool fixedSize = false;      // --size given: render resolution fixed, the window scales the image
  bool denoise = true;         // show the denoised image (--no-denoise: the raw one; key N toggles)
};

#ifdef CAUSTICA_HAVE_GLFW

class Viewer {
 public:
  Viewer(const Options& opts, const ViewConfig& config);
  int run();

 private:
  using Clock = std::chrono::steady_clock;
  double now() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }  // seconds
  void syncRenderer();
  bool resizeRenderer(int width, int height);  // true if the resolution changed (accumulation restarts)
  void warmUp();
  void renderWithin(double budgetMs, bool stopAtPassEnd = false);
  bool presentDue() const;
  void present();
  void finishPass();
  void updateTitle(bool force);
  void writeScreenshotPair();
  bool done() const {
    return pacer_.done(renderer_->samplesPerPixel()) || (controls_.stopAtTarget && estimate_ <= controls_.targetError);
  }
  void estimateAfterPass();  // the error estimate at scheduled sample counts (docs/adaptive-sampling.md)
  bool showDenoised() const { return controls_.denoise && renderer_->canDenoise(); }
  Image shownImage() const;  // the linear image the window shows: denoised or raw

  ViewConfig config_;
  Clock::time_point start_ = Clock::now();
  LoadedScene scene_;
  std::string sceneName_;
  std::unique_ptr<GlfwWindow> window_;  // first: GL objects below must go before the context
  std::unique_ptr<ShaderLibrary> library_;
  std::unique_ptr<Renderer> renderer_;
  std::unique_ptr<CameraController> controller_;
  Presenter presenter_;
  FramePacer pacer_;

  // What the renderer should be doing (applied by syncRenderer, which pausing defers).
  ViewControls controls_;
  ViewerInput input_{controls_, 0.0};
  int fullW_ = 0, fullH_ = 0;          // full render resolution, pixels
  std::uint64_t appliedRevision_ = 0;  // controller revision the renderer has
  bool showPreviewCopy_ = false;       // first full pass in flight: show the preview under its finished rows
  bool newSamples_ = false;            // samples not presented yet (presented at a rate that bounds display cost)

  // Statistics.
  std::uint64_t samples_ = 0;  // pixel samples traced since start
  double estimate_ = std::numeric_limits<double>::infinity();  // estimated relMSE of the image (inf: none yet)
  int nextEstimate_ = 0;       // spp of the next error estimate
  int frames_ = 0;             // loop iterations: input, at most one budget of path tracing, maybe a shown frame
  double lastInput_ = 0.0;     // seconds
  int presented_ = 0;          // frames shown
  double lastPresent_ = 0.0;   // seconds
  double frameMs_ = 0.0;       // moving average of the time between presented frames, milliseconds
  double lastTitle_ = -1.0, rateT0_ = 0.0;  // seconds
  std::uint64_t rateS0_ = 0;
  double samplesPerSecond_ = 0.0;
  // The filter's time per shown denoised frame (every denoise() since the frame before: the display's
  // and a preview copy's), milliseconds; the first (llvmpipe compiles the programs then) left out.
  double denoiseMs_ = 0.0;       // moving average, for the title
  double filterMsSeen_ = 0.0;    // Renderer::denoiseMsTotal() at the last shown frame
  double filterMsSum_ = 0.0;     // sum over the shown denoised frames counted
  int denoised_ = 0;             // frames shown denoised
};

#endif  // CAUSTICA_HAVE_GLFW

}  // namespace caustica::cli
