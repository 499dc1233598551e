// PNG encoding with libpng. libpng reports fatal errors by longjmp to png_jmpbuf(); the function
// that calls setjmp holds only trivially destructible state, so no destructor is skipped.
#include "core/io/image_write.h"

#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <vector>

#include "core/base/atomic_file.h"

namespace reconar {

namespace {

constexpr size_t kMessageLength = 256;

struct PngWriteContext {
  std::string* out;
  char message[kMessageLength];
};

void OnWrite(png_structp png, png_bytep data, size_t length) {
  auto* ctx = static_cast<PngWriteContext*>(png_get_io_ptr(png));
  ctx->out->append(reinterpret_cast<const char*>(data), length);
}

void OnFlush(png_structp) {}

[[noreturn]] void OnError(png_structp png, png_const_charp message) {
  auto* ctx = static_cast<PngWriteContext*>(png_get_error_ptr(png));
  std::snprintf(ctx->message, sizeof(ctx->message), "%s", message);
  png_longjmp(png, 1);
}

void OnWarning(png_structp, png_const_charp) {}

int ColorType(int channels) {
  switch (channels) {
    case 1: return PNG_COLOR_TYPE_GRAY;
    case 3: return PNG_COLOR_TYPE_RGB;
    default: return PNG_COLOR_TYPE_RGB_ALPHA;
  }
}

// Returns false after a libpng error (message in ctx->message).
bool Encode(png_structp png, png_infop info, ImageView<const uint8_t> interleaved, int channels,
            int compression_level, png_bytep* rows, PngWriteContext* ctx) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_write_fn(png, ctx, OnWrite, OnFlush);
  png_set_compression_level(png, compression_level);
  png_set_IHDR(png, info, static_cast<png_uint_32>(interleaved.width / channels),
               static_cast<png_uint_32>(interleaved.height), 8, ColorType(channels), PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_write_image(png, rows);
  png_write_end(png, nullptr);
  return true;
}

}  // namespace

Result<std::string> EncodePng(ImageView<const uint8_t> interleaved, int channels, int compression_level) {
  if (compression_level < 0 || compression_level > 9) {
    return InvalidArgument("PNG: compression level " + std::to_string(compression_level) + " (expected 0..9)");
  }
  if (channels != 1 && channels != 3 && channels != 4) {
    return InvalidArgument("PNG: " + std::to_string(channels) + " channels (expected 1, 3 or 4)");
  }
  if (interleaved.empty()) return InvalidArgument("PNG: empty image");
  if (interleaved.width % channels != 0) {
    return InvalidArgument("PNG: view width " + std::to_string(interleaved.width) + " is not a multiple of " +
                           std::to_string(channels) + " channels");
  }
  std::vector<png_bytep> rows(static_cast<size_t>(interleaved.height));
  for (int y = 0; y < interleaved.height; ++y) rows[y] = const_cast<png_bytep>(interleaved.row(y));

  std::string out;
  PngWriteContext ctx{&out, {}};
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &ctx, OnError, OnWarning);
  if (png == nullptr) return Internal("PNG: png_create_write_struct failed");
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_write_struct(&png, nullptr);
    return Internal("PNG: png_create_info_struct failed");
  }
  const bool ok = Encode(png, info, interleaved, channels, compression_level, rows.data(), &ctx);
  png_destroy_write_struct(&png, &info);
  if (!ok) return Internal(std::string("PNG: libpng: ") + ctx.message);
  return out;
}

Status WritePng(const std::string& path, ImageView<const uint8_t> interleaved, int channels) {
  Result<std::string> encoded = EncodePng(interleaved, channels);
  if (!encoded.ok()) return encoded.status().WithContext(path);
  return WriteFileAtomically(path, *encoded);
}

}  // namespace reconar
