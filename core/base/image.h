#pragma once
// ImageView<T>: a strided view over pixels someone else owns (a camera buffer, an arena block,
// an Image<T>). Stride is in elements of T, as AprilTag's image_u8 {width, height, stride, buf}.
// Image<T>: the owning counterpart; interleaved channels are stored as T with width*channels
// elements per row when a view is taken over them by the caller.
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

namespace reconar {

template <typename T>
struct ImageView {
  int width = 0;
  int height = 0;
  ptrdiff_t stride = 0;  // elements of T between the starts of two rows
  T* data = nullptr;

  ImageView() = default;
  ImageView(int w, int h, ptrdiff_t s, T* d) : width(w), height(h), stride(s), data(d) {}
  // A view of non-const pixels converts to a view of const pixels.
  template <typename U, typename = std::enable_if_t<std::is_same_v<const U, T> && !std::is_same_v<U, T>>>
  ImageView(const ImageView<U>& other)  // NOLINT: implicit by design
      : width(other.width), height(other.height), stride(other.stride), data(other.data) {}

  bool empty() const { return width <= 0 || height <= 0 || data == nullptr; }
  T* row(int y) const { return data + static_cast<ptrdiff_t>(y) * stride; }
  T& at(int x, int y) const { return row(y)[x]; }
  ImageView sub(int x0, int y0, int w, int h) const { return ImageView(w, h, stride, row(y0) + x0); }
};

template <typename T>
class Image {
 public:
  Image() = default;
  Image(int width, int height, int channels = 1)
      : width_(width), height_(height), channels_(channels),
        pixels_(static_cast<size_t>(width) * height * channels) {}

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  bool empty() const { return pixels_.empty(); }
  T* data() { return pixels_.data(); }
  const T* data() const { return pixels_.data(); }
  T* row(int y) { return pixels_.data() + static_cast<size_t>(y) * width_ * channels_; }
  const T* row(int y) const { return pixels_.data() + static_cast<size_t>(y) * width_ * channels_; }

  // Views over all interleaved samples of a row: width = width()*channels().
  ImageView<T> view() { return ImageView<T>(width_ * channels_, height_, width_ * channels_, pixels_.data()); }
  ImageView<const T> view() const {
    return ImageView<const T>(width_ * channels_, height_, width_ * channels_, pixels_.data());
  }
  size_t size_bytes() const { return pixels_.size() * sizeof(T); }

 private:
  int width_ = 0;
  int height_ = 0;
  int channels_ = 1;
  std::vector<T> pixels_;
};

}  // namespace reconar
