#include "render/shader_program.h"

#include <string>
#include <utility>

namespace reconar {
namespace {

// The info log of a shader or program (glGetShaderiv + glGetShaderInfoLog, or the program pair).
std::string InfoLog(GLuint object, void (*get_parameter)(GLuint, GLenum, GLint*),
                    void (*get_log)(GLuint, GLsizei, GLsizei*, GLchar*)) {
  GLint length = 0;
  get_parameter(object, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<size_t>(length > 0 ? length : 0), '\0');
  if (length > 0) get_log(object, length, nullptr, log.data());
  while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
  return log;
}

Result<GlShader> Compile(const std::string& name, GLenum stage, const char* source) {
  const char* stage_name = stage == GL_VERTEX_SHADER ? "vertex" : "fragment";
  GlShader shader(glCreateShader(stage));
  if (!shader) return Internal(name + " " + stage_name + " shader: glCreateShader failed (no current context?)");
  glShaderSource(shader.get(), 1, &source, nullptr);
  glCompileShader(shader.get());
  GLint compiled = GL_FALSE;
  glGetShaderiv(shader.get(), GL_COMPILE_STATUS, &compiled);
  if (compiled != GL_TRUE) {
    return InvalidArgument(name + " " + stage_name + " shader: compile failed:\n" +
                           InfoLog(shader.get(), glGetShaderiv, glGetShaderInfoLog));
  }
  return shader;
}

}  // namespace

Result<ShaderProgram> ShaderProgram::Build(const std::string& name, const char* vertex_source,
                                           const char* fragment_source) {
  RECONAR_ASSIGN_OR_RETURN(GlShader vertex, Compile(name, GL_VERTEX_SHADER, vertex_source));
  RECONAR_ASSIGN_OR_RETURN(GlShader fragment, Compile(name, GL_FRAGMENT_SHADER, fragment_source));
  ShaderProgram result;
  result.program_ = GlProgram(glCreateProgram());
  const GLuint program = result.program_.get();
  glAttachShader(program, vertex.get());
  glAttachShader(program, fragment.get());
  glLinkProgram(program);
  glDetachShader(program, vertex.get());
  glDetachShader(program, fragment.get());
  GLint linked = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &linked);
  if (linked != GL_TRUE) {
    return InvalidArgument(name + " program: link failed:\n" + InfoLog(program, glGetProgramiv, glGetProgramInfoLog));
  }
  return result;
}

}  // namespace reconar
