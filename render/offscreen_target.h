#pragma once
// OffscreenTarget: a framebuffer of a fixed size with an RGBA8 colour and a 24-bit depth buffer,
// optionally multisampled (resolved by a blit before reading or presenting). Rows are stored top
// row first (render/camera_projection.h), so ReadRgb copies without flipping and Present flips.
#include <cstdint>
#include <vector>

#include "core/base/image.h"
#include "core/base/status.h"
#include "render/gl_handles.h"

namespace reconar {

// Where PresentToDefaultFramebuffer shows an image in a window: the largest rectangle of the
// image's aspect ratio, centred (window pixels, row 0 at the top).
struct Letterbox {
  int x0 = 0, y0 = 0, width = 0, height = 0;

  // The image pixel (centre of the top-left pixel at 0, 0) under the window pixel (x, y), or
  // false when (x, y) is outside the image.
  bool ImagePixel(int image_width, int image_height, double x, double y, double* image_x, double* image_y) const;
};
Letterbox LetterboxIn(int image_width, int image_height, int window_width, int window_height);

class OffscreenTarget {
 public:
  // Needs a current GLES 3 context. `samples` is clamped to GL_MAX_SAMPLES; 0 = single-sampled.
  // InvalidArgument for a non-positive size or one above GL_MAX_RENDERBUFFER_SIZE; Internal when
  // the framebuffer is incomplete.
  static Result<OffscreenTarget> Create(int width, int height, int samples);

  int width() const { return width_; }
  int height() const { return height_; }
  int samples() const { return samples_; }

  // Binds the (multisampled) draw framebuffer and sets the viewport to the whole target.
  void Bind() const;

  // The rendered image as 8-bit RGB, row 0 at the top. Reallocates *rgb only when its size or
  // channel count differs; no other heap allocation.
  Status ReadRgb(Image<uint8_t>* rgb);

  // Blits the image into the default framebuffer (the EGL window surface) of the given size,
  // scaled to fit with its aspect ratio kept, black bars around, upright on screen. The window
  // surface must be single-sampled (EglContextOptions::samples = 0; use this target's samples).
  Status PresentToDefaultFramebuffer(int window_width, int window_height);

 private:
  void Resolve();

  int width_ = 0;
  int height_ = 0;
  int samples_ = 0;
  GlFramebuffer draw_framebuffer_;  // where drawing goes (multisampled when samples_ > 0)
  GlRenderbuffer draw_color_;
  GlRenderbuffer draw_depth_;
  GlFramebuffer resolve_framebuffer_;  // single-sampled copy; only when samples_ > 0
  GlRenderbuffer resolve_color_;
  bool read_rgb_directly_ = false;     // GL_IMPLEMENTATION_COLOR_READ_FORMAT is GL_RGB
  std::vector<uint8_t> rgba_scratch_;  // glReadPixels RGBA rows otherwise
};

}  // namespace reconar
