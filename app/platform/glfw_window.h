// glfw_window.h — a GLFW window with an OpenGL 4.3 core context: the viewer's GlContext, plus the
// input it needs (key presses, typed characters, mouse buttons, cursor, wheel) and buffer swaps.
#pragma once
#include <string>
#include <vector>

#include "platform/gl_context.h"

struct GLFWwindow;

namespace caustica {

// A key press (or auto-repeat) with GLFW key and modifier codes (GLFW_KEY_*, GLFW_MOD_*).
struct KeyPress {
  int key = 0;
  int mods = 0;
  bool repeat = false;
};

class GlfwWindow : public GlContext {
 public:
  // Opens a window of width x height screen coordinates with a 4.3 core forward-compatible context,
  // makes it current, loads GL and sets vsync. `description` receives "vendor | renderer | version".
  // Throws Error: with no usable display the message says so and points to 'caustica render'.
  GlfwWindow(int width, int height, const std::string& title, bool vsync, std::string* description = nullptr);
  ~GlfwWindow() override;
  GlfwWindow(const GlfwWindow&) = delete;
  GlfwWindow& operator=(const GlfwWindow&) = delete;

  std::string backendName() const override { return "glfw"; }
  void makeCurrent() override;

  bool shouldClose() const;
  void requestClose();
  // Processes pending events. Both first clear the input gathered since the previous call.
  void pollEvents();
  void waitEvents(double timeoutSeconds);
  void swapBuffers();
  void setVsync(bool on);
  void setTitle(const std::string& title);
  void framebufferSize(int& width, int& height) const;  // pixels
  void windowSize(int& width, int& height) const;       // screen coordinates (the cursor's units)

  // Input gathered by the last pollEvents()/waitEvents().
  const std::vector<KeyPress>& keyPresses() const { return keyPresses_; }
  const std::vector<unsigned>& characters() const { return characters_; }  // Unicode code points typed
  double wheel() const { return wheel_; }  // notches; positive: scrolled up / away from the user
  bool exposed() const { return exposed_; }  // the window needs redrawing (damage, resize)
  // Current state.
  bool keyDown(int key) const;
  bool mouseDown(int button) const;
  void cursor(double& x, double& y) const;  // screen coordinates from the top-left corner

 private:
  void clearInput();
  static void onKey(GLFWwindow* w, int key, int scancode, int action, int mods);
  static void onChar(GLFWwindow* w, unsigned codepoint);
  static void onScroll(GLFWwindow* w, double dx, double dy);
  static void onRefresh(GLFWwindow* w);
  static void onFramebufferSize(GLFWwindow* w, int width, int height);

  GLFWwindow* window_ = nullptr;
  std::vector<KeyPress> keyPresses_;
  std::vector<unsigned> characters_;
  double wheel_ = 0.0;
  bool exposed_ = false;
};

}  // namespace caustica
