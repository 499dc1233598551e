#pragma once
// ShaderProgram: a linked GLES 3.0 program ("#version 300 es" sources). Compile and link failures
// come back as Status carrying the program's name, the stage and the driver's info log.
#include <GLES3/gl3.h>

#include <string>

#include "core/base/status.h"
#include "render/gl_handles.h"

namespace reconar {

class ShaderProgram {
 public:
  // InvalidArgument "<name> vertex shader: compile failed:\n<log>" (or fragment / link).
  static Result<ShaderProgram> Build(const std::string& name, const char* vertex_source, const char* fragment_source);

  GLuint id() const { return program_.get(); }
  // Location of a uniform the program must have; -1 when the driver optimised it away.
  GLint Uniform(const char* uniform_name) const { return glGetUniformLocation(program_.get(), uniform_name); }

 private:
  GlProgram program_;
};

}  // namespace reconar
