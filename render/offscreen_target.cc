#include "render/offscreen_target.h"

#include <algorithm>
#include <string>
#include <utility>

#include "render/gl_error.h"

namespace reconar {
namespace {

Status AttachStorage(GLuint framebuffer, GLuint color, GLuint depth, int width, int height, int samples) {
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  glBindRenderbuffer(GL_RENDERBUFFER, color);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, width, height);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color);
  if (depth != 0) {
    glBindRenderbuffer(GL_RENDERBUFFER, depth);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
  }
  glBindRenderbuffer(GL_RENDERBUFFER, 0);
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  RECONAR_RETURN_IF_ERROR(CheckGlError("OffscreenTarget: allocating renderbuffers"));
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    return Internal("OffscreenTarget: framebuffer " + std::to_string(width) + "x" + std::to_string(height) + " with " +
                    std::to_string(samples) + " samples is incomplete (status " + std::to_string(status) + ")");
  }
  return Status::Ok();
}

}  // namespace

Result<OffscreenTarget> OffscreenTarget::Create(int width, int height, int samples) {
  GLint max_size = 0;
  GLint max_samples = 0;
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_size);
  glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  if (width <= 0 || height <= 0 || width > max_size || height > max_size) {
    return InvalidArgument("OffscreenTarget: size " + std::to_string(width) + "x" + std::to_string(height) +
                           " outside 1.." + std::to_string(max_size));
  }
  if (samples < 0) return InvalidArgument("OffscreenTarget: samples must be >= 0");
  OffscreenTarget target;
  target.width_ = width;
  target.height_ = height;
  target.samples_ = std::min(samples, static_cast<int>(max_samples));
  target.draw_framebuffer_ = MakeGlFramebuffer();
  target.draw_color_ = MakeGlRenderbuffer();
  target.draw_depth_ = MakeGlRenderbuffer();
  RECONAR_RETURN_IF_ERROR(AttachStorage(target.draw_framebuffer_.get(), target.draw_color_.get(),
                                        target.draw_depth_.get(), width, height, target.samples_));
  if (target.samples_ > 0) {
    target.resolve_framebuffer_ = MakeGlFramebuffer();
    target.resolve_color_ = MakeGlRenderbuffer();
    RECONAR_RETURN_IF_ERROR(
        AttachStorage(target.resolve_framebuffer_.get(), target.resolve_color_.get(), 0, width, height, 0));
  }
  GLint read_format = 0;
  GLint read_type = 0;
  glGetIntegerv(GL_IMPLEMENTATION_COLOR_READ_FORMAT, &read_format);
  glGetIntegerv(GL_IMPLEMENTATION_COLOR_READ_TYPE, &read_type);
  target.read_rgb_directly_ = read_format == GL_RGB && read_type == GL_UNSIGNED_BYTE;
  if (!target.read_rgb_directly_) target.rgba_scratch_.resize(static_cast<size_t>(width) * height * 4);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  RECONAR_RETURN_IF_ERROR(CheckGlError("OffscreenTarget::Create"));
  return target;
}

void OffscreenTarget::Bind() const {
  glBindFramebuffer(GL_FRAMEBUFFER, draw_framebuffer_.get());
  glViewport(0, 0, width_, height_);
}

void OffscreenTarget::Resolve() {
  if (samples_ == 0) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, draw_framebuffer_.get());
    return;
  }
  glBindFramebuffer(GL_READ_FRAMEBUFFER, draw_framebuffer_.get());
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_framebuffer_.get());
  glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, resolve_framebuffer_.get());
}

Status OffscreenTarget::ReadRgb(Image<uint8_t>* rgb) {
  if (rgb->width() != width_ || rgb->height() != height_ || rgb->channels() != 3) {
    *rgb = Image<uint8_t>(width_, height_, 3);
  }
  Resolve();
  glPixelStorei(GL_PACK_ROW_LENGTH, 0);
  if (read_rgb_directly_) {
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width_, height_, GL_RGB, GL_UNSIGNED_BYTE, rgb->data());
  } else {
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, rgba_scratch_.data());
    for (int y = 0; y < height_; ++y) {
      const uint8_t* source = rgba_scratch_.data() + static_cast<size_t>(y) * width_ * 4;
      uint8_t* target = rgb->row(y);
      for (int x = 0; x < width_; ++x) {
        target[3 * x + 0] = source[4 * x + 0];
        target[3 * x + 1] = source[4 * x + 1];
        target[3 * x + 2] = source[4 * x + 2];
      }
    }
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  return CheckGlError("OffscreenTarget::ReadRgb");
}

Letterbox LetterboxIn(int image_width, int image_height, int window_width, int window_height) {
  Letterbox box;
  if (image_width <= 0 || image_height <= 0 || window_width <= 0 || window_height <= 0) return box;
  const double scale =
      std::min(static_cast<double>(window_width) / image_width, static_cast<double>(window_height) / image_height);
  box.width = static_cast<int>(image_width * scale + 0.5);
  box.height = static_cast<int>(image_height * scale + 0.5);
  box.x0 = (window_width - box.width) / 2;
  box.y0 = (window_height - box.height) / 2;
  return box;
}

bool Letterbox::ImagePixel(int image_width, int image_height, double x, double y, double* image_x,
                           double* image_y) const {
  if (width <= 0 || height <= 0) return false;
  // Window pixel centres at +0.5; image pixel centres at integers.
  const double u = (x + 0.5 - x0) * image_width / width - 0.5;
  const double v = (y + 0.5 - y0) * image_height / height - 0.5;
  if (!(u >= -0.5 && v >= -0.5 && u <= image_width - 0.5 && v <= image_height - 0.5)) return false;
  *image_x = u;
  *image_y = v;
  return true;
}

Status OffscreenTarget::PresentToDefaultFramebuffer(int window_width, int window_height) {
  if (window_width <= 0 || window_height <= 0) {
    return InvalidArgument("OffscreenTarget::PresentToDefaultFramebuffer: window size " + std::to_string(window_width) +
                           "x" + std::to_string(window_height));
  }
  Resolve();
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glViewport(0, 0, window_width, window_height);
  glDisable(GL_SCISSOR_TEST);
  glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  const Letterbox box = LetterboxIn(width_, height_, window_width, window_height);
  // Our row 0 is the image's top; the window's row 0 is its bottom: swap the destination rows (the
  // box is centred, so its offset from the bottom is its offset from the top).
  glBlitFramebuffer(0, 0, width_, height_, box.x0, box.y0 + box.height, box.x0 + box.width, box.y0, GL_COLOR_BUFFER_BIT,
                    GL_LINEAR);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  return CheckGlError("OffscreenTarget::PresentToDefaultFramebuffer");
}

}  // namespace reconar
