// gl_context.h — the one small interface every OpenGL front end implements (EGL, OSMesa, GLFW).
// The renderer only needs a current GL 4.3 core context; it never knows which kind it is.
#pragma once
#include <string>

namespace caustica {

class GlContext {
 public:
  virtual ~GlContext() = default;
  virtual std::string backendName() const = 0;  // "egl", "osmesa" or "glfw"
  virtual void makeCurrent() = 0;
};

// Loads the GL 4.3 core entry points through `getProcAddress` for the current context, checks the
// version, and returns a one-line "vendor | renderer | version" description. Throws Error on failure.
using GlProc = void (*)();
std::string loadGl(GlProc (*getProcAddress)(const char*), const std::string& backend);

}  // namespace caustica
