// gl_limits.cpp — queries and checks GL implementation limits (see gl_limits.h).
#include "gpu/gl_limits.h"

#include <cstdio>
#include <cstdlib>

#include "gpu/gl_objects.h"
#include "shared/gpu_layout.h"
#include "util/error.h"

namespace caustica {

GlLimits queryGlLimits() {
  GlLimits l;
  GLint64 block = 0;
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &block);
  l.maxStorageBlockSize = block;
  // CAUSTICA_MAX_SSBO_BYTES lowers the limit, to see how a scene fares on a GPU that offers only the
  // 16 MiB the specification guarantees (used by the tests).
  if (const char* env = std::getenv("CAUSTICA_MAX_SSBO_BYTES")) {
    long long cap = std::atoll(env);
    if (cap > 0 && cap < l.maxStorageBlockSize) l.maxStorageBlockSize = cap;
  }
  glGetIntegerv(GL_MAX_COMPUTE_SHADER_STORAGE_BLOCKS, &l.maxComputeStorageBlocks);
  glGetIntegerv(GL_MAX_SHADER_STORAGE_BUFFER_BINDINGS, &l.maxStorageBufferBindings);
  // CAUSTICA_MAX_SSBO_BLOCKS lowers the block count, e.g. to the 8 GL 4.3 guarantees (tests).
  if (const char* env = std::getenv("CAUSTICA_MAX_SSBO_BLOCKS")) {
    long long cap = std::atoll(env);
    if (cap > 0 && cap < l.maxComputeStorageBlocks) l.maxComputeStorageBlocks = static_cast<int>(cap);
  }
  glGetIntegerv(GL_MAX_COMPUTE_WORK_GROUP_INVOCATIONS, &l.maxWorkGroupInvocations);
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &l.maxTextureSize);
  glGetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_COUNT, 0, &l.maxWorkGroupCount[0]);
  glGetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_COUNT, 1, &l.maxWorkGroupCount[1]);
  return l;
}

void checkImageSize(const GlLimits& l, int w, int h) {
  if (w < 1 || h < 1) throw Error("image size must be at least 1x1");
  if (w > l.maxTextureSize || h > l.maxTextureSize)
    throw Error("image size " + std::to_string(w) + "x" + std::to_string(h) + " exceeds this GPU's texture limit of " +
                std::to_string(l.maxTextureSize));
  int gx = (w + CAUSTICA_WORKGROUP_X - 1) / CAUSTICA_WORKGROUP_X, gy = (h + CAUSTICA_WORKGROUP_Y - 1) / CAUSTICA_WORKGROUP_Y;
  if (gx > l.maxWorkGroupCount[0] || gy > l.maxWorkGroupCount[1]) throw Error("image too large for one compute dispatch");
}

}  // namespace caustica
