#pragma once
// Writing 8-bit images as PNG (libpng): renders, overlays and debug pictures. Files are written
// atomically (core/base/atomic_file.h): a failed write leaves no file and any previous one intact.
#include <cstdint>
#include <string>

#include "core/base/image.h"
#include "core/base/status.h"

namespace reconar {

// Encodes interleaved 8-bit samples as PNG bytes. `interleaved.width` counts samples, i.e. the
// pixel width times `channels` (as Image<uint8_t>::view() gives it); channels 1 (gray), 3 (RGB)
// or 4 (RGBA). Rows may be strided. kInvalidArgument for an empty view, another channel count,
// or a width that is not a multiple of `channels`.
Result<std::string> EncodePng(ImageView<const uint8_t> interleaved, int channels);

// EncodePng, then an atomic write to `path`. kIoError naming `path` when it cannot be written
// (missing directory, permissions, full disk).
Status WritePng(const std::string& path, ImageView<const uint8_t> interleaved, int channels);

}  // namespace reconar
