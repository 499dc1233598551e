#include "tests/core/io/test_images.h"

#include <png.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <jpeglib.h>

namespace reconar::testing {

namespace {

void AppendToString(png_structp png, png_bytep data, size_t length) {
  static_cast<std::string*>(png_get_io_ptr(png))->append(reinterpret_cast<const char*>(data), length);
}
void NoFlush(png_structp) {}

int Channels(int color_type) {
  switch (color_type) {
    case PNG_COLOR_TYPE_GRAY: return 1;
    case PNG_COLOR_TYPE_GRAY_ALPHA: return 2;
    case PNG_COLOR_TYPE_RGB: return 3;
    case PNG_COLOR_TYPE_RGB_ALPHA: return 4;
    case PNG_COLOR_TYPE_PALETTE: return 1;
    default: return 0;
  }
}

// Packs one row of samples into PNG's big-endian, bit-packed row layout.
std::vector<uint8_t> PackRow(const PngSpec& spec, int y) {
  const int samples_per_row = spec.width * Channels(spec.color_type);
  const uint16_t* src = spec.samples.data() + static_cast<size_t>(y) * samples_per_row;
  std::vector<uint8_t> row;
  if (spec.bit_depth == 16) {
    for (int i = 0; i < samples_per_row; ++i) {
      row.push_back(static_cast<uint8_t>(src[i] >> 8));
      row.push_back(static_cast<uint8_t>(src[i] & 0xFF));
    }
  } else if (spec.bit_depth == 8) {
    for (int i = 0; i < samples_per_row; ++i) row.push_back(static_cast<uint8_t>(src[i]));
  } else {
    const int per_byte = 8 / spec.bit_depth;
    row.assign((samples_per_row + per_byte - 1) / per_byte, 0);
    for (int i = 0; i < samples_per_row; ++i) {
      const int shift = 8 - spec.bit_depth * (i % per_byte + 1);
      row[i / per_byte] |= static_cast<uint8_t>(src[i] << shift);
    }
  }
  return row;
}

}  // namespace

std::string EncodePng(const PngSpec& spec, bool header_only) {
  std::string out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error("test PNG encoding failed");
  }
  png_set_write_fn(png, &out, AppendToString, NoFlush);
  png_set_IHDR(png, info, spec.width, spec.height, spec.bit_depth, spec.color_type,
               spec.interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  std::vector<png_color> palette;
  for (const auto& c : spec.palette) palette.push_back(png_color{c[0], c[1], c[2]});
  if (!palette.empty()) png_set_PLTE(png, info, palette.data(), static_cast<int>(palette.size()));
  if (!spec.palette_alpha.empty()) {
    png_set_tRNS(png, info, spec.palette_alpha.data(), static_cast<int>(spec.palette_alpha.size()), nullptr);
  }
  std::string exif = spec.exif;
  if (!exif.empty()) {
    png_set_eXIf_1(png, info, static_cast<png_uint_32>(exif.size()), reinterpret_cast<png_bytep>(exif.data()));
  }
  png_write_info(png, info);
  if (!header_only) {
    std::vector<std::vector<uint8_t>> rows;
    std::vector<png_bytep> row_pointers;
    for (int y = 0; y < spec.height; ++y) rows.push_back(PackRow(spec, y));
    for (auto& row : rows) row_pointers.push_back(row.data());
    png_write_image(png, row_pointers.data());
    png_write_end(png, nullptr);
  }
  png_destroy_write_struct(&png, &info);
  return out;
}

std::string EncodeJpeg(const JpegSpec& spec) {
  jpeg_compress_struct cinfo{};
  jpeg_error_mgr jerr{};
  cinfo.err = jpeg_std_error(&jerr);  // test inputs are valid; libjpeg's exit() is acceptable here
  jpeg_create_compress(&cinfo);
  unsigned char* buffer = nullptr;
  unsigned long size = 0;
  jpeg_mem_dest(&cinfo, &buffer, &size);
  cinfo.image_width = spec.width;
  cinfo.image_height = spec.height;
  cinfo.input_components = spec.components;
  cinfo.in_color_space = spec.in_color_space != 0 ? static_cast<J_COLOR_SPACE>(spec.in_color_space)
                         : spec.components == 1   ? JCS_GRAYSCALE
                         : spec.components == 4   ? JCS_CMYK
                                                  : JCS_RGB;
  jpeg_set_defaults(&cinfo);
  if (spec.jpeg_color_space != 0) jpeg_set_colorspace(&cinfo, static_cast<J_COLOR_SPACE>(spec.jpeg_color_space));
  jpeg_set_quality(&cinfo, spec.quality, TRUE);
  if (spec.progressive) jpeg_simple_progression(&cinfo);
  cinfo.restart_in_rows = spec.restart_interval_rows;
  jpeg_start_compress(&cinfo, TRUE);
  if (!spec.app1.empty()) {
    jpeg_write_marker(&cinfo, JPEG_APP0 + 1, reinterpret_cast<const JOCTET*>(spec.app1.data()),
                      static_cast<unsigned>(spec.app1.size()));
  }
  const size_t row_bytes = static_cast<size_t>(spec.width) * spec.components;
  while (cinfo.next_scanline < cinfo.image_height) {
    JSAMPROW row = const_cast<JSAMPROW>(spec.pixels.data() + cinfo.next_scanline * row_bytes);
    jpeg_write_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_compress(&cinfo);
  std::string out(reinterpret_cast<const char*>(buffer), size);
  jpeg_destroy_compress(&cinfo);
  std::free(buffer);
  return out;
}

std::vector<uint8_t> TestPattern(int width, int height, int channels) {
  std::vector<uint8_t> pixels(static_cast<size_t>(width) * height * channels);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < channels; ++c) {
        const double v = 128 + 60 * std::sin(0.11 * x + 0.7 * c) + 50 * std::cos(0.07 * y - 0.3 * c);
        pixels[(static_cast<size_t>(y) * width + x) * channels + c] = static_cast<uint8_t>(std::lround(v));
      }
    }
  }
  return pixels;
}

std::string TiffBuilder::U16(uint16_t v) const {
  const char hi = static_cast<char>(v >> 8);
  const char lo = static_cast<char>(v & 0xFF);
  return big_endian_ ? std::string{hi, lo} : std::string{lo, hi};
}

std::string TiffBuilder::U32(uint32_t v) const {
  return big_endian_ ? U16(static_cast<uint16_t>(v >> 16)) + U16(static_cast<uint16_t>(v & 0xFFFF))
                     : U16(static_cast<uint16_t>(v & 0xFFFF)) + U16(static_cast<uint16_t>(v >> 16));
}

TiffBuilder::Entry TiffBuilder::Ascii(uint16_t tag, const std::string& value) const {
  return Entry{tag, 2, static_cast<uint32_t>(value.size() + 1), value + std::string(1, '\0')};
}
TiffBuilder::Entry TiffBuilder::Short(uint16_t tag, uint16_t value) const { return Entry{tag, 3, 1, U16(value)}; }
TiffBuilder::Entry TiffBuilder::Long(uint16_t tag, uint32_t value) const { return Entry{tag, 4, 1, U32(value)}; }
TiffBuilder::Entry TiffBuilder::Rational(uint16_t tag, uint32_t num, uint32_t den) const {
  return Entry{tag, 5, 1, U32(num) + U32(den)};
}

void TiffBuilder::WriteIfd(const std::vector<Entry>& entries, std::string* out, size_t ifd_offset) const {
  size_t data_offset = ifd_offset + 2 + 12 * entries.size() + 4;
  std::string table = U16(static_cast<uint16_t>(entries.size()));
  std::string data;
  for (const Entry& e : entries) {
    table += U16(e.tag) + U16(e.type) + U32(e.count);
    if (e.data.size() <= 4) {
      table += e.data + std::string(4 - e.data.size(), '\0');
    } else {
      table += U32(static_cast<uint32_t>(data_offset + data.size()));
      data += e.data;
      if (data.size() % 2 != 0) data += '\0';
    }
  }
  table += U32(0);  // no next IFD
  *out += table + data;
}

std::string TiffBuilder::Build() const {
  std::string out = big_endian_ ? std::string("MM") : std::string("II");
  out += U16(42) + U32(8);
  std::vector<Entry> ifd0 = ifd0_;
  if (!exif_.empty()) ifd0.push_back(Long(0x8769, 0));  // patched below once the offset is known
  WriteIfd(ifd0, &out, 8);
  if (!exif_.empty()) {
    const size_t exif_offset = out.size();
    const size_t pointer_value_at = 8 + 2 + 12 * (ifd0.size() - 1) + 8;
    out.replace(pointer_value_at, 4, U32(static_cast<uint32_t>(exif_offset)));
    WriteIfd(exif_, &out, exif_offset);
  }
  return out;
}

std::string MakeTempDir(const std::string& tag) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("reconar_io_test_" + std::to_string(::getpid()) + "_" + tag);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

void WriteBytes(const std::string& path, const std::string& bytes) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!file) throw std::runtime_error("cannot write " + path);
}

}  // namespace reconar::testing
