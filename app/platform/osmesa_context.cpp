// osmesa_context.cpp — headless OpenGL 4.3 core context through OSMesa (Mesa's llvmpipe on the CPU).
// The renderer draws nothing to the default framebuffer, so a 1×1 colour buffer is enough.
#include <glad/gl.h>
// glad's header stands in for GL/gl.h, which osmesa.h would otherwise include.
#include <GL/osmesa.h>

#include <array>

#include "util/error.h"
#include "platform/context.h"

namespace caustica {

namespace {

GlProc osmesaLoader(const char* name) { return reinterpret_cast<GlProc>(OSMesaGetProcAddress(name)); }

class OSMesaGlContext : public GlContext {
 public:
  explicit OSMesaGlContext(OSMesaContext context) : context_(context) {}
  ~OSMesaGlContext() override { OSMesaDestroyContext(context_); }
  std::string backendName() const override { return "osmesa"; }
  void makeCurrent() override {
    if (!OSMesaMakeCurrent(context_, pixel_.data(), GL_UNSIGNED_BYTE, 1, 1))
      throw Error("osmesa: OSMesaMakeCurrent failed");
  }

 private:
  OSMesaContext context_;
  std::array<unsigned char, 4> pixel_{};
};

}  // namespace

std::unique_ptr<GlContext> createOSMesaContext(std::string* description) {
  const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0, OSMESA_STENCIL_BITS, 0,
                         OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, 4,
                         OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
  OSMesaContext context = OSMesaCreateContextAttribs(attribs, nullptr);
  if (!context) throw Error("osmesa: could not create an OpenGL 4.3 core context");
  auto result = std::make_unique<OSMesaGlContext>(context);
  result->makeCurrent();
  std::string info = loadGl(osmesaLoader, "osmesa");
  if (description) *description = info;
  return result;
}

}  // namespace caustica
