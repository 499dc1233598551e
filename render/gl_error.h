#pragma once
// GL error reporting: every GL call sequence that can fail on input (sizes, formats) ends with
// CheckGlError, which turns glGetError() into a Status naming the step.
#include <GLES3/gl3.h>

#include <string>

#include "core/base/status.h"

namespace reconar {

// "GL_INVALID_VALUE (0x0501)".
std::string GlErrorName(GLenum error);

// Ok when glGetError() reports nothing; otherwise Internal("<what>: GL_... (0x....)"), draining
// every pending error flag.
Status CheckGlError(const char* what);

}  // namespace reconar
