#include "render/gl_error.h"

#include <cstdio>

namespace reconar {

std::string GlErrorName(GLenum error) {
  const char* name = "unknown GL error";
  switch (error) {
    case GL_NO_ERROR:
      name = "GL_NO_ERROR";
      break;
    case GL_INVALID_ENUM:
      name = "GL_INVALID_ENUM";
      break;
    case GL_INVALID_VALUE:
      name = "GL_INVALID_VALUE";
      break;
    case GL_INVALID_OPERATION:
      name = "GL_INVALID_OPERATION";
      break;
    case GL_INVALID_FRAMEBUFFER_OPERATION:
      name = "GL_INVALID_FRAMEBUFFER_OPERATION";
      break;
    case GL_OUT_OF_MEMORY:
      name = "GL_OUT_OF_MEMORY";
      break;
    default:
      break;
  }
  char code[16];
  std::snprintf(code, sizeof(code), "0x%04X", static_cast<unsigned>(error));
  return std::string(name) + " (" + code + ")";
}

Status CheckGlError(const char* what) {
  const GLenum first = glGetError();
  if (first == GL_NO_ERROR) return Status::Ok();
  for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; ++i) {
  }
  return Internal(std::string(what) + ": " + GlErrorName(first));
}

}  // namespace reconar
