// gl_objects.cpp — the one place where OpenGL objects are created and deleted.
#include "gpu/gl_objects.h"

#include <algorithm>

#include "util/error.h"

namespace caustica {

namespace {
void deleteBuffer(GLuint id) { glDeleteBuffers(1, &id); }
void deleteTexture(GLuint id) { glDeleteTextures(1, &id); }
void deleteProgram(GLuint id) { glDeleteProgram(id); }
void deleteFramebuffer(GLuint id) { glDeleteFramebuffers(1, &id); }
void deleteVertexArray(GLuint id) { glDeleteVertexArrays(1, &id); }

std::string shaderInfoLog(GLuint obj, bool isShader) {
  GLint len = 0;
  isShader ? glGetShaderiv(obj, GL_INFO_LOG_LENGTH, &len) : glGetProgramiv(obj, GL_INFO_LOG_LENGTH, &len);
  std::string log(static_cast<std::size_t>(std::max(len, 1)), '\0');
  isShader ? glGetShaderInfoLog(obj, len, nullptr, log.data()) : glGetProgramInfoLog(obj, len, nullptr, log.data());
  log.resize(std::min(log.size(), log.find('\0')));
  return log;
}

std::string errorName(GLenum e) {
  switch (e) {
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    default: return "GL error " + std::to_string(e);
  }
}
}  // namespace

void checkGlError(const char* what) {
  GLenum e = glGetError();
  if (e != GL_NO_ERROR) throw Error(std::string("OpenGL error during ") + what + ": " + errorName(e));
}

GlBuffer GlBuffer::create(std::size_t bytes, const void* data, GLenum usage) {
  GlBuffer b;
  GLuint id = 0;
  glGenBuffers(1, &id);
  b.handle_ = GlHandle(id, deleteBuffer);
  b.size_ = std::max<std::size_t>(bytes, 16);
  glBindBuffer(GL_COPY_WRITE_BUFFER, id);
  if (bytes >= 16 || !data) {
    glBufferData(GL_COPY_WRITE_BUFFER, static_cast<GLsizeiptr>(b.size_), data, usage);
  } else {  // pad tiny arrays to 16 bytes
    std::vector<unsigned char> padded(16, 0);
    std::copy_n(static_cast<const unsigned char*>(data), bytes, padded.begin());
    glBufferData(GL_COPY_WRITE_BUFFER, 16, padded.data(), usage);
  }
  if (!data) {  // zeros, in slices of at most 4 MiB (a big scene's blocks are filled in slices too)
    std::vector<unsigned char> zeros(std::min<std::size_t>(b.size_, std::size_t(4) << 20), 0);
    for (std::size_t at = 0; at < b.size_; at += zeros.size())
      glBufferSubData(GL_COPY_WRITE_BUFFER, static_cast<GLintptr>(at),
                      static_cast<GLsizeiptr>(std::min(zeros.size(), b.size_ - at)), zeros.data());
  }
  glBindBuffer(GL_COPY_WRITE_BUFFER, 0);
  checkGlError("buffer creation");
  return b;
}

void GlBuffer::update(std::size_t offset, std::size_t bytes, const void* data) {
  glBindBuffer(GL_COPY_WRITE_BUFFER, id());
  glBufferSubData(GL_COPY_WRITE_BUFFER, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes), data);
  glBindBuffer(GL_COPY_WRITE_BUFFER, 0);
}

void GlBuffer::read(std::size_t offset, std::size_t bytes, void* out) const {
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  glBindBuffer(GL_COPY_READ_BUFFER, id());
  glGetBufferSubData(GL_COPY_READ_BUFFER, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes), out);
  glBindBuffer(GL_COPY_READ_BUFFER, 0);
}

void GlBuffer::bindBase(GLenum target, GLuint index) const { glBindBufferBase(target, index, id()); }

GlTexture GlTexture::generate(int width, int height, GLenum internalFormat) {
  GlTexture t;
  GLuint id = 0;
  glGenTextures(1, &id);
  t.handle_ = GlHandle(id, deleteTexture);
  t.width_ = width;
  t.height_ = height;
  t.format_ = internalFormat;
  return t;
}

GlBufferTexture GlBufferTexture::create(const GlBuffer& buffer, GLenum internalFormat) {
  GlBufferTexture t;
  GLuint id = 0;
  glGenTextures(1, &id);
  t.handle_ = GlHandle(id, deleteTexture);
  glBindTexture(GL_TEXTURE_BUFFER, id);
  glTexBuffer(GL_TEXTURE_BUFFER, internalFormat, buffer.id());
  glBindTexture(GL_TEXTURE_BUFFER, 0);
  checkGlError("buffer texture creation");
  return t;
}

void GlBufferTexture::bind(GLuint unit) const {
  glActiveTexture(GL_TEXTURE0 + unit);
  glBindTexture(GL_TEXTURE_BUFFER, id());
  glActiveTexture(GL_TEXTURE0);
}

GlTexture GlTexture::create2D(int width, int height, GLenum internalFormat) {
  GlTexture t = generate(width, height, internalFormat);
  const GLuint id = t.id();
  glBindTexture(GL_TEXTURE_2D, id);
  glTexStorage2D(GL_TEXTURE_2D, 1, internalFormat, width, height);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glBindTexture(GL_TEXTURE_2D, 0);
  checkGlError("texture creation");
  t.clear();
  return t;
}

void GlTexture::clear() {
  // glClearTexImage is GL 4.4: upload zeros instead.
  glBindTexture(GL_TEXTURE_2D, id());
  if (format_ == GL_RGBA32F) {
    std::vector<float> zeros(static_cast<std::size_t>(width_) * height_ * 4, 0.0f);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width_, height_, GL_RGBA, GL_FLOAT, zeros.data());
  } else if (format_ == GL_R32F) {
    std::vector<float> zeros(static_cast<std::size_t>(width_) * height_, 0.0f);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width_, height_, GL_RED, GL_FLOAT, zeros.data());
  } else if (format_ == GL_R32UI) {
    std::vector<GLuint> zeros(static_cast<std::size_t>(width_) * height_, 0u);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width_, height_, GL_RED_INTEGER, GL_UNSIGNED_INT, zeros.data());
  } else {
    std::vector<unsigned char> zeros(static_cast<std::size_t>(width_) * height_ * 4, 0);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, zeros.data());
  }
  glBindTexture(GL_TEXTURE_2D, 0);
}

void GlTexture::bindImage(GLuint unit, GLenum access) const {
  glBindImageTexture(unit, id(), 0, GL_FALSE, 0, access, format_);
}

std::vector<float> GlTexture::readFloats(GLenum format, int channels) const {
  glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
  std::vector<float> out(static_cast<std::size_t>(width_) * height_ * channels);
  glBindTexture(GL_TEXTURE_2D, id());
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glGetTexImage(GL_TEXTURE_2D, 0, format, GL_FLOAT, out.data());
  glBindTexture(GL_TEXTURE_2D, 0);
  checkGlError("image readback");
  return out;
}

void GlTexture::uploadFloats(GLenum format, const std::vector<float>& values) {
  glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  glBindTexture(GL_TEXTURE_2D, id());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width_, height_, format, GL_FLOAT, values.data());
  glBindTexture(GL_TEXTURE_2D, 0);
  checkGlError("image upload");
}

std::vector<float> GlTexture::readRgba32f() const { return readFloats(GL_RGBA, 4); }

void GlTexture::uploadRgba32f(const std::vector<float>& rgba) {
  if (format_ != GL_RGBA32F || rgba.size() != static_cast<std::size_t>(width_) * height_ * 4)
    throw Error("internal: uploadRgba32f needs an rgba32f texture and width*height*4 floats");
  uploadFloats(GL_RGBA, rgba);
}

std::vector<float> GlTexture::readR32f() const {
  if (format_ != GL_R32F) throw Error("internal: readR32f needs an r32f texture");
  return readFloats(GL_RED, 1);
}

void GlTexture::uploadR32f(const std::vector<float>& values) {
  if (format_ != GL_R32F || values.size() != static_cast<std::size_t>(width_) * height_)
    throw Error("internal: uploadR32f needs an r32f texture and width*height floats");
  uploadFloats(GL_RED, values);
}

void GlTexture::uploadR32uiRows(const std::vector<std::uint32_t>& values) {
  const std::size_t rows = (values.size() + static_cast<std::size_t>(width_) - 1) / static_cast<std::size_t>(width_);
  if (format_ != GL_R32UI || rows > static_cast<std::size_t>(height_))
    throw Error("internal: uploadR32uiRows needs an r32ui texture with room for the values");
  if (rows == 0) return;
  std::vector<std::uint32_t> padded(values);
  padded.resize(rows * static_cast<std::size_t>(width_), 0u);
  glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  glBindTexture(GL_TEXTURE_2D, id());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width_, static_cast<GLsizei>(rows), GL_RED_INTEGER, GL_UNSIGNED_INT,
                  padded.data());
  glBindTexture(GL_TEXTURE_2D, 0);
  checkGlError("tile list upload");
}

GlProgram GlProgram::compileCompute(const std::string& source,
                                    const std::function<std::string(const std::string&)>& mapLog,
                                    const std::string& name) {
  GLuint shader = glCreateShader(GL_COMPUTE_SHADER);
  const char* src = source.c_str();
  glShaderSource(shader, 1, &src, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  auto infoLog = [](GLuint obj, bool isShader) {
    GLint len = 0;
    isShader ? glGetShaderiv(obj, GL_INFO_LOG_LENGTH, &len) : glGetProgramiv(obj, GL_INFO_LOG_LENGTH, &len);
    std::string log(static_cast<std::size_t>(std::max(len, 1)), '\0');
    isShader ? glGetShaderInfoLog(obj, len, nullptr, log.data()) : glGetProgramInfoLog(obj, len, nullptr, log.data());
    log.resize(std::min(log.size(), log.find('\0')));
    return log;
  };
  if (!ok) {
    std::string log = infoLog(shader, true);
    glDeleteShader(shader);
    throw Error("shader " + name + " failed to compile:\n" + mapLog(log));
  }
  GlProgram p;
  GLuint prog = glCreateProgram();
  p.handle_ = GlHandle(prog, deleteProgram);
  glAttachShader(prog, shader);
  glLinkProgram(prog);
  glDeleteShader(shader);  // flagged; freed with the program
  glGetProgramiv(prog, GL_LINK_STATUS, &ok);
  if (!ok) throw Error("shader " + name + " failed to link:\n" + mapLog(infoLog(prog, false)));
  return p;
}

GlProgram GlProgram::compileGraphics(const std::string& vertexSource,
                                     const std::function<std::string(const std::string&)>& mapVertexLog,
                                     const std::string& fragmentSource,
                                     const std::function<std::string(const std::string&)>& mapFragmentLog,
                                     const std::string& name) {
  auto compile = [&](GLenum stage, const std::string& source, const std::function<std::string(const std::string&)>& mapLog,
                     const char* stageName) {
    GLuint shader = glCreateShader(stage);
    const char* src = source.c_str();
    glShaderSource(shader, 1, &src, nullptr);
    glCompileShader(shader);
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
      std::string log = shaderInfoLog(shader, true);
      glDeleteShader(shader);
      throw Error("shader " + name + " (" + stageName + " stage) failed to compile:\n" + mapLog(log));
    }
    return shader;
  };
  GLuint vs = compile(GL_VERTEX_SHADER, vertexSource, mapVertexLog, "vertex");
  GLuint fs = 0;
  try {
    fs = compile(GL_FRAGMENT_SHADER, fragmentSource, mapFragmentLog, "fragment");
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  GlProgram p;
  GLuint prog = glCreateProgram();
  p.handle_ = GlHandle(prog, deleteProgram);
  glAttachShader(prog, vs);
  glAttachShader(prog, fs);
  glLinkProgram(prog);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(prog, GL_LINK_STATUS, &ok);
  if (!ok) throw Error("shader " + name + " failed to link:\n" + shaderInfoLog(prog, false));
  return p;
}

GlTexture GlTexture::createSrgb8(int width, int height, const void* rgba8, GLenum wrapS, GLenum wrapT, bool nearest) {
  GlTexture t = generate(width, height, GL_SRGB8_ALPHA8);
  const GLuint id = t.id();
  int levels = 1;
  while ((std::max(width, height) >> levels) > 0) ++levels;
  glBindTexture(GL_TEXTURE_2D, id);
  glTexStorage2D(GL_TEXTURE_2D, levels, GL_SRGB8_ALPHA8, width, height);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rgba8);
  glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, static_cast<GLint>(wrapS));
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, static_cast<GLint>(wrapT));
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, nearest ? GL_NEAREST_MIPMAP_NEAREST : GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, nearest ? GL_NEAREST : GL_LINEAR);
  glBindTexture(GL_TEXTURE_2D, 0);
  checkGlError("raster texture creation");
  return t;
}

GlTexture GlTexture::createDepthStencil(int width, int height) {
  GlTexture t = generate(width, height, GL_DEPTH24_STENCIL8);
  const GLuint id = t.id();
  glBindTexture(GL_TEXTURE_2D, id);
  glTexStorage2D(GL_TEXTURE_2D, 1, GL_DEPTH24_STENCIL8, width, height);
  glBindTexture(GL_TEXTURE_2D, 0);
  checkGlError("depth-stencil target creation");
  return t;
}

GlTexture GlTexture::createDepthCubeArray(int size, int cubes) {
  GlTexture t = generate(size, size, GL_DEPTH_COMPONENT32F);
  const GLuint id = t.id();
  glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY, id);
  glTexStorage3D(GL_TEXTURE_CUBE_MAP_ARRAY, 1, GL_DEPTH_COMPONENT32F, size, size, 6 * std::max(cubes, 1));
  glTexParameteri(GL_TEXTURE_CUBE_MAP_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_CUBE_MAP_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_CUBE_MAP_ARRAY, GL_TEXTURE_COMPARE_MODE, GL_NONE);
  glTexParameteri(GL_TEXTURE_CUBE_MAP_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_CUBE_MAP_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY, 0);
  checkGlError("shadow cube map creation");
  return t;
}

GlVertexArray GlVertexArray::create(const GlBuffer& vertices, std::size_t strideBytes, const std::vector<Attribute>& attributes) {
  GlVertexArray v;
  GLuint id = 0;
  glGenVertexArrays(1, &id);
  v.handle_ = GlHandle(id, deleteVertexArray);
  glBindVertexArray(id);
  glBindBuffer(GL_ARRAY_BUFFER, vertices.id());
  for (const Attribute& a : attributes) {
    glEnableVertexAttribArray(a.location);
    glVertexAttribPointer(a.location, a.components, GL_FLOAT, GL_FALSE, static_cast<GLsizei>(strideBytes),
                          reinterpret_cast<const void*>(a.offset));
  }
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  checkGlError("vertex array creation");
  return v;
}

void GlVertexArray::bind() const { glBindVertexArray(id()); }

GlFramebuffer GlFramebuffer::forTargets(const GlTexture& color, const GlTexture& depthStencil) {
  GlFramebuffer f;
  GLuint id = 0;
  glGenFramebuffers(1, &id);
  f.handle_ = GlHandle(id, deleteFramebuffer);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, id);
  glFramebufferTexture2D(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color.id(), 0);
  glFramebufferTexture2D(GL_DRAW_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_TEXTURE_2D, depthStencil.id(), 0);
  GLenum status = glCheckFramebufferStatus(GL_DRAW_FRAMEBUFFER);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  if (status != GL_FRAMEBUFFER_COMPLETE) throw Error("raster framebuffer incomplete (status " + std::to_string(status) + ")");
  return f;
}

GlFramebuffer GlFramebuffer::forDepthLayer(const GlTexture& cubeArray, int layer) {
  GlFramebuffer f;
  GLuint id = 0;
  glGenFramebuffers(1, &id);
  f.handle_ = GlHandle(id, deleteFramebuffer);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, id);
  glFramebufferTextureLayer(GL_DRAW_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, cubeArray.id(), 0, layer);
  glDrawBuffer(GL_NONE);
  GLenum status = glCheckFramebufferStatus(GL_DRAW_FRAMEBUFFER);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  if (status != GL_FRAMEBUFFER_COMPLETE) throw Error("shadow map framebuffer incomplete (status " + std::to_string(status) + ")");
  return f;
}

void GlFramebuffer::bindDraw() const { glBindFramebuffer(GL_DRAW_FRAMEBUFFER, handle_.id()); }

void GlProgram::use() const { glUseProgram(id()); }
GLint GlProgram::uniformLocation(const char* n) const { return glGetUniformLocation(id(), n); }

GlFramebuffer GlFramebuffer::forTexture(const GlTexture& texture) {
  GlFramebuffer f;
  GLuint id = 0;
  glGenFramebuffers(1, &id);
  f.handle_ = GlHandle(id, deleteFramebuffer);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, id);
  glFramebufferTexture2D(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture.id(), 0);
  if (glCheckFramebufferStatus(GL_READ_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) throw Error("display framebuffer incomplete");
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  return f;
}

void GlFramebuffer::blitToDefault(int srcW, int srcH, int dstW, int dstH) const {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, handle_.id());
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  // Row 0 of the image is the top: flip vertically while blitting.
  glBlitFramebuffer(0, 0, srcW, srcH, 0, dstH, dstW, 0, GL_COLOR_BUFFER_BIT, GL_LINEAR);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
}

}  // namespace caustica
