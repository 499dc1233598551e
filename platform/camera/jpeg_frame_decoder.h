#pragma once
// Decodes one JPEG (an MJPEG camera buffer or a .jpg file) into caller-owned gray and RGB
// buffers with libjpeg-turbo. The decompressor is created once and reused frame after frame
// (its working memory comes from libjpeg's own pools, not operator new).
// Gray is the JPEG's Y channel; RGB is converted from the decoded full-range Y,Cb,Cr with
// pixel_convert.h (libjpeg's constants, its default "fancy" chroma upsampling).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string_view>

#include "core/base/image.h"
#include "core/base/status.h"

namespace reconar {

struct JpegHeader {
  int width = 0;
  int height = 0;
  int components = 0;
};

class JpegFrameDecoder {
 public:
  JpegFrameDecoder();
  ~JpegFrameDecoder();
  JpegFrameDecoder(const JpegFrameDecoder&) = delete;
  JpegFrameDecoder& operator=(const JpegFrameDecoder&) = delete;

  // kCorruptData (message prefixed with `name`) when the bytes are not a readable JPEG.
  Result<JpegHeader> ReadHeader(const uint8_t* data, size_t size, std::string_view name);

  // Decodes a JPEG whose size must be gray.width x gray.height. `rgb` (width 3 * pixels) may be
  // an empty view, then only luma is decoded. Truncated or damaged entropy data is kCorruptData,
  // never grey-filled pixels; CMYK is kUnsupported.
  Status Decode(const uint8_t* data, size_t size, std::string_view name, const ImageView<uint8_t>& gray,
                const ImageView<uint8_t>& rgb);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace reconar
