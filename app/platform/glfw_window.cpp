// glfw_window.cpp — GLFW window front end (OpenGL 4.3 core context) for `caustica view`.
// GLFW is initialised by the window and terminated with it: one window per process.
#include "platform/glfw_window.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <cstdlib>

#include "util/error.h"

namespace caustica {

namespace {

std::string gLastGlfwError;  // GLFW reports errors through a callback; kept for the exception text

void onGlfwError(int code, const char* description) {
  gLastGlfwError = std::string(description ? description : "unknown error") + " (GLFW error " + std::to_string(code) + ")";
}

GlProc glfwLoader(const char* name) { return reinterpret_cast<GlProc>(glfwGetProcAddress(name)); }

GlfwWindow* self(GLFWwindow* w) { return static_cast<GlfwWindow*>(glfwGetWindowUserPointer(w)); }

const char* kUseRender = "use 'caustica render' for headless images";

}  // namespace

GlfwWindow::GlfwWindow(int width, int height, const std::string& title, bool vsync, std::string* description) {
  gLastGlfwError.clear();
  glfwSetErrorCallback(onGlfwError);
  const char* x11 = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if (!glfwInit()) {
    bool none = (!x11 || !*x11) && (!wayland || !*wayland);
    throw Error(std::string("no display: the viewer needs a window") +
                (none ? " (DISPLAY/WAYLAND_DISPLAY is not set)" : " (" + gLastGlfwError + ")") + "; " + kUseRender);
  }
  glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_DEPTH_BITS, 0);
  glfwWindowHint(GLFW_STENCIL_BITS, 0);
  glfwWindowHint(GLFW_SRGB_CAPABLE, GLFW_FALSE);  // the display image is sRGB-encoded already
  window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!window_) {
    std::string why = gLastGlfwError;
    glfwTerminate();
    throw Error("glfw: could not open a window with an OpenGL 4.3 core context (" + why + "); " + kUseRender);
  }
  glfwSetWindowUserPointer(window_, this);
  glfwSetKeyCallback(window_, onKey);
  glfwSetCharCallback(window_, onChar);
  glfwSetScrollCallback(window_, onScroll);
  glfwSetWindowRefreshCallback(window_, onRefresh);
  glfwSetFramebufferSizeCallback(window_, onFramebufferSize);
  glfwMakeContextCurrent(window_);
  try {
    std::string info = loadGl(glfwLoader, "glfw");
    if (description) *description = info;
  } catch (...) {
    glfwDestroyWindow(window_);
    glfwTerminate();
    throw;
  }
  setVsync(vsync);
}

GlfwWindow::~GlfwWindow() {
  if (window_) glfwDestroyWindow(window_);
  glfwTerminate();
  glfwSetErrorCallback(nullptr);
}

void GlfwWindow::makeCurrent() { glfwMakeContextCurrent(window_); }
bool GlfwWindow::shouldClose() const { return glfwWindowShouldClose(window_) != 0; }
void GlfwWindow::requestClose() { glfwSetWindowShouldClose(window_, GLFW_TRUE); }

void GlfwWindow::clearInput() {
  keyPresses_.clear();
  characters_.clear();
  wheel_ = 0.0;
  exposed_ = false;
}

void GlfwWindow::pollEvents() {
  clearInput();
  glfwPollEvents();
}

void GlfwWindow::waitEvents(double timeoutSeconds) {
  clearInput();
  glfwWaitEventsTimeout(timeoutSeconds);
}

void GlfwWindow::swapBuffers() { glfwSwapBuffers(window_); }
void GlfwWindow::setVsync(bool on) { glfwSwapInterval(on ? 1 : 0); }
void GlfwWindow::setTitle(const std::string& title) { glfwSetWindowTitle(window_, title.c_str()); }
void GlfwWindow::framebufferSize(int& width, int& height) const { glfwGetFramebufferSize(window_, &width, &height); }
void GlfwWindow::windowSize(int& width, int& height) const { glfwGetWindowSize(window_, &width, &height); }

bool GlfwWindow::keyDown(int key) const { return glfwGetKey(window_, key) == GLFW_PRESS; }
bool GlfwWindow::mouseDown(int button) const { return glfwGetMouseButton(window_, button) == GLFW_PRESS; }
void GlfwWindow::cursor(double& x, double& y) const { glfwGetCursorPos(window_, &x, &y); }

void GlfwWindow::onKey(GLFWwindow* w, int key, int, int action, int mods) {
  if (action == GLFW_PRESS || action == GLFW_REPEAT) self(w)->keyPresses_.push_back({key, mods, action == GLFW_REPEAT});
}
void GlfwWindow::onChar(GLFWwindow* w, unsigned codepoint) { self(w)->characters_.push_back(codepoint); }
void GlfwWindow::onScroll(GLFWwindow* w, double, double dy) { self(w)->wheel_ += dy; }
void GlfwWindow::onRefresh(GLFWwindow* w) { self(w)->exposed_ = true; }
void GlfwWindow::onFramebufferSize(GLFWwindow* w, int, int) { self(w)->exposed_ = true; }

}  // namespace caustica
