#include "platform/camera/frame_buffers.h"

#include <algorithm>
#include <cstdarg>
#include <cstdio>

#include "core/base/check.h"

namespace reconar::camera_internal {

FrameBuffers::FrameBuffers(int count) : buffers_(static_cast<size_t>(count)) {
  RECONAR_CHECK(count > 0) << "a frame source needs at least one buffer";
}

void FrameBuffers::Resize(int width, int height, bool want_rgb) {
  if (width == width_ && height == height_ && want_rgb == want_rgb_) return;
  width_ = width;
  height_ = height;
  want_rgb_ = want_rgb;
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  for (Buffer& buffer : buffers_) {
    RECONAR_CHECK(!buffer.held) << "frame size changed while frames are held";
    buffer.gray.assign(pixels, 0);
    buffer.rgb.assign(want_rgb ? 3 * pixels : 0, 0);
  }
}

int FrameBuffers::Acquire() {
  for (int i = 0; i < count(); ++i) {
    if (!buffers_[static_cast<size_t>(i)].held) {
      MarkHeld(i);
      return i;
    }
  }
  return -1;
}

void FrameBuffers::MarkHeld(int index) {
  RECONAR_CHECK(index >= 0 && index < count()) << "buffer index " << index << " out of range";
  Buffer& buffer = buffers_[static_cast<size_t>(index)];
  RECONAR_CHECK(!buffer.held) << "buffer " << index << " is already held";
  buffer.held = true;
  ++held_;
}

void FrameBuffers::Release(int index) {
  RECONAR_CHECK(index >= 0 && index < count()) << "Release() of a frame this source did not deliver";
  Buffer& buffer = buffers_[static_cast<size_t>(index)];
  RECONAR_CHECK(buffer.held) << "frame buffer " << index << " released twice";
  buffer.held = false;
  --held_;
}

ImageView<uint8_t> FrameBuffers::gray(int index) {
  Buffer& buffer = buffers_[static_cast<size_t>(index)];
  return ImageView<uint8_t>(width_, height_, width_, buffer.gray.data());
}

ImageView<uint8_t> FrameBuffers::rgb(int index) {
  Buffer& buffer = buffers_[static_cast<size_t>(index)];
  if (buffer.rgb.empty()) return ImageView<uint8_t>();
  return ImageView<uint8_t>(3 * width_, height_, 3 * width_, buffer.rgb.data());
}

std::string_view FrameBuffers::SetName(int index, const char* format, ...) {
  Buffer& buffer = buffers_[static_cast<size_t>(index)];
  va_list args;
  va_start(args, format);
  const int written = std::vsnprintf(buffer.name, sizeof(buffer.name), format, args);
  va_end(args);
  const size_t length = written < 0 ? 0 : std::min<size_t>(static_cast<size_t>(written), kMaxNameLength);
  return std::string_view(buffer.name, length);
}

}  // namespace reconar::camera_internal
