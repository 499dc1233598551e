#pragma once
// Internal to platform/camera: the conversion buffers behind a source's frames. Buffer i holds
// one gray and (optionally) one RGB image plus a name; each is handed out by Acquire() and
// returned by Release(). Pixel memory is (re)allocated only when the frame size changes.
#include <cstdint>
#include <string_view>
#include <vector>

#include "core/base/image.h"

namespace reconar::camera_internal {

class FrameBuffers {
 public:
  static constexpr int kMaxNameLength = 95;

  explicit FrameBuffers(int count);

  int count() const { return static_cast<int>(buffers_.size()); }
  int held() const { return held_; }
  bool all_held() const { return held_ == count(); }

  // Sizes every buffer for width x height (no-op when unchanged).
  void Resize(int width, int height, bool want_rgb);

  // A free buffer index (the lowest), or -1 when all are held.
  int Acquire();
  // Marks a specific buffer held (device sources whose buffer index the driver chooses).
  void MarkHeld(int index);
  void Release(int index);

  ImageView<uint8_t> gray(int index);
  ImageView<uint8_t> rgb(int index);  // empty unless want_rgb
  // Writes the printf-formatted name into buffer `index` and returns a view of it.
  std::string_view SetName(int index, const char* format, ...) __attribute__((format(printf, 3, 4)));

 private:
  struct Buffer {
    std::vector<uint8_t> gray;
    std::vector<uint8_t> rgb;
    char name[kMaxNameLength + 1] = {};
    bool held = false;
  };
  std::vector<Buffer> buffers_;
  int width_ = 0;
  int height_ = 0;
  bool want_rgb_ = false;
  int held_ = 0;
};

}  // namespace reconar::camera_internal
