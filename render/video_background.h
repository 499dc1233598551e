#pragma once
// VideoBackground: the camera frame as a texture drawn over the whole target. The texture is
// allocated when the frame size or channel count changes and refilled with glTexSubImage2D for
// every other frame (no GL reallocation, no heap allocation).
#include <cstdint>

#include "core/base/image.h"
#include "core/base/status.h"
#include "render/gl_handles.h"
#include "render/shader_program.h"

namespace reconar {

class VideoBackground {
 public:
  // Needs a current GLES 3 context.
  static Result<VideoBackground> Create();

  // `frame` holds interleaved 8-bit samples: width = channels * pixels per row, stride in bytes
  // (any stride >= width; rows are uploaded one by one when GL_UNPACK_ROW_LENGTH/ALIGNMENT cannot
  // express it). channels: 1 (gray, shown as gray), 3 (RGB) or 4 (RGBA, alpha ignored).
  // InvalidArgument for an empty frame, a width that is not a multiple of channels, stride < width.
  Status Upload(ImageView<const uint8_t> frame, int channels);

  // Draws the last uploaded frame stretched over the current viewport, without depth test or
  // depth writes; row 0 of the frame at GL window row 0 (see render/camera_projection.h).
  // FailedPrecondition before the first Upload.
  Status Draw() const;

  int frame_width() const { return width_; }
  int frame_height() const { return height_; }

 private:
  ShaderProgram program_;
  GLint frame_uniform_ = -1;
  GlTexture texture_;
  GlVertexArray vertex_array_;
  int width_ = 0;
  int height_ = 0;
  int channels_ = 0;
};

}  // namespace reconar
