#pragma once
// The raw buffer layouts a camera (or a recording of one) delivers, as V4L2 names them.
// Byte order within each format follows linux/videodev2.h:
//   kGray8 (GREY) one byte per pixel; kRgb24 (RGB3) R,G,B per pixel;
//   kYuyv (YUYV) Y0 U Y1 V per pixel pair (4:2:2, width must be even);
//   kNv12 (NV12) a Y plane, then an interleaved U,V plane at half width and half height (4:2:0);
//   kMjpeg (MJPG) one complete JPEG (JFIF, full-range YCbCr) per buffer.
#include <cstddef>
#include <cstdint>

namespace reconar {

enum class PixelFormat : uint8_t { kUnknown = 0, kGray8, kRgb24, kYuyv, kNv12, kMjpeg };

// How Y'CbCr samples are quantised (V4L2 v4l2_quantization). Both use the BT.601 matrix.
enum class YuvRange : uint8_t {
  kLimited = 0,  // Y in [16, 235], Cb/Cr in [16, 240] (V4L2 default for YUV formats)
  kFull = 1,     // all of [0, 255] (JPEG/JFIF, V4L2_QUANTIZATION_FULL_RANGE)
};

// V4L2 fourcc ('Y','U','Y','V' → v4l2_fourcc('Y','U','Y','V')), and back (kUnknown if not ours).
uint32_t PixelFormatFourcc(PixelFormat format);
PixelFormat PixelFormatFromFourcc(uint32_t fourcc);
const char* PixelFormatName(PixelFormat format);  // "YUYV", "NV12", ...

// Smallest bytes-per-line of plane 0 (0 for kMjpeg, which has no rows).
size_t MinBytesPerLine(PixelFormat format, int width);
// Bytes a buffer of this layout needs (Y and UV plane for NV12 with the given Y stride; 0 for kMjpeg).
size_t RawBufferBytes(PixelFormat format, int height, size_t bytes_per_line);

}  // namespace reconar
