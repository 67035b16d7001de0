// viewer.cpp — the viewer's loop: input, renderer settings and resolution, path tracing in row bands
// paced by FramePacer, presentation, title and screenshots. Times in seconds unless named ms.
#include "cli/view/viewer.h"

#ifdef CAUSTICA_HAVE_GLFW
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>

#include "cli/environment_options.h"
#include "gpu/adaptive_sampler.h"
#include "image/image_io.h"
#include "util/error.h"

namespace caustica::cli {

namespace {

constexpr int kDefaultWidth = 960;  // window width in pixels when --size is not given

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

}  // namespace

Viewer::Viewer(const Options& opts, const ViewConfig& config)
    : config_(config), pacer_(PacingConfig{config.budgetMs, config.maxSpp, config.preview, config.frameLimit > 0}) {
  scene_ = loadSceneForCli(opts, !config_.quiet, kDefaultWidth);  // every image setting, the scene's applied
  sceneName_ = fileStem(scene_.scene.path);
  RenderSettings settings = scene_.settings.render;
  flattenForMode(scene_.scene, settings.mode, opts, config_.quiet);  // raster draws flat scenes
  controls_.instancedScene = !scene_.scene.instances.empty();  // M skips the modes that draw flat scenes only
  controls_.wanted = settings;
  controls_.tone = scene_.settings.tone;
  controls_.stopAtTarget = config_.targetError > 0.0;
  controls_.denoise = config_.denoise;
  if (config_.targetError > 0.0) controls_.targetError = config_.targetError;
  input_ = ViewerInput(controls_, config_.spinRadians);

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
  renderer_->setFeatureBuffers(controls_.denoise);  // the denoiser's inputs (kept once on: N only changes the display)
  warmUp();
  present();  // compiles the tone-mapping shader and whatever the blit needs, before anything is timed
  presented_ = 0;
  controller_ = std::make_unique<CameraController>(scene_.camera, scene_.scene.bounds);
  appliedRevision_ = controller_->revision();
  note(config_.quiet, scene_.scene.path + ": " + std::to_string(scene_.scene.triangles.size()) + " triangles, features: " +
                          renderer_->sceneFeatures().describe() + "; " + std::to_string(fullW_) + "x" +
                          std::to_string(fullH_) + ", " + integratorName(controls_.wanted.integrator) +
                          "; press H for the controls");
  double x = 0.0, y = 0.0;
  window_->cursor(x, y);
  input_.setCursor(x, y);
  pacer_.noteMotion(now());  // start like a camera change: a preview first if full passes are slow
}

// ---- rendering -----------------------------------------------------------------------------------

void Viewer::syncRenderer() {
  // Settings first, at the current resolution (chosen below); a new shader variant is warmed up.
  RenderSettings next = controls_.wanted;
  next.width = renderer_->settings().width;
  next.height = renderer_->settings().height;
  SettingsChange change = renderer_->apply(next);
  bool restarted = change.restart;
  if (controls_.denoise && !renderer_->featureBuffers()) {  // N turned the denoiser on: it needs the feature sums
    renderer_->setFeatureBuffers(true);
    change.shader = restarted = true;
  }
  if (change.shader) warmUp();
  if (controller_->revision() != appliedRevision_) {
    renderer_->setCamera(controller_->camera());
    appliedRevision_ = controller_->revision();
    restarted = true;
  }
  ResolutionChoice res = pacer_.chooseResolution(fullW_, fullH_, now(), restarted);
  if (res.leftPreview) presenter_.keepPreview(*renderer_, controls_.tone, showDenoised());
  if (resizeRenderer(res.width, res.height)) restarted = true;
  if (restarted) {
    estimate_ = std::numeric_limits<double>::infinity();
    nextEstimate_ = 0;
    pacer_.restartPass();
    showPreviewCopy_ = res.leftPreview;
    controls_.redraw = true;
  }
}

bool Viewer::resizeRenderer(int width, int height) {
  RenderSettings r = renderer_->settings();
  r.width = width;
  r.height = height;
  if (!renderer_->apply(r).resize) return false;
  presenter_.imageResized();
  return true;
}

void Viewer::warmUp() {
  // Drivers may compile a shader variant at its first dispatch (llvmpipe does, taking ~1 s): do that
  // on one row now, so the time model never sees it.
  renderer_->renderRows(0, 1, 1);
  renderer_->reset();
}

void Viewer::renderWithin(double budgetMs, bool stopAtPassEnd) {
  if (done()) return;
  const double t0 = now();
  const int w = renderer_->settings().width, h = renderer_->settings().height;
  auto remainingMs = [&] { return budgetMs - (now() - t0) * 1000.0; };
  for (;;) {
    Band band = pacer_.nextBand(w, h, renderer_->samplesPerPixel(), remainingMs());
    double t = now();
    renderer_->renderRows(band.y0, band.y1, band.spp);  // returns when the GPU is done (it reads counters back)
    bool passDone = pacer_.finishBand(band, w, h, (now() - t) * 1000.0);
    samples_ += static_cast<std::uint64_t>(band.rows()) * static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(band.spp);
    newSamples_ = true;
    if (passDone) {
      renderer_->endPass(band.spp);
      estimateAfterPass();
      if (!pacer_.previewing()) {
        showPreviewCopy_ = false;
        if (controls_.screenshotPending) {
          writeScreenshotPair();
          controls_.screenshotPending = false;
        }
      }
      if (done() || stopAtPassEnd) break;
    }
    if (!pacer_.nextRowFits(w, remainingMs())) break;
  }
}

// The error estimate reads three images back: only at the schedule of AdaptiveSampler (16 spp, then
// each +1/8), whether or not a target is set, so the title can show it.
void Viewer::estimateAfterPass() {
  const int spp = renderer_->samplesPerPixel();
  if (pacer_.previewing() || spp < nextEstimate_ || spp < 2) return;
  if (nextEstimate_ == 0) nextEstimate_ = AdaptiveSampler(1.0, false).checkAtOrAfter(spp);
  if (spp < nextEstimate_) return;
  estimate_ = renderer_->errorEstimate().image;
  nextEstimate_ = AdaptiveSampler(1.0, false).checkAtOrAfter(spp + 1);
}

// Showing the image costs GPU time too (tone mapping, blit): while the view is still, frames are shown
// at most at the rate that keeps that cost within a quarter of the time.
bool Viewer::presentDue() const {
  return controls_.redraw || controls_.paused || done() || pacer_.presentDue((now() - lastPresent_) * 1000.0);
}

void Viewer::present() {
  int ww = 0, wh = 0;
  window_->framebufferSize(ww, wh);
  if (ww <= 0 || wh <= 0) return;
  double t = now();
  std::optional<int> finishedRows;  // first full pass in flight: its rows over the preview
  if (showPreviewCopy_ && !pacer_.previewing() && renderer_->samplesPerPixel() == 0) finishedRows = pacer_.passRow();
  const bool denoised = showDenoised();
  presenter_.draw(*renderer_, controls_.tone, ww, wh, finishedRows, denoised);
  const double filterMs = renderer_->denoiseMsTotal() - filterMsSeen_;  // this frame's filter runs (they wait for the GPU)
  filterMsSeen_ = renderer_->denoiseMsTotal();
  if (denoised) {
    // The first is left out: llvmpipe compiles the programs at their first dispatch (about a second).
    if (denoised_ > 0) {
      denoiseMs_ += (denoised_ == 1 ? 1.0 : 0.1) * (filterMs - denoiseMs_);
      filterMsSum_ += filterMs;
    }
    ++denoised_;
  }
  pacer_.recordDisplay((now() - t) * 1000.0, presented_);
  window_->swapBuffers();
  controls_.redraw = newSamples_ = false;
  double end = now();
  if (presented_ > 0) frameMs_ += (presented_ == 1 ? 1.0 : 0.1) * ((end - lastPresent_) * 1000.0 - frameMs_);
  lastPresent_ = end;
  ++presented_;
}

void Viewer::finishPass() {
  pacer_.settle();
  for (;;) {
    syncRenderer();
    if (done() || (!pacer_.previewing() && pacer_.passRow() == 0 && renderer_->samplesPerPixel() > 0)) break;
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
  const RenderSettings& wanted = controls_.wanted;
  std::string title = "caustica view - " + sceneName_ + " | " +
                      lightingTag(scene_.scene, renderer_->gpuScene().emitterCount) + " | " + std::to_string(renderer_->samplesPerPixel()) + " spp | " +
                      format("%.3g samples/s", samplesPerSecond_) + " | " + format("%.1f ms/frame", frameMs_) + " | " +
                      integratorName(wanted.integrator) +
                      (wanted.integrator == Integrator::Mis && !renderer_->gpuScene().casters.empty()
                           ? (wanted.casterProbability > 0.0f ? " + casters" : " no casters")
                           : "") +
                      " | " + dispersionModeName(wanted.dispersion) + " | depth " + std::to_string(wanted.maxDepth) +
                      " | " + format("exposure %+.1f", controls_.tone.exposureStops) + " | non-finite " +
                      std::to_string(renderer_->stats().nonFinite);
  if (std::isfinite(estimate_)) title += format(" | relMSE~%.3g", estimate_);
  if (controls_.stopAtTarget) title += format(" | target %.3g", controls_.targetError);
  if (pacer_.previewing()) title += " | preview 1/" + std::to_string(pacer_.previewScale());
  if (controls_.fly) title += " | fly";
  title += showDenoised() ? format(" | denoised (N) %.1f ms", denoiseMs_) : std::string(" | raw (N)");
  if (controls_.paused) title += " | paused";
  if (done()) title += " | done";
  window_->setTitle(title);
}

Image Viewer::shownImage() const { return showDenoised() ? renderer_->denoisedImage() : renderer_->image(); }

void Viewer::writeScreenshotPair() {
  std::string base = "caustica-" + sceneName_ + "-" + std::to_string(renderer_->samplesPerPixel()) + "spp" +
                     (showDenoised() ? "-denoised" : "");
  try {
    Image img = shownImage();
    writeImage(base + ".png", img, controls_.tone);
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
    bool idle = controls_.paused || done();
    if (idle && !controls_.redraw && !newSamples_ && !controls_.screenshotPending) window_->waitEvents(0.1);
    else window_->pollEvents();
    if (window_->shouldClose()) {
      closed = true;
      break;
    }
    double t = now();
    if (input_.apply(*window_, *controller_, controls_, std::min(t - lastInput_, 0.1))) pacer_.noteMotion(now());
    lastInput_ = t;
    int fw = 0, fh = 0;
    window_->framebufferSize(fw, fh);
    if (fw > 0 && fh > 0) {  // not minimised
      if (!config_.fixedSize && (fw != fullW_ || fh != fullH_)) {
        fullW_ = fw;
        fullH_ = fh;
        pacer_.noteMotion(t);
      }
      if (window_->exposed()) controls_.redraw = true;
      if (!controls_.paused) {
        syncRenderer();
        renderWithin(pacer_.tracingBudgetMs(presentDue()));
      }
      if (controls_.screenshotPending && (controls_.paused || done())) {
        writeScreenshotPair();
        controls_.screenshotPending = false;
      }
      if (controls_.redraw || (newSamples_ && presentDue())) present();
    }
    updateTitle(false);
    ++frames_;
    if (config_.frameLimit > 0 && frames_ >= config_.frameLimit) break;
  }
  const double loopSeconds = now() - loopStart;
  const std::uint64_t loopSamples = samples_;
  const int loopPresented = presented_;
  // The filter's mean time per shown frame over the same frames as the loop's figures (not finishPass's).
  const double loopFilterMs = denoised_ > 1 ? filterMsSum_ / (denoised_ - 1) : 0.0;
  const int loopDenoised = denoised_;
  if (config_.frameLimit > 0 && !closed) finishPass();
  if (config_.frameLimit > 0) {
    updateTitle(true);
    std::printf("%d frames in %.2f s (%.1f ms/frame), %d shown (%.1f fps), %.3g samples/s; %dx%d, %d spp%s%s\n", frames_,
                loopSeconds, 1000.0 * loopSeconds / std::max(frames_, 1), loopPresented,
                loopPresented / std::max(loopSeconds, 1e-9), static_cast<double>(loopSamples) / std::max(loopSeconds, 1e-9),
                renderer_->settings().width, renderer_->settings().height, renderer_->samplesPerPixel(),
                std::isfinite(estimate_) ? format(", relMSE~%.3g", estimate_).c_str() : "",
                loopDenoised > 1 ? format("; denoised, filter %.1f ms a shown frame", loopFilterMs).c_str()
                                 : loopDenoised ? "; denoised" : "; raw");
    if (controls_.stopAtTarget && done()) std::printf("target relMSE %.3g reached\n", controls_.targetError);
  }
  if (!config_.screenshotPath.empty()) {
    writeImage(config_.screenshotPath, shownImage(), controls_.tone);
    std::printf("screenshot %s: %dx%d, %d spp%s\n", config_.screenshotPath.c_str(), renderer_->settings().width,
                renderer_->settings().height, renderer_->samplesPerPixel(), showDenoised() ? ", denoised" : "");
  }
  std::fflush(stdout);
  return 0;
}

}  // namespace caustica::cli

#endif  // CAUSTICA_HAVE_GLFW
