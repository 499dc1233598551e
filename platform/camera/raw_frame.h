#pragma once
// A raw camera buffer as a device delivers it (and as a .frames recording stores it), and the
// conversion of such a buffer into a Frame's gray and RGB views. Shared by the V4L2, libcamera
// and recorded sources, so recorded frames take exactly the path live frames take.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/base/image.h"
#include "core/base/status.h"
#include "platform/camera/frame_source.h"
#include "platform/camera/jpeg_frame_decoder.h"
#include "platform/camera/pixel_format.h"

namespace reconar {

struct RawFrameLayout {
  PixelFormat format = PixelFormat::kUnknown;
  int width = 0;
  int height = 0;
  uint32_t bytes_per_line = 0;  // plane 0 row pitch (V4L2 bytesperline); NV12's UV plane uses the same; 0 for MJPEG
  YuvRange range = YuvRange::kLimited;  // ignored for GRAY8/RGB24; MJPEG is always full range
};

struct RawFrame {
  RawFrameLayout layout;
  const uint8_t* data = nullptr;  // plane 0 (for MJPEG: the JPEG bytes)
  size_t size = 0;                // bytes used in plane 0 (V4L2 bytesused)
  // NV12 only: the UV plane when it is not contiguous after the Y plane (libcamera multi-plane
  // buffers). When null, UV starts at data + bytes_per_line * height.
  const uint8_t* chroma = nullptr;
  size_t chroma_size = 0;
};

// kInvalidArgument when the layout cannot describe a frame (unknown format, odd YUYV width,
// bytes_per_line smaller than a row); `name` prefixes the message.
Status CheckRawFrameLayout(const RawFrameLayout& layout, std::string_view name);

struct FrameConversionSettings {
  bool want_rgb = true;
  GrayRange gray_range = GrayRange::kAsDelivered;
};

class RawFrameConverter {
 public:
  explicit RawFrameConverter(const FrameConversionSettings& settings) : settings_(settings) {}

  // Views `raw` as gray (+ RGB): zero-copy into `raw` where the layout allows, otherwise converted
  // into `gray_buffer` / `rgb_buffer` (width x height and 3*width x height, owned by the caller;
  // rgb_buffer may be empty when !want_rgb). kCorruptData "<name>: ..." when the buffer is
  // shorter than its layout needs or the JPEG does not decode.
  Status Convert(const RawFrame& raw, std::string_view name, const ImageView<uint8_t>& gray_buffer,
                 const ImageView<uint8_t>& rgb_buffer, ImageView<const uint8_t>* gray,
                 ImageView<const uint8_t>* rgb);

  const FrameConversionSettings& settings() const { return settings_; }

 private:
  FrameConversionSettings settings_;
  JpegFrameDecoder jpeg_;
};

}  // namespace reconar
