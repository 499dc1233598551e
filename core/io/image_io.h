#pragma once
// Reading photographs: JPEG (libjpeg-turbo) and PNG (libpng), chosen by the file's magic bytes,
// always delivered as 8-bit interleaved RGB, upright according to EXIF orientation.
// Input problems come back as Status (never exit(), never a crash), naming the file and the reason.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/image.h"
#include "core/base/status.h"
#include "core/io/exif.h"
#include "core/io/gray.h"

namespace reconar {

struct ImageReadOptions {
  // Images with more pixels are refused before any pixel memory is allocated.
  int64_t max_pixels = 100'000'000;
  bool apply_exif_orientation = true;
};

struct DecodedImage {
  Image<uint8_t> rgb;  // 3 channels, interleaved, after orientation
  ExifInfo exif;       // from a JPEG APP1 or PNG eXIf chunk; present=false without one
  int original_width = 0;   // as stored in the file, before orientation
  int original_height = 0;
  // Non-fatal decoder remarks (e.g. "iCCP: known incorrect sRGB profile", a malformed EXIF block).
  std::vector<std::string> warnings;
};

// What a photo's header says, without its pixels decoded.
struct ImageHeader {
  int width = 0;   // upright, after the EXIF orientation
  int height = 0;
  ExifInfo exif;   // a JPEG's APP1; present=false for a PNG
};

enum class ImageFormat { kUnknown, kJpeg, kPng };

// Identifies the format from the first bytes of a file.
ImageFormat DetectImageFormat(std::string_view bytes);

// kNotFound for a missing file, kCorruptData for empty / unrecognised / damaged / truncated data,
// kResourceExhausted for images above options.max_pixels, kUnsupported for valid formats we do
// not decode (CMYK JPEG, HEIC, ...).
Result<DecodedImage> ReadImage(const std::string& path, const ImageReadOptions& options = {});

// The size and EXIF of a photo from its header alone (the pixels are not decoded). Errors as
// ReadImage's for a missing file or a header that is damaged or of an unsupported format.
Result<ImageHeader> ReadImageHeader(const std::string& path);

// Same as ReadImage on bytes already in memory (e.g. a recorded MJPEG frame); `name_for_errors`
// prefixes every error message.
Result<DecodedImage> ReadImageFromMemory(std::string_view bytes, const std::string& name_for_errors,
                                         const ImageReadOptions& options = {});

}  // namespace reconar
