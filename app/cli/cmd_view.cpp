// cmd_view.cpp — `caustica view`: interactive progressive preview in a GLFW window. The same Renderer
// as `render`; each frame's path tracing is split into row bands that fit a GPU time budget.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <vector>

#include "cli/cli_common.h"
#include "cli/commands.h"
#include "cli/view/camera_controller.h"
#include "util/error.h"
#include "image/image_io.h"

#ifdef CAUSTICA_HAVE_GLFW
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "platform/glfw_window.h"
#endif

namespace caustica::cli {

namespace {

const char* kControls =
    "controls:\n"
    "  left drag            orbit around the target (fly mode: look around)\n"
    "  middle / shift-drag  pan\n"
    "  wheel                dolly toward / away from the target\n"
    "  W A S D, Q E         move forward, left, back, right, down, up (shift: faster, ctrl: slower)\n"
    "  F                    toggle fly mode (left drag looks around instead of orbiting)\n"
    "  R                    reset to the scene camera\n"
    "  I                    integrator: mis / naive\n"
    "  C                    mis: caster aiming (bounces aimed at glass and mirrors) on / off\n"
    "  L                    dispersion: rgb / spectral (hero wavelength)\n"
    "  [ ]                  max depth down / up\n"
    "  + -  (0)             exposure +/- 0.5 stop (reset)\n"
    "  T                    tone curve: aces / clamp\n"
    "  space                pause / resume sampling (changes apply on resume)\n"
    "  P                    screenshot: caustica-SCENE-Nspp.png and .exr, at the end of the pass in flight\n"
    "  H                    print these controls\n"
    "  Esc                  quit\n";

#ifdef CAUSTICA_HAVE_GLFW

using Clock = std::chrono::steady_clock;

const int kDepthSteps[] = {1, 2, 3, 4, 5, 6, 8, 10, 12, 16, 24, 32, 48, 64, 96, 128, 256, 512, 1024};
constexpr double kSettleSeconds = 0.25;  // camera still this long: leave the preview for full resolution
constexpr int kDefaultWidth = 960;       // window width in pixels when --size is not given

std::string fileStem(const std::string& path) {
  size_t slash = path.find_last_of("/\\");
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  size_t dot = name.find_last_of('.');
  return dot == std::string::npos || dot == 0 ? name : name.substr(0, dot);
}

std::string format(const char* fmt, double a) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, a);
  return buf;
}

struct ViewConfig {
  bool quiet = false;
  int frameLimit = 0;          // scripted run: frames to render, 0 = interactive
  std::string screenshotPath;  // written at exit ("" = none)
  double budgetMs = 30.0;      // path-tracing GPU time per frame, milliseconds
  int maxSpp = 0;              // stop refining here; 0 = never
  bool vsync = true;
  bool preview = true;         // lower resolution while the camera moves, when full passes do not fit
  double spinRadians = 0.0;    // orbit per frame
  ToneMapSettings tone;
  bool fixedSize = false;      // --size given: render resolution fixed, the window scales the image
};

class Viewer {
 public:
  Viewer(const Options& opts, const ViewConfig& config);
  int run();

 private:
  double now() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }
  void handleInput(double dt);
  void syncRenderer();
  void copyPreview();
  void warmUp();
  void renderWithin(double budgetMs, bool stopAtPassEnd = false);
  int choosePassSpp() const;
  void present();
  bool resizeRenderer(int width, int height);  // true if the resolution changed (accumulation restarts)
  void finishPass();
  void updateTitle(bool force);
  void writeScreenshotPair();
  bool done() const { return config_.maxSpp > 0 && !previewing_ && bandY_ == 0 && renderer_->samplesPerPixel() >= config_.maxSpp; }

  ViewConfig config_;
  Clock::time_point start_ = Clock::now();
  LoadedScene scene_;
  std::string sceneName_;
  std::unique_ptr<GlfwWindow> window_;  // first: GL objects below must go before the context
  std::unique_ptr<ShaderLibrary> library_;
  std::unique_ptr<Renderer> renderer_;
  std::unique_ptr<CameraController> controller_;

  // What the renderer should be doing (applied by syncRenderer, which pausing defers).
  RenderSettings wanted_;  // width and height aside: syncRenderer picks full or preview resolution
  float casterProbabilityOn_ = RenderSettings{}.casterProbability;  // what C switches back to
  int fullW_ = 0, fullH_ = 0;          // full render resolution, pixels
  std::uint64_t appliedRevision_ = 0;  // controller revision the renderer has
  double exposure0_ = 0.0;

  // Progress of the pass in flight and the time model.
  int bandY_ = 0;          // first row not yet covered by the pass in flight
  int passSpp_ = 1;        // samples per pixel of the pass in flight
  double costMs_ = 3.3e-3; // GPU milliseconds per pixel sample (EMA of measurements); starts at llvmpipe speed
  std::vector<double> rowCost_;  // per image row: milliseconds per pixel sample in its last band (0 = unknown)
  double displayMs_ = 1.0; // tone mapping + blit, milliseconds (EMA)

  // Preview while moving.
  bool previewing_ = false;  // renderer is at preview resolution
  int previewScale_ = 1;     // preview = full / scale
  int previewPasses_ = 0;    // complete preview passes since its last restart
  double lastMotion_ = -1e9; // seconds
  bool showPreviewCopy_ = false;  // first full pass in flight: show the preview under its finished rows
  GlTexture previewCopy_;
  GlFramebuffer previewCopyFb_;
  GlFramebuffer displayFb_;
  GLuint displayFbTexture_ = 0;
  bool displayFbStale_ = true;

  // Interaction state.
  bool paused_ = false, fly_ = false, screenshotPending_ = false;
  bool redraw_ = true;       // present at the end of this iteration (restart, exposure, damage...)
  bool newSamples_ = false;  // samples not presented yet (presented at a rate that bounds display cost)
  double lastX_ = 0.0, lastY_ = 0.0;

  // Statistics.
  std::uint64_t samples_ = 0;  // pixel samples traced since start
  int frames_ = 0;             // loop iterations: input, at most one budget of path tracing, maybe a shown frame
  double lastInput_ = 0.0;     // seconds
  int presented_ = 0;          // frames shown
  double lastPresent_ = 0.0;   // seconds
  double frameMs_ = 0.0;       // EMA of the time between presented frames, milliseconds
  double lastTitle_ = -1.0, rateT0_ = 0.0;
  std::uint64_t rateS0_ = 0;
  double samplesPerSecond_ = 0.0;
};

Viewer::Viewer(const Options& opts, const ViewConfig& config) : config_(config) {
  scene_ = loadSceneForCli(opts, !config_.quiet);
  sceneName_ = fileStem(scene_.scene.path);
  RenderSettings settings = renderSettingsFrom(opts, scene_.camera, kDefaultWidth);
  wanted_ = settings;
  if (wanted_.casterProbability > 0.0f) casterProbabilityOn_ = wanted_.casterProbability;
  exposure0_ = config_.tone.exposureStops;

  std::string glInfo;
  window_ = std::make_unique<GlfwWindow>(settings.width, settings.height, "caustica view - " + sceneName_, config_.vsync, &glInfo);
  note(config_.quiet, "OpenGL (" + window_->backendName() + "): " + glInfo);
  glClearColor(0.0f, 0.0f, 0.0f, 1.0f);  // something to look at while shaders compile
  glClear(GL_COLOR_BUFFER_BIT);
  window_->swapBuffers();
  if (!config_.fixedSize) window_->framebufferSize(settings.width, settings.height);  // HiDPI: pixels
  settings.width = std::max(settings.width, 1);
  settings.height = std::max(settings.height, 1);
  fullW_ = settings.width;
  fullH_ = settings.height;

  library_ = std::make_unique<ShaderLibrary>(shaderLibraryFrom(opts));
  renderer_ = std::make_unique<Renderer>(*library_, scene_.scene, scene_.camera, settings);
  warmUp();
  present();  // compiles the tone-mapping shader and whatever the blit needs, before anything is timed
  presented_ = 0;
  controller_ = std::make_unique<CameraController>(scene_.camera, scene_.scene.bounds);
  appliedRevision_ = controller_->revision();
  note(config_.quiet, scene_.scene.path + ": " + std::to_string(scene_.scene.triangles.size()) + " triangles, features: " +
                          renderer_->gpuScene().features.describe() + "; " + std::to_string(fullW_) + "x" +
                          std::to_string(fullH_) + ", " + integratorName(wanted_.integrator) + "; press H for the controls");
  window_->cursor(lastX_, lastY_);
  lastMotion_ = now();  // start like a camera change: a preview first if full passes are slow
}

// ---- input ---------------------------------------------------------------------------------------

void Viewer::handleInput(double dt) {
  std::uint64_t revision = controller_->revision();
  for (const KeyPress& k : window_->keyPresses()) {
    if (k.repeat && k.key != GLFW_KEY_R) continue;
    switch (k.key) {
      case GLFW_KEY_ESCAPE: window_->requestClose(); break;
      case GLFW_KEY_SPACE: paused_ = !paused_; break;
      case GLFW_KEY_R: controller_->reset(); break;
      case GLFW_KEY_F: fly_ = !fly_; break;
      case GLFW_KEY_I:
        wanted_.integrator = wanted_.integrator == Integrator::Mis ? Integrator::Naive : Integrator::Mis;
        break;
      case GLFW_KEY_C: wanted_.casterProbability = wanted_.casterProbability > 0.0f ? 0.0f : casterProbabilityOn_; break;
      case GLFW_KEY_L:
        wanted_.dispersion = wanted_.dispersion == DispersionMode::Rgb ? DispersionMode::Spectral : DispersionMode::Rgb;
        break;
      case GLFW_KEY_T:
        config_.tone.curve = config_.tone.curve == ToneCurve::Aces ? ToneCurve::Clamp : ToneCurve::Aces;
        redraw_ = true;
        break;
      case GLFW_KEY_P: screenshotPending_ = true; break;
      case GLFW_KEY_H: std::cout << kControls << std::flush; break;
      default: break;
    }
  }
  for (unsigned c : window_->characters()) {
    if (c == '+' || c == '=') config_.tone.exposureStops += 0.5f;
    else if (c == '-' || c == '_') config_.tone.exposureStops -= 0.5f;
    else if (c == '0') config_.tone.exposureStops = static_cast<float>(exposure0_);
    else if (c == '[' || c == ']') {
      const int n = static_cast<int>(sizeof kDepthSteps / sizeof kDepthSteps[0]);
      if (c == ']') {
        for (int i = 0; i < n; ++i)
          if (kDepthSteps[i] > wanted_.maxDepth) { wanted_.maxDepth = kDepthSteps[i]; break; }
      } else {
        for (int i = n - 1; i >= 0; --i)
          if (kDepthSteps[i] < wanted_.maxDepth) { wanted_.maxDepth = kDepthSteps[i]; break; }
      }
    } else {
      continue;
    }
    redraw_ = true;
  }

  // Mouse: cursor motion since the last frame, in screen coordinates (y down).
  double x = 0.0, y = 0.0;
  window_->cursor(x, y);
  double dx = x - lastX_, dy = y - lastY_;
  lastX_ = x;
  lastY_ = y;
  int ww = 0, wh = 0;
  window_->windowSize(ww, wh);
  float height = static_cast<float>(std::max(wh, 1));  // the image fills the window's height
  bool left = window_->mouseDown(GLFW_MOUSE_BUTTON_LEFT), middle = window_->mouseDown(GLFW_MOUSE_BUTTON_MIDDLE);
  bool shift = window_->keyDown(GLFW_KEY_LEFT_SHIFT) || window_->keyDown(GLFW_KEY_RIGHT_SHIFT);
  bool ctrl = window_->keyDown(GLFW_KEY_LEFT_CONTROL) || window_->keyDown(GLFW_KEY_RIGHT_CONTROL);
  float fdx = static_cast<float>(dx), fdy = static_cast<float>(dy);
  if (middle || (left && shift)) {
    controller_->pan(fdx / height, fdy / height);
  } else if (left) {
    float k = 3.14159265f / height;  // a drag over the window's height turns half a revolution
    if (fly_) controller_->look(-fdx * k, -fdy * k);
    else controller_->orbit(-fdx * k, fdy * k);
  }
  if (window_->wheel() != 0.0) controller_->dolly(static_cast<float>(window_->wheel()));

  // Keyboard motion: a quarter of the scene size per second.
  auto held = [&](int key) { return window_->keyDown(key) ? 1.0f : 0.0f; };
  float step = 0.25f * controller_->sceneSize() * static_cast<float>(dt) * (shift ? 4.0f : 1.0f) * (ctrl ? 0.25f : 1.0f);
  float fwd = held(GLFW_KEY_W) - held(GLFW_KEY_S), right = held(GLFW_KEY_D) - held(GLFW_KEY_A),
        up = held(GLFW_KEY_E) - held(GLFW_KEY_Q);
  controller_->move(right * step, up * step, fwd * step);

  if (config_.spinRadians != 0.0) controller_->orbit(static_cast<float>(config_.spinRadians), 0.0f);
  if (controller_->revision() != revision) lastMotion_ = now();
}

// ---- rendering -----------------------------------------------------------------------------------

void Viewer::syncRenderer() {
  // Settings first, at the current resolution (chosen below); a new shader variant is warmed up.
  RenderSettings next = wanted_;
  next.width = renderer_->settings().width;
  next.height = renderer_->settings().height;
  SettingsChange change = renderer_->apply(next);
  if (change.shader) warmUp();
  bool restarted = change.restart;
  if (controller_->revision() != appliedRevision_) {
    renderer_->setCamera(controller_->camera());
    appliedRevision_ = controller_->revision();
    restarted = true;
  }
  bool moving = now() - lastMotion_ < kSettleSeconds;
  // A full pass that does not fit the budget makes a restart show black rows for a while: preview.
  bool slow = config_.preview && costMs_ * fullW_ * fullH_ > 0.8 * config_.budgetMs;
  bool wantPreview = slow && (moving || restarted || (previewing_ && previewPasses_ == 0));
  bool leaving = false;
  if (wantPreview) {
    // Preview passes should take about half the budget. Re-chosen at restarts, with some hysteresis.
    int scale = static_cast<int>(std::clamp(std::ceil(std::sqrt(costMs_ * fullW_ * fullH_ / (0.5 * config_.budgetMs))), 2.0, 16.0));
    if (!previewing_ || (restarted && std::abs(scale - previewScale_) >= 2)) previewScale_ = scale;
    int pw = std::max(1, fullW_ / previewScale_), ph = std::max(1, fullH_ / previewScale_);
    if (resizeRenderer(pw, ph)) restarted = true;
    previewing_ = true;
  } else {
    if (previewing_) {
      leaving = previewPasses_ > 0;
      if (leaving) copyPreview();
      previewing_ = false;
    }
    if (resizeRenderer(fullW_, fullH_)) restarted = true;
  }
  if (restarted) {
    bandY_ = 0;
    previewPasses_ = 0;
    showPreviewCopy_ = leaving;
    redraw_ = true;
  }
}

bool Viewer::resizeRenderer(int width, int height) {
  RenderSettings r = renderer_->settings();
  r.width = width;
  r.height = height;
  if (!renderer_->apply(r).resize) return false;
  displayFbStale_ = true;
  return true;
}

void Viewer::copyPreview() {
  const GlTexture& d = renderer_->updateDisplay(config_.tone);
  if (previewCopy_.width() != d.width() || previewCopy_.height() != d.height()) {
    previewCopy_ = GlTexture::create2D(d.width(), d.height(), GL_RGBA8);
    previewCopyFb_ = GlFramebuffer::forTexture(previewCopy_);
  }
  glCopyImageSubData(d.id(), GL_TEXTURE_2D, 0, 0, 0, 0, previewCopy_.id(), GL_TEXTURE_2D, 0, 0, 0, 0, d.width(), d.height(), 1);
  checkGlError("copying the preview image");
}

int Viewer::choosePassSpp() const {
  if (config_.frameLimit > 0) return 1;  // scripted: one sample per pass, so spp counts passes exactly
  const RenderSettings& s = renderer_->settings();
  double passMs = costMs_ * s.width * s.height;
  int spp = static_cast<int>(std::clamp(std::floor(0.5 * config_.budgetMs / passMs), 1.0, 64.0));
  if (config_.maxSpp > 0) spp = std::max(1, std::min(spp, config_.maxSpp - renderer_->samplesPerPixel()));
  return spp;
}

void Viewer::renderWithin(double budgetMs, bool stopAtPassEnd) {
  if (done()) return;
  const double t0 = now();
  const int w = renderer_->settings().width, h = renderer_->settings().height;
  if (static_cast<int>(rowCost_.size()) != h) rowCost_.assign(static_cast<size_t>(h), 0.0);
  // Predicted milliseconds of row y: its cost in the last pass, else the running mean.
  auto rowMs = [&](int y) { return (rowCost_[y] > 0.0 ? rowCost_[y] : costMs_) * w * passSpp_; };
  for (;;) {
    if (bandY_ == 0) passSpp_ = choosePassSpp();
    double remaining = budgetMs - (now() - t0) * 1000.0;
    int y1 = bandY_;  // the band: as many rows as fit the time left, at least one
    double predicted = 0.0;
    while (y1 < h && (y1 == bandY_ || predicted + rowMs(y1) <= remaining)) predicted += rowMs(y1++);
    double t = now();
    renderer_->renderRows(bandY_, y1, passSpp_);  // returns when the GPU is done (it reads counters back)
    double ms = (now() - t) * 1000.0;
    double n = static_cast<double>(y1 - bandY_) * w * passSpp_;
    samples_ += static_cast<std::uint64_t>(n);
    // The band's rows keep their relative costs, scaled to the measured total.
    double ratio = ms / std::max(predicted, 1e-9);
    for (int y = bandY_; y < y1; ++y) rowCost_[y] = (rowCost_[y] > 0.0 ? rowCost_[y] : costMs_) * ratio;
    costMs_ += 0.3 * (ms / n - costMs_);
    bandY_ = y1;
    newSamples_ = true;
    if (bandY_ >= h) {
      renderer_->endPass(passSpp_);
      bandY_ = 0;
      if (previewing_) {
        ++previewPasses_;
      } else {
        showPreviewCopy_ = false;
        if (screenshotPending_) {
          writeScreenshotPair();
          screenshotPending_ = false;
        }
      }
      if (done() || stopAtPassEnd) break;
    }
    if (budgetMs - (now() - t0) * 1000.0 < rowMs(bandY_)) break;  // not one more row fits
  }
}

void Viewer::warmUp() {
  // Drivers may compile a shader variant at its first dispatch (llvmpipe does, taking ~1 s): do that
  // on one row now, so the time model never sees it.
  renderer_->renderRows(0, 1, 1);
  renderer_->reset();
}

void Viewer::present() {
  int ww = 0, wh = 0;
  window_->framebufferSize(ww, wh);
  if (ww <= 0 || wh <= 0) return;
  double t = now();
  const GlTexture& d = renderer_->updateDisplay(config_.tone);
  if (displayFbStale_ || d.id() != displayFbTexture_) {
    displayFb_ = GlFramebuffer::forTexture(d);
    displayFbTexture_ = d.id();
    displayFbStale_ = false;
  }
  if (showPreviewCopy_ && !previewing_ && renderer_->samplesPerPixel() == 0) {
    // First full pass in flight: the preview, with the rows finished so far on top of it.
    previewCopyFb_.blitToDefault(previewCopy_.width(), previewCopy_.height(), ww, wh);
    int shown = static_cast<int>(static_cast<long long>(bandY_) * wh / d.height());  // window pixels
    if (shown > 0) {
      glEnable(GL_SCISSOR_TEST);
      glScissor(0, wh - shown, ww, shown);  // window y is up; image row 0 is the top
      displayFb_.blitToDefault(d.width(), d.height(), ww, wh);
      glDisable(GL_SCISSOR_TEST);
    }
  } else {
    displayFb_.blitToDefault(d.width(), d.height(), ww, wh);
  }
  glFinish();  // so the time below is the GPU's
  checkGlError("presenting the image");
  double ms = (now() - t) * 1000.0;
  displayMs_ += (presented_ <= 1 ? 1.0 : 0.2) * (ms - displayMs_);
  window_->swapBuffers();
  redraw_ = newSamples_ = false;
  double end = now();
  if (presented_ > 0) frameMs_ += (presented_ == 1 ? 1.0 : 0.1) * ((end - lastPresent_) * 1000.0 - frameMs_);
  lastPresent_ = end;
  ++presented_;
}

void Viewer::finishPass() {
  lastMotion_ = -1e9;
  for (;;) {
    syncRenderer();
    if (done() || (!previewing_ && bandY_ == 0 && renderer_->samplesPerPixel() > 0)) break;
    renderWithin(config_.budgetMs, true);
    window_->pollEvents();
    present();
  }
}

// ---- output --------------------------------------------------------------------------------------

void Viewer::updateTitle(bool force) {
  double t = now();
  if (!force && t - lastTitle_ < 0.25) return;
  if (t - rateT0_ >= 1.0) {
    if (samples_ != rateS0_) samplesPerSecond_ = static_cast<double>(samples_ - rateS0_) / (t - rateT0_);  // idle: keep
    rateT0_ = t;
    rateS0_ = samples_;
  }
  lastTitle_ = t;
  std::string title = "caustica view - " + sceneName_ + " | " + std::to_string(renderer_->samplesPerPixel()) + " spp | " +
                      format("%.3g samples/s", samplesPerSecond_) + " | " + format("%.1f ms/frame", frameMs_) + " | " +
                      integratorName(wanted_.integrator) +
                      (wanted_.integrator == Integrator::Mis && !renderer_->gpuScene().casters.empty()
                           ? (wanted_.casterProbability > 0.0f ? " + casters" : " no casters")
                           : "") +
                      " | " + dispersionModeName(wanted_.dispersion) + " | depth " +
                      std::to_string(wanted_.maxDepth) + " | " + format("exposure %+.1f", config_.tone.exposureStops) +
                      " | non-finite " + std::to_string(renderer_->stats().nonFinite);
  if (previewing_) title += " | preview 1/" + std::to_string(previewScale_);
  if (fly_) title += " | fly";
  if (paused_) title += " | paused";
  if (done()) title += " | done";
  window_->setTitle(title);
}

void Viewer::writeScreenshotPair() {
  std::string base = "caustica-" + sceneName_ + "-" + std::to_string(renderer_->samplesPerPixel()) + "spp";
  try {
    Image img = renderer_->image();
    writeImage(base + ".png", img, config_.tone);
    writeImage(base + ".exr", img);
    note(config_.quiet, "wrote " + base + ".png and " + base + ".exr");
  } catch (const Error& e) {  // a failed screenshot is no reason to close the window
    std::cerr << "caustica view: screenshot failed: " << e.what() << "\n";
  }
}

int Viewer::run() {
  const double loopStart = now();
  bool closed = false;
  for (;;) {
    bool idle = paused_ || done();
    if (idle && !redraw_ && !newSamples_ && !screenshotPending_) window_->waitEvents(0.1);
    else window_->pollEvents();
    if (window_->shouldClose()) {
      closed = true;
      break;
    }
    double t = now();
    handleInput(std::min(t - lastInput_, 0.1));
    lastInput_ = t;
    int fw = 0, fh = 0;
    window_->framebufferSize(fw, fh);
    if (fw > 0 && fh > 0) {  // not minimised
      if (!config_.fixedSize && (fw != fullW_ || fh != fullH_)) {
        fullW_ = fw;
        fullH_ = fh;
        lastMotion_ = t;
      }
      if (window_->exposed()) redraw_ = true;
      // Showing the image costs GPU time too (tone mapping, blit): while the view is still, frames are
      // shown at most at the rate that keeps that cost within a quarter of the time.
      auto presentDue = [&] {
        return redraw_ || previewing_ || paused_ || done() || (now() - lastPresent_) * 1000.0 + 1e-3 >= 4.0 * displayMs_;
      };
      if (!paused_) {
        syncRenderer();
        double budget = config_.budgetMs;
        if (presentDue()) budget = std::max(budget - displayMs_, 0.25 * budget);
        renderWithin(budget);
      }
      if (screenshotPending_ && (paused_ || done())) {
        writeScreenshotPair();
        screenshotPending_ = false;
      }
      if (redraw_ || (newSamples_ && presentDue())) present();
    }
    updateTitle(false);
    ++frames_;
    if (config_.frameLimit > 0 && frames_ >= config_.frameLimit) break;
  }
  const double loopSeconds = now() - loopStart;
  const std::uint64_t loopSamples = samples_;
  const int loopPresented = presented_;
  if (config_.frameLimit > 0 && !closed) finishPass();
  if (config_.frameLimit > 0) {
    updateTitle(true);
    std::printf("%d frames in %.2f s (%.1f ms/frame), %d shown (%.1f fps), %.3g samples/s; %dx%d, %d spp\n", frames_,
                loopSeconds, 1000.0 * loopSeconds / std::max(frames_, 1), loopPresented,
                loopPresented / std::max(loopSeconds, 1e-9), static_cast<double>(loopSamples) / std::max(loopSeconds, 1e-9),
                renderer_->settings().width, renderer_->settings().height, renderer_->samplesPerPixel());
  }
  if (!config_.screenshotPath.empty()) {
    writeImage(config_.screenshotPath, renderer_->image(), config_.tone);
    std::printf("screenshot %s: %dx%d, %d spp\n", config_.screenshotPath.c_str(), renderer_->settings().width,
                renderer_->settings().height, renderer_->samplesPerPixel());
  }
  std::fflush(stdout);
  return 0;
}

#endif  // CAUSTICA_HAVE_GLFW

}  // namespace

int cmdView(const std::vector<std::string>& args) {
  std::vector<OptionSpec> specs = {
      {"--frames", "", "N", "scripted run: render N frames, complete the sample pass in flight, write --screenshot, exit"},
      {"--screenshot", "", "FILE", "image written at exit: .png (tone-mapped), .exr or .pfm (linear)"},
      {"--budget-ms", "", "MS", "path-tracing GPU time per frame in milliseconds (default 30)"},
      {"--spp", "", "N", "stop refining at N samples per pixel (default: never)"},
      {"--exposure", "", "STOPS", "display exposure in stops (default 0)"},
      {"--tonemap", "", "CURVE", "display tone curve: aces (default) or clamp"},
      {"--no-vsync", "", "", "do not wait for the display's vertical blank"},
      {"--no-preview", "", "", "always render at full resolution, also while the camera moves"},
      {"--spin", "", "DEG", "orbit the camera DEG degrees per frame (demos, preview benchmarks)"},
  };
  for (OptionSpec s : sceneOptionSpecs()) {
    if (s.name == "--backend") continue;  // a window brings its own context
    if (s.name == "--size") s.help = "render resolution (default: follows the window, which opens 960 wide)";
    specs.push_back(s);
  }
  Options opts("caustica view [SCENE] [options]",
               std::string("Opens a window showing SCENE (a .gltf/.glb file or a bundled scene name; default\n"
                           "cornell-glass) refining progressively: the same renderer as 'caustica render'.\n\n") +
                   kControls,
               specs);
  if (!opts.parse(args)) return 0;
#ifdef CAUSTICA_HAVE_GLFW
  ViewConfig config;
  config.quiet = opts.has("--quiet");
  config.frameLimit = opts.getInt("--frames", 0, 1, 1 << 30);
  config.screenshotPath = opts.get("--screenshot", "");
  if (!config.screenshotPath.empty()) checkImageExtension(config.screenshotPath);  // fail before any work
  config.budgetMs = opts.getDouble("--budget-ms", 30.0);
  if (config.budgetMs < 1.0 || config.budgetMs > 10000.0) throw Error("option --budget-ms needs 1 to 10000 milliseconds");
  config.maxSpp = opts.getInt("--spp", 0, 1, 1 << 24);
  config.vsync = !opts.has("--no-vsync");
  config.preview = !opts.has("--no-preview");
  config.spinRadians = opts.getDouble("--spin", 0.0) * 3.14159265358979 / 180.0;
  config.tone.exposureStops = static_cast<float>(opts.getDouble("--exposure", 0.0));
  config.tone.curve = parseToneCurve(opts.get("--tonemap", "aces"));
  config.fixedSize = opts.has("--size");
  Viewer viewer(opts, config);
  return viewer.run();
#else
  throw Error("this caustica was built without the viewer (CAUSTICA_VIEWER=OFF); use 'caustica render' for headless images");
#endif
}

}  // namespace caustica::cli
