#pragma once
// Writing 8-bit images as PNG (libpng: renders, overlays and debug pictures) and as JPEG
// (libjpeg-turbo, jpeg_encoder.cc: the keyframes a capture takes, with their EXIF). Files are written
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
// `compression_level`: zlib's 0 (none) .. 9; 6 is zlib's default. A photo atlas (texture_stage.h)
// is written at kPngFastCompression: 5x faster than 6 for 15 % more bytes (fountain-P11's 4096²
// atlas: 0.8 s and 13.9 MiB against 3.8 s and 12.1 MiB).
inline constexpr int kPngDefaultCompression = 6;
inline constexpr int kPngFastCompression = 2;
Result<std::string> EncodePng(ImageView<const uint8_t> interleaved, int channels,
                              int compression_level = kPngDefaultCompression);

// EncodePng, then an atomic write to `path`. kIoError naming `path` when it cannot be written
// (missing directory, permissions, full disk).
Status WritePng(const std::string& path, ImageView<const uint8_t> interleaved, int channels);

// Encodes gray (channels 1) or interleaved RGB (3) samples as a baseline JPEG of `quality`
// (1..100), with `app1_payload` (e.g. BuildExifApp1, core/io/exif.h) as an APP1 segment when not
// empty. kInvalidArgument for an empty view, another channel count, a bad quality or a payload over
// 65533 bytes; kInternal for a libjpeg failure.
Result<std::string> EncodeJpeg(ImageView<const uint8_t> interleaved, int channels, int quality,
                               const std::string& app1_payload = "");

// EncodeJpeg, then an atomic write to `path` (kIoError naming it when it cannot be written).
Status WriteJpeg(const std::string& path, ImageView<const uint8_t> interleaved, int channels, int quality,
                 const std::string& app1_payload = "");

}  // namespace reconar
