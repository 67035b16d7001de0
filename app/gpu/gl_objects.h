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
  // r32f texture (the coverage image): width*height floats, row 0 first.
  std::vector<float> readR32f() const;
  void uploadR32f(const std::vector<float>& values);
  // r32ui texture: writes `values` row by row from texel (0, 0), the last row padded with zeros.
  void uploadR32uiRows(const std::vector<std::uint32_t>& values);
  // Raster mode: an sRGB RGBA8 colour texture with mipmaps (rgba8: width*height*4 bytes, row 0 =
  // t 0), wrap GL_REPEAT / GL_MIRRORED_REPEAT / GL_CLAMP_TO_EDGE per axis, nearest or trilinear.
  static GlTexture createSrgb8(int width, int height, const void* rgba8, GLenum wrapS, GLenum wrapT, bool nearest);
  // Raster mode: a depth-stencil render target (GL_DEPTH24_STENCIL8).
  static GlTexture createDepthStencil(int width, int height);
  // Raster mode: `cubes` depth cube maps of `size`^2 texels per face (GL_TEXTURE_CUBE_MAP_ARRAY,
  // GL_DEPTH_COMPONENT32F, linear filtering, no comparison); layer = cube * 6 + face.
  static GlTexture createDepthCubeArray(int size, int cubes);
  int width() const { return width_; }
  int height() const { return height_; }
  GLuint id() const { return handle_.id(); }

 private:
  // A new texture name of that size and format, without storage: what every create* starts from.
  static GlTexture generate(int width, int height, GLenum internalFormat);
  // Whole-level float transfers behind read/upload*: pixel format GL_RGBA or GL_RED, row 0 first.
  std::vector<float> readFloats(GLenum format, int channels) const;
  void uploadFloats(GLenum format, const std::vector<float>& values);
  GlHandle handle_;
  int width_ = 0, height_ = 0;
  GLenum format_ = 0;
};

// A buffer texture (GL_TEXTURE_BUFFER): the bytes of a GlBuffer read as texels of `internalFormat`
// (e.g. GL_RGBA32UI) by texelFetch on a (u)samplerBuffer. The buffer must outlive the texture's use.
class GlBufferTexture {
 public:
  GlBufferTexture() = default;
  static GlBufferTexture create(const GlBuffer& buffer, GLenum internalFormat);
  void bind(GLuint unit) const;  // on texture unit `unit`; leaves GL_TEXTURE0 active
  GLuint id() const { return handle_.id(); }

 private:
  GlHandle handle_;
};

// A linked compute program (or, for the raster mode, a vertex + fragment program).
class GlProgram {
 public:
  GlProgram() = default;
  // Vertex and fragment stages; errors name `name` and the stage, with each log mapped by its mapLog.
  static GlProgram compileGraphics(const std::string& vertexSource, const std::function<std::string(const std::string&)>& mapVertexLog,
                                   const std::string& fragmentSource, const std::function<std::string(const std::string&)>& mapFragmentLog,
                                   const std::string& name);
  // Compiles and links; on failure throws Error whose message is `mapLog(driver log)`.
  static GlProgram compileCompute(const std::string& source, const std::function<std::string(const std::string&)>& mapLog,
                                  const std::string& name);
  void use() const;
  GLint uniformLocation(const char* name) const;
  GLuint id() const { return handle_.id(); }

 private:
  GlHandle handle_;
};

// A vertex array over one interleaved float vertex buffer (raster mode).
class GlVertexArray {
 public:
  struct Attribute {
    GLuint location;
    GLint components;   // floats
    std::size_t offset;  // bytes into a vertex
  };
  GlVertexArray() = default;
  static GlVertexArray create(const GlBuffer& vertices, std::size_t strideBytes, const std::vector<Attribute>& attributes);
  void bind() const;
  GLuint id() const { return handle_.id(); }

 private:
  GlHandle handle_;
};

// A read framebuffer with one colour texture, used to blit the display image to a window; or (raster
// mode) a draw framebuffer with a colour texture and a depth-stencil texture, or a depth layer only.
class GlFramebuffer {
 public:
  GlFramebuffer() = default;
  static GlFramebuffer forTexture(const GlTexture& texture);
  // Colour attachment 0 = `color` (may be 0-sized to leave it out), depth-stencil = `depthStencil`.
  static GlFramebuffer forTargets(const GlTexture& color, const GlTexture& depthStencil);
  // Depth only: layer `layer` of a depth cube-map array (no colour buffer).
  static GlFramebuffer forDepthLayer(const GlTexture& cubeArray, int layer);
  void bindDraw() const;  // as GL_DRAW_FRAMEBUFFER
  void blitToDefault(int srcW, int srcH, int dstW, int dstH) const;

 private:
  GlHandle handle_;
};

// Throws Error naming `what` if the GL error flag is set.
void checkGlError(const char* what);

}  // namespace caustica
