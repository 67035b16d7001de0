// gl_objects.h — RAII owners of OpenGL objects (buffers, textures, programs, framebuffers).
// gl_objects.cpp is the only place that creates or deletes GL objects; everything else holds these.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <glad/gl.h>

namespace caustica {

// A move-only GL name with its deleter.
class GlHandle {
 public:
  GlHandle() = default;
  GlHandle(GLuint id, void (*destroy)(GLuint)) : id_(id), destroy_(destroy) {}
  GlHandle(GlHandle&& o) noexcept : id_(std::exchange(o.id_, 0)), destroy_(o.destroy_) {}
  GlHandle& operator=(GlHandle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, 0);
      destroy_ = o.destroy_;
    }
    return *this;
  }
  GlHandle(const GlHandle&) = delete;
  GlHandle& operator=(const GlHandle&) = delete;
  ~GlHandle() { reset(); }
  GLuint id() const { return id_; }
  explicit operator bool() const { return id_ != 0; }
  void reset() {
    if (id_ && destroy_) destroy_(id_);
    id_ = 0;
  }

 private:
  GLuint id_ = 0;
  void (*destroy_)(GLuint) = nullptr;
};

// Buffer object used as SSBO or UBO. Sizes in bytes.
class GlBuffer {
 public:
  GlBuffer() = default;
  // Creates a buffer of `bytes` (at least 16, so empty arrays still bind) holding `data` (may be null).
  static GlBuffer create(std::size_t bytes, const void* data, GLenum usage = GL_STATIC_DRAW);
  template <class T>
  static GlBuffer fromVector(const std::vector<T>& v, GLenum usage = GL_STATIC_DRAW) {
    return create(v.size() * sizeof(T), v.empty() ? nullptr : v.data(), usage);
  }
  void update(std::size_t offset, std::size_t bytes, const void* data);
  void read(std::size_t offset, std::size_t bytes, void* out) const;
  void bindBase(GLenum target, GLuint index) const;
  std::size_t size() const { return size_; }
  GLuint id() const { return handle_.id(); }

 private:
  GlHandle handle_;
  std::size_t size_ = 0;
};

// Immutable-storage 2D texture used as an image (rgba32f accumulation, rgba8 display).
class GlTexture {
 public:
  GlTexture() = default;
  static GlTexture create2D(int width, int height, GLenum internalFormat);
  void clear();  // zero every texel
  void bindImage(GLuint unit, GLenum access) const;
  std::vector<float> readRgba32f() const;  // width*height*4 floats, row 0 first
  // Replaces every texel of an rgba32f texture with `rgba` (width*height*4 floats, row 0 first).
  void uploadRgba32f(const std::vector<float>& rgba);
  // r32ui texture: writes `values` row by row from texel (0, 0), the last row padded with zeros.
  void uploadR32uiRows(const std::vector<std::uint32_t>& values);
  int width() const { return width_; }
  int height() const { return height_; }
  GLuint id() const { return handle_.id(); }

 private:
  GlHandle handle_;
  int width_ = 0, height_ = 0;
  GLenum format_ = 0;
};

// A linked compute program.
class GlProgram {
 public:
  GlProgram() = default;
  // Compiles and links; on failure throws Error whose message is `mapLog(driver log)`.
  static GlProgram compileCompute(const std::string& source, const std::function<std::string(const std::string&)>& mapLog,
                                  const std::string& name);
  void use() const;
  GLint uniformLocation(const char* name) const;
  GLuint id() const { return handle_.id(); }

 private:
  GlHandle handle_;
};

// A read framebuffer with one colour texture, used to blit the display image to a window.
class GlFramebuffer {
 public:
  GlFramebuffer() = default;
  static GlFramebuffer forTexture(const GlTexture& texture);
  void blitToDefault(int srcW, int srcH, int dstW, int dstH) const;

 private:
  GlHandle handle_;
};

// Throws Error naming `what` if the GL error flag is set.
void checkGlError(const char* what);

}  // namespace caustica
