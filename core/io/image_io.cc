#include "core/io/image_io.h"

#include <cstdio>

#include "core/base/atomic_file.h"
#include "core/io/decoders.h"
#include "core/io/orientation.h"

namespace reconar {

namespace {

bool StartsWith(std::string_view bytes, std::string_view prefix) { return bytes.substr(0, prefix.size()) == prefix; }

// Formats we recognise only to say clearly that they are not supported; empty if unknown.
std::string RecognisedUnsupportedFormat(std::string_view bytes) {
  if (StartsWith(bytes, "GIF87a") || StartsWith(bytes, "GIF89a")) return "GIF";
  if (StartsWith(bytes, "BM")) return "BMP";
  if (StartsWith(bytes, std::string_view("II*\0", 4)) || StartsWith(bytes, std::string_view("MM\0*", 4))) {
    return "TIFF";
  }
  if (StartsWith(bytes, "RIFF") && bytes.size() >= 12 && bytes.substr(8, 4) == "WEBP") return "WebP";
  if (bytes.size() >= 12 && bytes.substr(4, 4) == "ftyp") {
    const std::string_view brand = bytes.substr(8, 4);
    if (brand == "avif" || brand == "avis") return "AVIF";
    if (brand == "heic" || brand == "heix" || brand == "mif1" || brand == "msf1" || brand == "hevc") return "HEIC/HEIF";
  }
  return {};
}

std::string FirstBytesHex(std::string_view bytes) {
  std::string hex;
  for (size_t i = 0; i < bytes.size() && i < 8; ++i) {
    char text[4];
    std::snprintf(text, sizeof(text), "%s%02x", i == 0 ? "" : " ", static_cast<unsigned>(static_cast<uint8_t>(bytes[i])));
    hex += text;
  }
  return hex;
}

}  // namespace

namespace io_internal {

Status CheckDimensions(uint64_t width, uint64_t height, const std::string& name, const ImageReadOptions& options) {
  if (width == 0 || height == 0) {
    return FileError(StatusCode::kCorruptData, name,
                     "image has zero size (" + std::to_string(width) + "x" + std::to_string(height) + ")");
  }
  // Both are below 2^32, so the product cannot overflow 64 bits.
  const uint64_t pixels = width * height;
  if (pixels > static_cast<uint64_t>(options.max_pixels)) {
    return FileError(StatusCode::kResourceExhausted, name,
                     "image is " + std::to_string(width) + "x" + std::to_string(height) + " = " +
                         std::to_string(pixels) + " pixels, above the limit of " + std::to_string(options.max_pixels));
  }
  return Status::Ok();
}

}  // namespace io_internal

ImageFormat DetectImageFormat(std::string_view bytes) {
  if (StartsWith(bytes, "\xFF\xD8\xFF")) return ImageFormat::kJpeg;
  if (StartsWith(bytes, "\x89PNG\r\n\x1A\n")) return ImageFormat::kPng;
  return ImageFormat::kUnknown;
}

Result<DecodedImage> ReadImage(const std::string& path, const ImageReadOptions& options) {
  RECONAR_ASSIGN_OR_RETURN(const std::string bytes, ReadFileToString(path));
  return ReadImageFromMemory(bytes, path, options);
}

Result<ImageHeader> ReadImageHeader(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(const std::string bytes, ReadFileToString(path));
  if (bytes.empty()) return FileError(StatusCode::kCorruptData, path, "empty file (0 bytes)");
  ImageHeader header;
  switch (DetectImageFormat(bytes)) {
    case ImageFormat::kJpeg:
      RECONAR_RETURN_IF_ERROR(io_internal::ReadJpegHeader(bytes, path, &header));
      break;
    case ImageFormat::kPng:
      RECONAR_RETURN_IF_ERROR(io_internal::ReadPngHeader(bytes, path, &header));
      break;
    case ImageFormat::kUnknown:
      return FileError(StatusCode::kCorruptData, path, "not a JPEG or PNG image");
  }
  if (OrientationSwapsAxes(header.exif.orientation)) std::swap(header.width, header.height);
  return header;
}

Result<DecodedImage> ReadImageFromMemory(std::string_view bytes, const std::string& name,
                                         const ImageReadOptions& options) {
  if (options.max_pixels <= 0) {
    return FileError(StatusCode::kInvalidArgument, name,
                     "ImageReadOptions::max_pixels must be positive, got " + std::to_string(options.max_pixels));
  }
  if (bytes.empty()) return FileError(StatusCode::kCorruptData, name, "empty file (0 bytes)");

  DecodedImage image;
  switch (DetectImageFormat(bytes)) {
    case ImageFormat::kJpeg:
      RECONAR_RETURN_IF_ERROR(io_internal::DecodeJpeg(bytes, name, options, &image));
      break;
    case ImageFormat::kPng:
      RECONAR_RETURN_IF_ERROR(io_internal::DecodePng(bytes, name, options, &image));
      break;
    case ImageFormat::kUnknown: {
      const std::string format = RecognisedUnsupportedFormat(bytes);
      if (!format.empty()) {
        return FileError(StatusCode::kUnsupported, name, format + " images are not supported; convert to JPEG or PNG");
      }
      return FileError(StatusCode::kCorruptData, name,
                       "not a JPEG or PNG image (starts with bytes " + FirstBytesHex(bytes) + ")");
    }
  }
  image.original_width = image.rgb.width();
  image.original_height = image.rgb.height();
  if (options.apply_exif_orientation && image.exif.orientation != 1) {
    image.rgb = ApplyOrientation(image.rgb, image.exif.orientation);
  }
  return image;
}

}  // namespace reconar
