// PNG decoding with libpng. libpng reports fatal errors by longjmp to png_jmpbuf(); the phase
// functions that call setjmp hold only trivially destructible state, so no destructor is skipped.
#include <png.h>

#include <algorithm>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <vector>

#include "core/io/decoders.h"

namespace reconar::io_internal {

namespace {

constexpr int kMaxKeptWarnings = 4;
constexpr size_t kMessageLength = 256;

struct PngContext {
  const uint8_t* data;
  size_t size;
  size_t position;
  bool truncated;
  char message[kMessageLength];
  int warning_count;
  char warnings[kMaxKeptWarnings][kMessageLength];
};

PngContext* GetContext(png_structp png) { return static_cast<PngContext*>(png_get_error_ptr(png)); }

void OnRead(png_structp png, png_bytep out, size_t length) {
  auto* ctx = static_cast<PngContext*>(png_get_io_ptr(png));
  if (length > ctx->size - ctx->position) {
    ctx->truncated = true;
    png_error(png, "truncated PNG data");
  }
  std::memcpy(out, ctx->data + ctx->position, length);
  ctx->position += length;
}

[[noreturn]] void OnError(png_structp png, png_const_charp message) {
  PngContext* ctx = GetContext(png);
  std::snprintf(ctx->message, sizeof(ctx->message), "%s", message);
  png_longjmp(png, 1);
}

void OnWarning(png_structp png, png_const_charp message) {
  PngContext* ctx = GetContext(png);
  if (ctx->warning_count < kMaxKeptWarnings) {
    std::snprintf(ctx->warnings[ctx->warning_count], kMessageLength, "%s", message);
  }
  ++ctx->warning_count;
}

struct HeaderInfo {
  png_uint_32 width;
  png_uint_32 height;
  int bit_depth;
  int color_type;
  const png_byte* exif;  // eXIf chunk payload (a TIFF block) seen before the image data, or null
  png_uint_32 exif_size;
};

bool ReadHeader(png_structp png, png_infop info, PngContext* ctx, HeaderInfo* header) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_read_fn(png, ctx, OnRead);
  // Our own pixel budget (checked next) replaces libpng's default 1e6 x 1e6 limit.
  png_set_user_limits(png, 0x7fffffff, 0x7fffffff);
  png_read_info(png, info);
  int interlace = 0;
  png_get_IHDR(png, info, &header->width, &header->height, &header->bit_depth, &header->color_type, &interlace,
               nullptr, nullptr);
#ifdef PNG_eXIf_SUPPORTED
  png_bytep exif = nullptr;
  if (png_get_eXIf_1(png, info, &header->exif_size, &exif) != 0) header->exif = exif;
#endif
  return true;
}

// Sets up the transforms to 8-bit RGB and decodes into `rows`. Returns false on a libpng error.
bool DecodeRows(png_structp png, png_infop info, PngContext* ctx, const HeaderInfo& header, png_bytep* rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  if (header.color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (header.color_type == PNG_COLOR_TYPE_GRAY && header.bit_depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (header.bit_depth == 16) png_set_scale_16(png);
  // Alpha (including a palette's tRNS, which palette expansion turns into alpha) is dropped:
  // photogrammetry wants the stored colour, not a composite over some background.
  png_set_strip_alpha(png);
  if (header.color_type == PNG_COLOR_TYPE_GRAY || header.color_type == PNG_COLOR_TYPE_GRAY_ALPHA) {
    png_set_gray_to_rgb(png);
  }
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  if (png_get_rowbytes(png, info) != static_cast<size_t>(header.width) * 3 || png_get_channels(png, info) != 3 ||
      png_get_bit_depth(png, info) != 8) {
    std::snprintf(ctx->message, sizeof(ctx->message), "unexpected transform result (%u channels, %u bits)",
                  static_cast<unsigned>(png_get_channels(png, info)),
                  static_cast<unsigned>(png_get_bit_depth(png, info)));
    return false;
  }
  png_read_image(png, rows);
  return true;
}

class ReadStructGuard {
 public:
  ReadStructGuard(png_structp png, png_infop info) : png_(png), info_(info) {}
  ~ReadStructGuard() { png_destroy_read_struct(&png_, &info_, nullptr); }
  ReadStructGuard(const ReadStructGuard&) = delete;
  ReadStructGuard& operator=(const ReadStructGuard&) = delete;

 private:
  png_structp png_;
  png_infop info_;
};

Status FailureToStatus(const PngContext& ctx, const std::string& name) {
  if (ctx.truncated) return FileError(StatusCode::kCorruptData, name, "truncated PNG data");
  return FileError(StatusCode::kCorruptData, name, std::string("invalid PNG data: ") + ctx.message);
}

}  // namespace

Status ReadPngHeader(std::string_view bytes, const std::string& name, ImageHeader* out) {
  // IHDR is always the first chunk: 8 bytes of signature, its length and type, then the size.
  const auto* raw = reinterpret_cast<const uint8_t*>(bytes.data());
  if (bytes.size() < 24 || bytes.substr(12, 4) != "IHDR") {
    return FileError(StatusCode::kCorruptData, name, "PNG without an IHDR chunk first (truncated or damaged)");
  }
  const auto be32 = [&](size_t at) {
    return static_cast<uint32_t>(raw[at]) << 24 | static_cast<uint32_t>(raw[at + 1]) << 16 |
           static_cast<uint32_t>(raw[at + 2]) << 8 | raw[at + 3];
  };
  const uint32_t width = be32(16), height = be32(20);
  if (width == 0 || height == 0 || width > 0x7FFFFFFF || height > 0x7FFFFFFF) {
    return FileError(StatusCode::kCorruptData, name,
                     "PNG size " + std::to_string(width) + " x " + std::to_string(height) + " is invalid");
  }
  out->width = static_cast<int>(width);
  out->height = static_cast<int>(height);
  return Status::Ok();
}

Status DecodePng(std::string_view bytes, const std::string& name, const ImageReadOptions& options,
                 DecodedImage* out) {
  // Refuse absurd sizes from IHDR (always the first chunk) before libpng reads any further.
  const auto* raw = reinterpret_cast<const uint8_t*>(bytes.data());
  if (bytes.size() >= 24 && bytes.substr(12, 4) == "IHDR") {
    const auto be32 = [&](size_t at) {
      return static_cast<uint32_t>(raw[at]) << 24 | static_cast<uint32_t>(raw[at + 1]) << 16 |
             static_cast<uint32_t>(raw[at + 2]) << 8 | raw[at + 3];
    };
    const uint32_t width = be32(16);
    const uint32_t height = be32(20);
    // Zero or over-2^31 sizes are invalid PNG; libpng reports those in its own words below.
    if (width != 0 && height != 0 && width <= 0x7FFFFFFF && height <= 0x7FFFFFFF) {
      RECONAR_RETURN_IF_ERROR(CheckDimensions(width, height, name, options));
    }
  }

  PngContext ctx{};
  ctx.data = raw;
  ctx.size = bytes.size();
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &ctx, OnError, OnWarning);
  if (png == nullptr) return FileError(StatusCode::kResourceExhausted, name, "cannot create PNG decoder");
  png_infop info = png_create_info_struct(png);
  ReadStructGuard guard(png, info);
  if (info == nullptr) return FileError(StatusCode::kResourceExhausted, name, "cannot create PNG decoder");

  HeaderInfo header{};
  if (!ReadHeader(png, info, &ctx, &header)) return FailureToStatus(ctx, name);
  RECONAR_RETURN_IF_ERROR(CheckDimensions(header.width, header.height, name, options));
  if (header.exif != nullptr) {
    out->exif = ParseExifTiff(std::string_view(reinterpret_cast<const char*>(header.exif), header.exif_size));
    if (!out->exif.warning.empty()) out->warnings.push_back("EXIF: " + out->exif.warning);
  }

  out->rgb = Image<uint8_t>(static_cast<int>(header.width), static_cast<int>(header.height), 3);
  std::vector<png_bytep> rows(header.height);
  for (png_uint_32 y = 0; y < header.height; ++y) rows[y] = out->rgb.row(static_cast<int>(y));
  if (!DecodeRows(png, info, &ctx, header, rows.data())) {
    out->rgb = Image<uint8_t>();
    return FailureToStatus(ctx, name);
  }
  for (int i = 0; i < std::min(ctx.warning_count, kMaxKeptWarnings); ++i) {
    out->warnings.push_back(std::string("PNG: ") + ctx.warnings[i]);
  }
  if (ctx.warning_count > kMaxKeptWarnings) {
    out->warnings.push_back("PNG: " + std::to_string(ctx.warning_count - kMaxKeptWarnings) + " more warnings");
  }
  return Status::Ok();
}

}  // namespace reconar::io_internal
