#include "render/video_background.h"

#include <string>
#include <utility>

#include "render/gl_error.h"

namespace reconar {
namespace {

// One triangle covering the viewport; v_uv is 0..1 over the viewport, v = 0 at window row 0.
constexpr const char* kVertexShader = R"(#version 300 es
out vec2 v_uv;
void main() {
  vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  v_uv = corner;
  gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
)";

constexpr const char* kFragmentShader = R"(#version 300 es
precision highp float;
uniform sampler2D u_frame;
in vec2 v_uv;
out vec4 o_color;
void main() {
  o_color = vec4(texture(u_frame, v_uv).rgb, 1.0);
}
)";

GLenum FormatOf(int channels) { return channels == 1 ? GL_RED : channels == 3 ? GL_RGB : GL_RGBA; }
GLenum InternalFormatOf(int channels) { return channels == 1 ? GL_R8 : channels == 3 ? GL_RGB8 : GL_RGBA8; }

// GL_UNPACK_ROW_LENGTH (pixels) and GL_UNPACK_ALIGNMENT that make GL step `stride` bytes per row,
// or false when no pair does (GL's row step is row_length * channels rounded up to the alignment).
bool UnpackParametersFor(ptrdiff_t stride, int channels, int* row_length, int* alignment) {
  if (stride % channels == 0) {
    *row_length = static_cast<int>(stride / channels);
    *alignment = 1;
    return true;
  }
  const ptrdiff_t pixels = stride / channels;
  for (int candidate : {2, 4, 8}) {
    const ptrdiff_t packed = pixels * channels;
    const ptrdiff_t aligned = (packed + candidate - 1) / candidate * candidate;
    if (aligned == stride) {
      *row_length = static_cast<int>(pixels);
      *alignment = candidate;
      return true;
    }
  }
  return false;
}

}  // namespace

Result<VideoBackground> VideoBackground::Create() {
  VideoBackground background;
  RECONAR_ASSIGN_OR_RETURN(background.program_,
                           ShaderProgram::Build("video background", kVertexShader, kFragmentShader));
  background.frame_uniform_ = background.program_.Uniform("u_frame");
  background.texture_ = MakeGlTexture();
  background.vertex_array_ = MakeGlVertexArray();
  glBindTexture(GL_TEXTURE_2D, background.texture_.get());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glBindTexture(GL_TEXTURE_2D, 0);
  RECONAR_RETURN_IF_ERROR(CheckGlError("VideoBackground::Create"));
  return background;
}

Status VideoBackground::Upload(ImageView<const uint8_t> frame, int channels) {
  if (channels != 1 && channels != 3 && channels != 4) {
    return InvalidArgument("VideoBackground::Upload: channels must be 1, 3 or 4, got " + std::to_string(channels));
  }
  if (frame.empty()) return InvalidArgument("VideoBackground::Upload: empty frame");
  if (frame.width % channels != 0) {
    return InvalidArgument("VideoBackground::Upload: view width " + std::to_string(frame.width) +
                           " is not a multiple of " + std::to_string(channels) + " channels");
  }
  if (frame.stride < frame.width) {
    return InvalidArgument("VideoBackground::Upload: stride " + std::to_string(frame.stride) + " < width " +
                           std::to_string(frame.width));
  }
  const int width = frame.width / channels;
  const GLenum format = FormatOf(channels);
  glBindTexture(GL_TEXTURE_2D, texture_.get());
  if (width != width_ || frame.height != height_ || channels != channels_) {
    glTexImage2D(GL_TEXTURE_2D, 0, static_cast<GLint>(InternalFormatOf(channels)), width, frame.height, 0, format,
                 GL_UNSIGNED_BYTE, nullptr);
    const GLint green = channels == 1 ? GL_RED : GL_GREEN;
    const GLint blue = channels == 1 ? GL_RED : GL_BLUE;
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_SWIZZLE_G, green);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_SWIZZLE_B, blue);
    RECONAR_RETURN_IF_ERROR(CheckGlError("VideoBackground::Upload: allocating the frame texture"));
    width_ = width;
    height_ = frame.height;
    channels_ = channels;
  }
  int row_length = 0;
  int alignment = 1;
  if (UnpackParametersFor(frame.stride, channels, &row_length, &alignment)) {
    glPixelStorei(GL_UNPACK_ROW_LENGTH, row_length);
    glPixelStorei(GL_UNPACK_ALIGNMENT, alignment);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width, frame.height, format, GL_UNSIGNED_BYTE, frame.data);
  } else {
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    for (int y = 0; y < frame.height; ++y) {
      glTexSubImage2D(GL_TEXTURE_2D, 0, 0, y, width, 1, format, GL_UNSIGNED_BYTE, frame.row(y));
    }
  }
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glBindTexture(GL_TEXTURE_2D, 0);
  return CheckGlError("VideoBackground::Upload");
}

Status VideoBackground::Draw() const {
  if (width_ == 0) return FailedPrecondition("VideoBackground::Draw: no frame uploaded yet");
  glDisable(GL_DEPTH_TEST);
  glDepthMask(GL_FALSE);
  glUseProgram(program_.id());
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, texture_.get());
  glUniform1i(frame_uniform_, 0);
  glBindVertexArray(vertex_array_.get());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  glBindTexture(GL_TEXTURE_2D, 0);
  glDepthMask(GL_TRUE);
  return CheckGlError("VideoBackground::Draw");
}

}  // namespace reconar
