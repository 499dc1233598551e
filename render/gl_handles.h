#pragma once
// Move-only owners of GL object names (buffer, texture, vertex array, framebuffer, renderbuffer,
// program). They need the context that created them to be current when they are destroyed.
#include <GLES3/gl3.h>

#include <utility>

namespace reconar {

template <void (*Delete)(GLuint)>
class GlName {
 public:
  GlName() = default;
  explicit GlName(GLuint name) : name_(name) {}
  ~GlName() { reset(); }
  GlName(GlName&& other) noexcept : name_(std::exchange(other.name_, 0)) {}
  GlName& operator=(GlName&& other) noexcept {
    if (this != &other) {
      reset();
      name_ = std::exchange(other.name_, 0);
    }
    return *this;
  }
  GlName(const GlName&) = delete;
  GlName& operator=(const GlName&) = delete;

  GLuint get() const { return name_; }
  explicit operator bool() const { return name_ != 0; }
  void reset() {
    if (name_ != 0) Delete(name_);
    name_ = 0;
  }

 private:
  GLuint name_ = 0;
};

namespace gl_delete {
inline void Buffer(GLuint name) { glDeleteBuffers(1, &name); }
inline void Texture(GLuint name) { glDeleteTextures(1, &name); }
inline void VertexArray(GLuint name) { glDeleteVertexArrays(1, &name); }
inline void Framebuffer(GLuint name) { glDeleteFramebuffers(1, &name); }
inline void Renderbuffer(GLuint name) { glDeleteRenderbuffers(1, &name); }
inline void Program(GLuint name) { glDeleteProgram(name); }
inline void Shader(GLuint name) { glDeleteShader(name); }
}  // namespace gl_delete

using GlBuffer = GlName<gl_delete::Buffer>;
using GlTexture = GlName<gl_delete::Texture>;
using GlVertexArray = GlName<gl_delete::VertexArray>;
using GlFramebuffer = GlName<gl_delete::Framebuffer>;
using GlRenderbuffer = GlName<gl_delete::Renderbuffer>;
using GlProgram = GlName<gl_delete::Program>;
using GlShader = GlName<gl_delete::Shader>;

inline GlBuffer MakeGlBuffer() {
  GLuint name = 0;
  glGenBuffers(1, &name);
  return GlBuffer(name);
}
inline GlTexture MakeGlTexture() {
  GLuint name = 0;
  glGenTextures(1, &name);
  return GlTexture(name);
}
inline GlVertexArray MakeGlVertexArray() {
  GLuint name = 0;
  glGenVertexArrays(1, &name);
  return GlVertexArray(name);
}
inline GlFramebuffer MakeGlFramebuffer() {
  GLuint name = 0;
  glGenFramebuffers(1, &name);
  return GlFramebuffer(name);
}
inline GlRenderbuffer MakeGlRenderbuffer() {
  GLuint name = 0;
  glGenRenderbuffers(1, &name);
  return GlRenderbuffer(name);
}

}  // namespace reconar
