// gl_limits.h — the limits of the current GL implementation that matter to caustica, and the checks
// that turn them into clear errors before anything is uploaded.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>

namespace caustica {

struct GlLimits {
  std::int64_t maxStorageBlockSize = 0;  // bytes per SSBO (lowered by $CAUSTICA_MAX_SSBO_BYTES)
  int maxComputeStorageBlocks = 0;   // (lowered by $CAUSTICA_MAX_SSBO_BLOCKS)
  int maxStorageBufferBindings = 0;  // GL_MAX_SHADER_STORAGE_BUFFER_BINDINGS
  int maxWorkGroupInvocations = 0;
  int maxTextureSize = 0;
  int maxWorkGroupCount[2] = {0, 0};
};
// Needs a current GL context.
GlLimits queryGlLimits();

// Throws Error unless a width x height accumulation image and its dispatch fit these limits.
void checkImageSize(const GlLimits& limits, int width, int height);

}  // namespace caustica
