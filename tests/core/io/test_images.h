#pragma once
// Test-only encoders (libpng / libjpeg) and a builder for hand-made EXIF blocks, so the decoder
// tests can produce every variant they need in memory.
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace reconar::testing {

struct PngSpec {
  int width = 0;
  int height = 0;
  int color_type = 0;  // PNG_COLOR_TYPE_*
  int bit_depth = 8;
  bool interlaced = false;
  // Samples row-major, channels interleaved, one value per sample (palette indices for palettes).
  std::vector<uint16_t> samples;
  std::vector<std::array<uint8_t, 3>> palette;  // for PNG_COLOR_TYPE_PALETTE
  std::vector<uint8_t> palette_alpha;           // tRNS for palettes (optional)
  std::string exif;                             // eXIf chunk payload (a TIFF block), empty for none
};

// Returns the encoded PNG; writes only the header chunks when header_only is set.
std::string EncodePng(const PngSpec& spec, bool header_only = false);

struct JpegSpec {
  int width = 0;
  int height = 0;
  int components = 3;   // 1 gray, 3 RGB, 4 CMYK
  int in_color_space = 0;   // J_COLOR_SPACE of `pixels`; 0 picks from components
  int jpeg_color_space = 0; // J_COLOR_SPACE stored in the file; 0 keeps libjpeg's default
  int quality = 95;
  bool progressive = false;
  int restart_interval_rows = 0;
  std::vector<uint8_t> pixels;
  std::string app1;  // raw APP1 payload (e.g. "Exif\0\0" + TIFF), empty for none
};

std::string EncodeJpeg(const JpegSpec& spec);

// A smooth, textured RGB test pattern (deterministic).
std::vector<uint8_t> TestPattern(int width, int height, int channels);

// Builds a TIFF/EXIF block in either byte order: IFD0 entries, then an optional ExifIFD.
class TiffBuilder {
 public:
  explicit TiffBuilder(bool big_endian) : big_endian_(big_endian) {}
  void Ifd0Ascii(uint16_t tag, const std::string& value) { ifd0_.push_back(Ascii(tag, value)); }
  void Ifd0Short(uint16_t tag, uint16_t value) { ifd0_.push_back(Short(tag, value)); }
  void ExifRational(uint16_t tag, uint32_t num, uint32_t den) { exif_.push_back(Rational(tag, num, den)); }
  void ExifShort(uint16_t tag, uint16_t value) { exif_.push_back(Short(tag, value)); }
  void ExifLong(uint16_t tag, uint32_t value) { exif_.push_back(Long(tag, value)); }
  // The TIFF block ("II*\0..." / "MM\0*...").
  std::string Build() const;
  // The APP1 payload: "Exif\0\0" + Build().
  std::string BuildApp1() const { return std::string("Exif\0\0", 6) + Build(); }

 private:
  struct Entry {
    uint16_t tag;
    uint16_t type;
    uint32_t count;
    std::string data;  // value bytes in the block's byte order
  };
  Entry Ascii(uint16_t tag, const std::string& value) const;
  Entry Short(uint16_t tag, uint16_t value) const;
  Entry Long(uint16_t tag, uint32_t value) const;
  Entry Rational(uint16_t tag, uint32_t num, uint32_t den) const;
  std::string U16(uint16_t v) const;
  std::string U32(uint32_t v) const;
  void WriteIfd(const std::vector<Entry>& entries, std::string* out, size_t ifd_offset) const;

  bool big_endian_;
  std::vector<Entry> ifd0_;
  std::vector<Entry> exif_;
};

// A fresh empty directory under the system temp dir, unique to this process and `tag`.
std::string MakeTempDir(const std::string& tag);
void WriteBytes(const std::string& path, const std::string& bytes);

}  // namespace reconar::testing
