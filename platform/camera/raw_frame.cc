#include "platform/camera/raw_frame.h"

#include <string>

#include "platform/camera/pixel_convert.h"

namespace reconar {

namespace {

Status LayoutError(std::string_view name, const std::string& reason) {
  return Status(StatusCode::kInvalidArgument, std::string(name) + ": " + reason);
}

Status ShortBuffer(std::string_view name, const char* what, size_t have, size_t need) {
  return Status(StatusCode::kCorruptData, std::string(name) + ": " + what + " holds " + std::to_string(have) +
                                              " bytes, the frame layout needs " + std::to_string(need));
}

}  // namespace

Status CheckRawFrameLayout(const RawFrameLayout& layout, std::string_view name) {
  constexpr int kMaxSide = 1 << 15;
  if (layout.format == PixelFormat::kUnknown) return LayoutError(name, "unknown pixel format");
  if (layout.width <= 0 || layout.height <= 0 || layout.width > kMaxSide || layout.height > kMaxSide) {
    return LayoutError(name, "bad frame size " + std::to_string(layout.width) + "x" + std::to_string(layout.height));
  }
  if ((layout.format == PixelFormat::kYuyv || layout.format == PixelFormat::kNv12) && layout.width % 2 != 0) {
    return LayoutError(name, std::string(PixelFormatName(layout.format)) + " needs an even width, got " +
                                 std::to_string(layout.width));
  }
  if (layout.format != PixelFormat::kMjpeg && layout.bytes_per_line < MinBytesPerLine(layout.format, layout.width)) {
    return LayoutError(name, "bytes per line " + std::to_string(layout.bytes_per_line) + " is less than a " +
                                 PixelFormatName(layout.format) + " row of " + std::to_string(layout.width) +
                                 " pixels");
  }
  return Status::Ok();
}

Status RawFrameConverter::Convert(const RawFrame& raw, std::string_view name, const ImageView<uint8_t>& gray_buffer,
                                  const ImageView<uint8_t>& rgb_buffer, ImageView<const uint8_t>* gray,
                                  ImageView<const uint8_t>* rgb) {
  const RawFrameLayout& layout = raw.layout;
  RECONAR_RETURN_IF_ERROR(CheckRawFrameLayout(layout, name));
  const bool want_rgb = settings_.want_rgb;
  const int w = layout.width;
  const int h = layout.height;
  const ptrdiff_t pitch = layout.bytes_per_line;
  const YuvConversionOptions yuv{layout.range};
  const bool expand_gray = settings_.gray_range == GrayRange::kFull && layout.range == YuvRange::kLimited;
  *rgb = ImageView<const uint8_t>();

  if (layout.format == PixelFormat::kMjpeg) {
    if (raw.size == 0) return Status(StatusCode::kCorruptData, std::string(name) + ": empty MJPEG buffer");
    RECONAR_RETURN_IF_ERROR(jpeg_.Decode(raw.data, raw.size, name, gray_buffer,
                                         want_rgb ? rgb_buffer : ImageView<uint8_t>()));
    *gray = gray_buffer;
    if (want_rgb) *rgb = rgb_buffer;
    return Status::Ok();
  }

  const size_t plane_bytes = static_cast<size_t>(pitch) * static_cast<size_t>(h);
  const size_t needed = (layout.format == PixelFormat::kNv12 && raw.chroma != nullptr)
                            ? plane_bytes
                            : RawBufferBytes(layout.format, h, layout.bytes_per_line);
  // The last row need not extend to the full pitch.
  const size_t tight_needed = needed - (static_cast<size_t>(pitch) - MinBytesPerLine(layout.format, w));
  if (raw.size < tight_needed) return ShortBuffer(name, "buffer", raw.size, tight_needed);

  switch (layout.format) {
    case PixelFormat::kGray8: {
      const ImageView<const uint8_t> plane(w, h, pitch, raw.data);
      if (want_rgb) GrayToRgb(plane, rgb_buffer);
      *gray = plane;
      break;
    }
    case PixelFormat::kRgb24: {
      const ImageView<const uint8_t> plane(3 * w, h, pitch, raw.data);
      RgbToGray(plane, gray_buffer);
      *gray = gray_buffer;
      if (want_rgb) *rgb = plane;
      return Status::Ok();
    }
    case PixelFormat::kYuyv: {
      const ImageView<const uint8_t> plane(2 * w, h, pitch, raw.data);
      if (expand_gray) {
        YuyvToGray(plane, yuv, gray_buffer);
      } else {
        ExtractYuyvLuma(plane, gray_buffer);
      }
      *gray = gray_buffer;
      if (want_rgb) YuyvToRgb(plane, yuv, rgb_buffer);
      break;
    }
    case PixelFormat::kNv12: {
      const ImageView<const uint8_t> luma(w, h, pitch, raw.data);
      const int chroma_rows = (h + 1) / 2;
      if (want_rgb) {
        const uint8_t* uv = raw.chroma != nullptr ? raw.chroma : raw.data + plane_bytes;
        if (raw.chroma != nullptr) {
          const size_t uv_needed = static_cast<size_t>(pitch) * static_cast<size_t>(chroma_rows - 1) +
                                   static_cast<size_t>(w);
          if (raw.chroma_size < uv_needed) return ShortBuffer(name, "UV plane", raw.chroma_size, uv_needed);
        }
        Nv12ToRgb(luma, ImageView<const uint8_t>(w, chroma_rows, pitch, uv), yuv, rgb_buffer);
      }
      if (expand_gray) {
        LumaToGray(luma, yuv, gray_buffer);
        *gray = gray_buffer;
      } else {
        *gray = luma;
      }
      break;
    }
    case PixelFormat::kMjpeg:
    case PixelFormat::kUnknown:
      break;
  }
  if (want_rgb) *rgb = rgb_buffer;
  return Status::Ok();
}

}  // namespace reconar
