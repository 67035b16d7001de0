// context.h — creates a headless OpenGL 4.3 core context: EGL (GPU drivers, Mesa) or OSMesa (llvmpipe).
#pragma once
#include <memory>
#include <string>

#include "platform/gl_context.h"

namespace caustica {

enum class Backend { Auto, Egl, OSMesa };

Backend parseBackend(const std::string& name);  // "auto" | "egl" | "osmesa"; throws Error otherwise

// Creates and makes current a headless context; Auto tries EGL, then OSMesa. Throws Error when none
// works, with the reason of each attempt. `description` receives "vendor | renderer | version".
std::unique_ptr<GlContext> createHeadlessContext(Backend backend, std::string* description = nullptr);

std::unique_ptr<GlContext> createEglContext(std::string* description);
std::unique_ptr<GlContext> createOSMesaContext(std::string* description);

}  // namespace caustica
