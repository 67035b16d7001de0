// context.cpp — backend selection for headless contexts, and the GL loader shared by all front ends.
#include "platform/context.h"

#include <glad/gl.h>

#include "util/error.h"

namespace caustica {

namespace {
GlProc (*gActiveLoader)(const char*) = nullptr;
GLADapiproc gladLoader(const char* name) { return reinterpret_cast<GLADapiproc>(gActiveLoader(name)); }
std::string glString(GLenum name) {
  const GLubyte* s = glGetString(name);
  return s ? reinterpret_cast<const char*>(s) : "?";
}
}  // namespace

std::string loadGl(GlProc (*getProcAddress)(const char*), const std::string& backend) {
  gActiveLoader = getProcAddress;
  int version = gladLoadGL(gladLoader);
  if (version == 0) throw Error(backend + ": could not load OpenGL entry points");
  int major = GLAD_VERSION_MAJOR(version), minor = GLAD_VERSION_MINOR(version);
  if (major < 4 || (major == 4 && minor < 3))
    throw Error(backend + ": OpenGL 4.3 core is required, the context offers " + std::to_string(major) + "." +
                std::to_string(minor) + " (" + glString(GL_RENDERER) + ")");
  return glString(GL_VENDOR) + " | " + glString(GL_RENDERER) + " | " + glString(GL_VERSION);
}

Backend parseBackend(const std::string& name) {
  if (name == "auto") return Backend::Auto;
  if (name == "egl") return Backend::Egl;
  if (name == "osmesa") return Backend::OSMesa;
  throw Error("unknown backend '" + name + "' (expected auto, egl or osmesa)");
}

std::unique_ptr<GlContext> createHeadlessContext(Backend backend, std::string* description) {
  if (backend == Backend::Egl) return createEglContext(description);
  if (backend == Backend::OSMesa) return createOSMesaContext(description);
  std::string reasons;
  try {
    return createEglContext(description);
  } catch (const Error& e) {
    reasons = std::string("egl: ") + e.what();
  }
  try {
    return createOSMesaContext(description);
  } catch (const Error& e) {
    throw Error("no headless OpenGL 4.3 context could be created (" + reasons + "; osmesa: " + e.what() + ")");
  }
}

}  // namespace caustica
