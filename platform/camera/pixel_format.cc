#include "platform/camera/pixel_format.h"

#include <initializer_list>

namespace reconar {

namespace {

constexpr uint32_t Fourcc(char a, char b, char c, char d) {
  return static_cast<uint32_t>(static_cast<uint8_t>(a)) | static_cast<uint32_t>(static_cast<uint8_t>(b)) << 8 |
         static_cast<uint32_t>(static_cast<uint8_t>(c)) << 16 | static_cast<uint32_t>(static_cast<uint8_t>(d)) << 24;
}

}  // namespace

uint32_t PixelFormatFourcc(PixelFormat format) {
  switch (format) {
    case PixelFormat::kGray8: return Fourcc('G', 'R', 'E', 'Y');
    case PixelFormat::kRgb24: return Fourcc('R', 'G', 'B', '3');
    case PixelFormat::kYuyv: return Fourcc('Y', 'U', 'Y', 'V');
    case PixelFormat::kNv12: return Fourcc('N', 'V', '1', '2');
    case PixelFormat::kMjpeg: return Fourcc('M', 'J', 'P', 'G');
    case PixelFormat::kUnknown: break;
  }
  return 0;
}

PixelFormat PixelFormatFromFourcc(uint32_t fourcc) {
  for (PixelFormat format : {PixelFormat::kGray8, PixelFormat::kRgb24, PixelFormat::kYuyv, PixelFormat::kNv12,
                             PixelFormat::kMjpeg}) {
    if (PixelFormatFourcc(format) == fourcc) return format;
  }
  // Many UVC cameras announce baseline JPEG as 'JPEG' rather than 'MJPG'; the buffers are the same.
  if (fourcc == Fourcc('J', 'P', 'E', 'G')) return PixelFormat::kMjpeg;
  return PixelFormat::kUnknown;
}

const char* PixelFormatName(PixelFormat format) {
  switch (format) {
    case PixelFormat::kGray8: return "GREY";
    case PixelFormat::kRgb24: return "RGB3";
    case PixelFormat::kYuyv: return "YUYV";
    case PixelFormat::kNv12: return "NV12";
    case PixelFormat::kMjpeg: return "MJPG";
    case PixelFormat::kUnknown: break;
  }
  return "unknown";
}

size_t MinBytesPerLine(PixelFormat format, int width) {
  const size_t w = width > 0 ? static_cast<size_t>(width) : 0;
  switch (format) {
    case PixelFormat::kGray8: return w;
    case PixelFormat::kRgb24: return 3 * w;
    case PixelFormat::kYuyv: return 2 * w;
    case PixelFormat::kNv12: return w;
    case PixelFormat::kMjpeg:
    case PixelFormat::kUnknown: break;
  }
  return 0;
}

size_t RawBufferBytes(PixelFormat format, int height, size_t bytes_per_line) {
  const size_t h = height > 0 ? static_cast<size_t>(height) : 0;
  switch (format) {
    case PixelFormat::kGray8:
    case PixelFormat::kRgb24:
    case PixelFormat::kYuyv: return h * bytes_per_line;
    case PixelFormat::kNv12: return h * bytes_per_line + (h + 1) / 2 * bytes_per_line;
    case PixelFormat::kMjpeg:
    case PixelFormat::kUnknown: break;
  }
  return 0;
}

}  // namespace reconar
