#pragma once
// Pure pixel conversions from camera buffer layouts to 8-bit gray and interleaved RGB, with the
// BT.601 matrix in either quantisation (pixel_format.h YuvRange). Scalar, fixed point with 16
// fractional bits; the full-range constants and rounding are libjpeg's (jdcolor.c), so a JFIF
// frame converts to the same RGB that libjpeg produces from the same (upsampled) samples.
//
// Every view is strided: a source view's stride is the buffer's bytesperline, which may exceed
// the packed row size (and may be odd). Sizes are in view units:
//   yuyv view: width = 2 * pixels (bytes), height = rows;
//   NV12 luma view: width = pixels; NV12 chroma view: width = 2 * ceil(pixels / 2) bytes (U,V pairs),
//     height = ceil(rows / 2);
//   gray view: width = pixels; rgb view: width = 3 * pixels.
// Each function requires matching sizes (a programmer error otherwise: RECONAR_CHECK).
// Chroma is replicated to the pixels it covers (no interpolation); libjpeg does the same with
// do_fancy_upsampling = FALSE.
#include <cstdint>

#include "core/base/image.h"
#include "platform/camera/pixel_format.h"

namespace reconar {

struct YuvConversionOptions {
  YuvRange range = YuvRange::kLimited;  // V4L2's default for YUYV/NV12
};

// gray = the Y samples exactly as delivered (no range expansion).
void ExtractYuyvLuma(const ImageView<const uint8_t>& yuyv, const ImageView<uint8_t>& gray);
// gray = full-range luma: limited-range Y is expanded (16 → 0, 235 → 255, clamped), full range copied.
void YuyvToGray(const ImageView<const uint8_t>& yuyv, const YuvConversionOptions& options,
                const ImageView<uint8_t>& gray);
void LumaToGray(const ImageView<const uint8_t>& luma, const YuvConversionOptions& options,
                const ImageView<uint8_t>& gray);
void YuyvToRgb(const ImageView<const uint8_t>& yuyv, const YuvConversionOptions& options,
               const ImageView<uint8_t>& rgb);
void Nv12ToRgb(const ImageView<const uint8_t>& luma, const ImageView<const uint8_t>& chroma,
               const YuvConversionOptions& options, const ImageView<uint8_t>& rgb);
// Interleaved Y,Cb,Cr triples (libjpeg's JCS_YCbCr output) to RGB and to gray (= Y as is).
void YcbcrToRgb(const ImageView<const uint8_t>& ycbcr, const YuvConversionOptions& options,
                const ImageView<uint8_t>& rgb);
void ExtractYcbcrLuma(const ImageView<const uint8_t>& ycbcr, const ImageView<uint8_t>& gray);

// Passthrough helpers for GRAY8 and RGB24 buffers.
void CopyPlane(const ImageView<const uint8_t>& from, const ImageView<uint8_t>& to);
void GrayToRgb(const ImageView<const uint8_t>& gray, const ImageView<uint8_t>& rgb);
// BT.601 luma of full-range RGB, rounded: (19595 R + 38470 G + 7471 B + 32768) >> 16 (libjpeg's weights).
void RgbToGray(const ImageView<const uint8_t>& rgb, const ImageView<uint8_t>& gray);

}  // namespace reconar
