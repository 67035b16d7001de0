// egl_context.cpp — headless OpenGL 4.3 core context through EGL without any surface.
// Tries the device platform (NVIDIA's headless driver, Mesa's software device), then Mesa's
// surfaceless platform, then the default display.
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstring>
#include <vector>

#include "util/error.h"
#include "platform/context.h"

namespace caustica {

namespace {

bool hasExtension(const char* list, const char* name) {
  if (!list) return false;
  size_t n = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += n)
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  return false;
}

std::string eglErrorName(EGLint e) {
  switch (e) {
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    default: return "EGL error " + std::to_string(e);
  }
}

GlProc eglLoader(const char* name) { return reinterpret_cast<GlProc>(eglGetProcAddress(name)); }

class EglContext : public GlContext {
 public:
  EglContext(EGLDisplay display, EGLContext context) : display_(display), context_(context) {}
  ~EglContext() override {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_, context_);
    eglTerminate(display_);
  }
  std::string backendName() const override { return "egl"; }
  void makeCurrent() override {
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
      throw Error("egl: eglMakeCurrent failed: " + eglErrorName(eglGetError()));
  }

 private:
  EGLDisplay display_;
  EGLContext context_;
};

// Creates a GL 4.3 core context on an initialised display, or returns EGL_NO_CONTEXT and a reason.
EGLContext createContextOn(EGLDisplay display, std::string& reason) {
  if (!eglBindAPI(EGL_OPENGL_API)) {
    reason = "eglBindAPI(EGL_OPENGL_API) failed";
    return EGL_NO_CONTEXT;
  }
  const char* ext = eglQueryString(display, EGL_EXTENSIONS);
  EGLConfig config = nullptr;
  const EGLint configAttribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
  EGLint count = 0;
  if (!eglChooseConfig(display, configAttribs, &config, 1, &count) || count == 0) {
    if (!hasExtension(ext, "EGL_KHR_no_config_context")) {
      reason = "no EGL config supports desktop OpenGL";
      return EGL_NO_CONTEXT;
    }
    config = nullptr;  // EGL_NO_CONFIG_KHR
  }
  const EGLint contextAttribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 3,
                                   EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, contextAttribs);
  if (context == EGL_NO_CONTEXT) {
    reason = "eglCreateContext(OpenGL 4.3 core) failed: " + eglErrorName(eglGetError());
    return EGL_NO_CONTEXT;
  }
  if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
    reason = "eglMakeCurrent without a surface failed: " + eglErrorName(eglGetError());
    eglDestroyContext(display, context);
    return EGL_NO_CONTEXT;
  }
  return context;
}

}  // namespace

std::unique_ptr<GlContext> createEglContext(std::string* description) {
  const char* clientExt = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  auto getPlatformDisplay =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  std::vector<EGLDisplay> candidates;
  if (getPlatformDisplay && hasExtension(clientExt, "EGL_EXT_platform_device")) {
    auto queryDevices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    EGLDeviceEXT devices[16];
    EGLint numDevices = 0;
    if (queryDevices && queryDevices(16, devices, &numDevices))
      for (EGLint i = 0; i < numDevices; ++i)
        candidates.push_back(getPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr));
  }
  if (getPlatformDisplay && hasExtension(clientExt, "EGL_MESA_platform_surfaceless"))
    candidates.push_back(getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr));
  candidates.push_back(eglGetDisplay(EGL_DEFAULT_DISPLAY));

  std::string reasons;
  for (EGLDisplay display : candidates) {
    if (display == EGL_NO_DISPLAY) continue;
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display, &major, &minor)) {
      reasons += (reasons.empty() ? "" : "; ") + std::string("eglInitialize: ") + eglErrorName(eglGetError());
      continue;
    }
    std::string reason;
    EGLContext context = createContextOn(display, reason);
    if (context == EGL_NO_CONTEXT) {
      reasons += (reasons.empty() ? "" : "; ") + reason;
      eglTerminate(display);
      continue;
    }
    auto result = std::make_unique<EglContext>(display, context);
    try {
      std::string info = loadGl(eglLoader, "egl");
      if (description) *description = info;
    } catch (const Error& e) {
      reasons += (reasons.empty() ? "" : "; ") + std::string(e.what());
      continue;  // result's destructor releases this display
    }
    return result;
  }
  throw Error("egl: no display offers an OpenGL 4.3 core context" + (reasons.empty() ? "" : " (" + reasons + ")"));
}

}  // namespace caustica
