#pragma once
// Internal to core/io: the per-format decoders behind ReadImageFromMemory. Each fills
// out->rgb (as stored, before orientation), out->exif and out->warnings.
#include <string>
#include <string_view>

#include "core/base/status.h"
#include "core/io/image_io.h"

namespace reconar::io_internal {

Status DecodeJpeg(std::string_view bytes, const std::string& name, const ImageReadOptions& options,
                  DecodedImage* out);
Status DecodePng(std::string_view bytes, const std::string& name, const ImageReadOptions& options,
                 DecodedImage* out);

// The stored size (before orientation) and the EXIF of an image from its header.
Status ReadJpegHeader(std::string_view bytes, const std::string& name, ImageHeader* out);
Status ReadPngHeader(std::string_view bytes, const std::string& name, ImageHeader* out);

// Refuses zero or over-budget dimensions before any pixel memory is allocated.
Status CheckDimensions(uint64_t width, uint64_t height, const std::string& name, const ImageReadOptions& options);

}  // namespace reconar::io_internal
