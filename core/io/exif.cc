#include "core/io/exif.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace reconar {

namespace {

constexpr uint16_t kTagMake = 0x010F;
constexpr uint16_t kTagModel = 0x0110;
constexpr uint16_t kTagOrientation = 0x0112;
constexpr uint16_t kTagExifIfdPointer = 0x8769;
constexpr uint16_t kTagExposureTime = 0x829A;
constexpr uint16_t kTagFNumber = 0x829D;
constexpr uint16_t kTagIsoSpeedRatings = 0x8827;
constexpr uint16_t kTagFocalLength = 0x920A;
constexpr uint16_t kTagPixelXDimension = 0xA002;
constexpr uint16_t kTagPixelYDimension = 0xA003;
constexpr uint16_t kTagFocalPlaneXResolution = 0xA20E;
constexpr uint16_t kTagFocalPlaneYResolution = 0xA20F;
constexpr uint16_t kTagFocalPlaneResolutionUnit = 0xA210;
constexpr uint16_t kTagFocalLengthIn35mm = 0xA405;

enum TiffType : uint16_t {
  kByte = 1, kAscii = 2, kShort = 3, kLong = 4, kRational = 5, kSByte = 6, kUndefined = 7,
  kSShort = 8, kSLong = 9, kSRational = 10, kFloat = 11, kDouble = 12, kIfd = 13,
};

constexpr size_t kMaxStringLength = 256;
constexpr double kMaxPlausibleFocalMm = 10000;

uint64_t TypeSize(uint16_t type) {
  switch (type) {
    case kByte: case kAscii: case kSByte: case kUndefined: return 1;
    case kShort: case kSShort: return 2;
    case kLong: case kSLong: case kFloat: case kIfd: return 4;
    case kRational: case kSRational: case kDouble: return 8;
    default: return 0;
  }
}

struct IfdEntry {
  uint16_t tag = 0;
  uint16_t type = 0;
  uint32_t count = 0;
  size_t value_offset = 0;  // offset of the first value byte inside the TIFF block
};

// Byte-order-aware, bounds-checked reads from the TIFF block. Every accessor returns false
// instead of reading past the end.
class TiffReader {
 public:
  TiffReader(std::string_view data, bool big_endian) : data_(data), big_endian_(big_endian) {}

  size_t size() const { return data_.size(); }

  bool Fits(uint64_t offset, uint64_t length) const {
    return offset <= data_.size() && length <= data_.size() - offset;
  }

  bool U16(uint64_t offset, uint16_t* out) const {
    if (!Fits(offset, 2)) return false;
    const auto* p = reinterpret_cast<const uint8_t*>(data_.data()) + offset;
    *out = big_endian_ ? static_cast<uint16_t>(p[0] << 8 | p[1]) : static_cast<uint16_t>(p[1] << 8 | p[0]);
    return true;
  }

  bool U32(uint64_t offset, uint32_t* out) const {
    if (!Fits(offset, 4)) return false;
    const auto* p = reinterpret_cast<const uint8_t*>(data_.data()) + offset;
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i) {
      const int shift = big_endian_ ? 8 * (3 - i) : 8 * i;
      v |= static_cast<uint32_t>(p[i]) << shift;
    }
    *out = v;
    return true;
  }

  std::string_view Bytes(uint64_t offset, uint64_t length) const {
    if (!Fits(offset, length)) return {};
    return data_.substr(static_cast<size_t>(offset), static_cast<size_t>(length));
  }

 private:
  std::string_view data_;
  bool big_endian_;
};

// Collects "; "-separated remarks, keeping the first few so a hostile block cannot grow it.
class Warnings {
 public:
  void Add(const std::string& text) {
    if (++count_ > kMaxKept) return;
    if (!text_.empty()) text_ += "; ";
    text_ += text;
  }
  std::string Take() {
    if (count_ > kMaxKept) text_ += "; and " + std::to_string(count_ - kMaxKept) + " more problems";
    count_ = 0;
    return std::move(text_);
  }

 private:
  static constexpr int kMaxKept = 8;
  std::string text_;
  int count_ = 0;
};

std::string Hex(uint16_t value) {
  char text[8];
  std::snprintf(text, sizeof(text), "0x%04X", static_cast<unsigned>(value));
  return text;
}

// Reads the entry table of the IFD at `offset`. Entries that do not fit the block, or whose
// values would lie outside it, are dropped with a warning; returns false if nothing was readable.
bool ReadIfd(const TiffReader& reader, uint32_t offset, const char* ifd_name, std::vector<IfdEntry>* entries,
             Warnings* warnings) {
  uint16_t count = 0;
  if (!reader.U16(offset, &count)) {
    warnings->Add(std::string(ifd_name) + " offset " + std::to_string(offset) + " is outside the " +
                  std::to_string(reader.size()) + "-byte EXIF block");
    return false;
  }
  const uint64_t table = static_cast<uint64_t>(offset) + 2;
  const uint64_t fitting = (reader.size() - std::min<uint64_t>(table, reader.size())) / 12;
  if (fitting < count) {
    warnings->Add(std::string(ifd_name) + " claims " + std::to_string(count) + " entries but only " +
                  std::to_string(fitting) + " fit in the EXIF block");
  }
  const uint64_t n = std::min<uint64_t>(count, fitting);
  for (uint64_t i = 0; i < n; ++i) {
    const uint64_t at = table + 12 * i;
    IfdEntry entry;
    if (!reader.U16(at, &entry.tag) || !reader.U16(at + 2, &entry.type) || !reader.U32(at + 4, &entry.count)) {
      break;
    }
    const uint64_t bytes = TypeSize(entry.type) * entry.count;
    if (TypeSize(entry.type) == 0 || entry.count == 0) continue;  // unknown type: skip silently
    uint64_t value_at = at + 8;
    if (bytes > 4) {
      uint32_t pointer = 0;
      if (!reader.U32(at + 8, &pointer)) continue;
      value_at = pointer;
    }
    if (!reader.Fits(value_at, bytes)) {
      warnings->Add(std::string(ifd_name) + " tag " + Hex(entry.tag) + " points outside the EXIF block");
      continue;
    }
    entry.value_offset = static_cast<size_t>(value_at);
    entries->push_back(entry);
  }
  return true;
}

bool GetUInt(const TiffReader& reader, const IfdEntry& entry, uint32_t* out) {
  if (entry.type == kShort) {
    uint16_t v = 0;
    if (!reader.U16(entry.value_offset, &v)) return false;
    *out = v;
    return true;
  }
  if (entry.type == kLong || entry.type == kIfd) return reader.U32(entry.value_offset, out);
  return false;
}

bool GetRational(const TiffReader& reader, const IfdEntry& entry, double* out) {
  uint32_t num = 0;
  uint32_t den = 0;
  if (entry.type == kRational) {
    if (!reader.U32(entry.value_offset, &num) || !reader.U32(entry.value_offset + 4, &den) || den == 0) return false;
    *out = static_cast<double>(num) / den;
    return true;
  }
  if (entry.type == kSRational) {
    if (!reader.U32(entry.value_offset, &num) || !reader.U32(entry.value_offset + 4, &den)) return false;
    const auto snum = static_cast<int32_t>(num);
    const auto sden = static_cast<int32_t>(den);
    if (sden == 0) return false;
    *out = static_cast<double>(snum) / sden;
    return true;
  }
  uint32_t integer = 0;
  if (!GetUInt(reader, entry, &integer)) return false;
  *out = integer;
  return true;
}

bool GetString(const TiffReader& reader, const IfdEntry& entry, std::string* out) {
  if (entry.type != kAscii && entry.type != kUndefined && entry.type != kByte) return false;
  std::string_view raw = reader.Bytes(entry.value_offset, entry.count);
  const size_t nul = raw.find('\0');
  if (nul != std::string_view::npos) raw = raw.substr(0, nul);
  if (raw.size() > kMaxStringLength) raw = raw.substr(0, kMaxStringLength);
  std::string s;
  s.reserve(raw.size());
  for (char c : raw) {
    const auto u = static_cast<unsigned char>(c);
    s += (u < 0x20 || u == 0x7F) ? ' ' : c;
  }
  const size_t first = s.find_first_not_of(' ');
  if (first == std::string::npos) {
    out->clear();
    return true;
  }
  *out = s.substr(first, s.find_last_not_of(' ') - first + 1);
  return true;
}

bool PlausibleFocal(double mm) { return std::isfinite(mm) && mm > 0 && mm <= kMaxPlausibleFocalMm; }

// Applies one entry to `info`; returns the ExifIFD offset through `exif_ifd` when it is that tag.
void ApplyEntry(const TiffReader& reader, const IfdEntry& entry, ExifInfo* info, Warnings* warnings,
                uint32_t* exif_ifd, bool* has_exif_ifd) {
  const auto bad = [&](const char* what) { warnings->Add(std::string("unreadable ") + what); };
  uint32_t u = 0;
  double d = 0;
  switch (entry.tag) {
    case kTagMake:
      if (!GetString(reader, entry, &info->make)) bad("Make");
      break;
    case kTagModel:
      if (!GetString(reader, entry, &info->model)) bad("Model");
      break;
    case kTagOrientation:
      if (!GetUInt(reader, entry, &u)) {
        bad("Orientation");
      } else if (u < 1 || u > 8) {
        warnings->Add("invalid Orientation " + std::to_string(u) + " (using 1)");
      } else {
        info->orientation = static_cast<int>(u);
      }
      break;
    case kTagExifIfdPointer:
      if (GetUInt(reader, entry, &u)) {
        *exif_ifd = u;
        *has_exif_ifd = true;
      } else {
        bad("ExifIFD pointer");
      }
      break;
    case kTagFocalLength:
      if (!GetRational(reader, entry, &d)) {
        bad("FocalLength");
      } else if (d != 0 && !PlausibleFocal(d)) {
        warnings->Add("implausible FocalLength " + std::to_string(d) + " mm ignored");
      } else {
        info->focal_length_mm = d;
      }
      break;
    case kTagFocalLengthIn35mm:
      if (!GetUInt(reader, entry, &u)) {
        bad("FocalLengthIn35mmFilm");
      } else if (u != 0 && !PlausibleFocal(u)) {
        warnings->Add("implausible FocalLengthIn35mmFilm " + std::to_string(u) + " mm ignored");
      } else {
        info->focal_length_35mm = u;
      }
      break;
    case kTagPixelXDimension:
    case kTagPixelYDimension:
      if (!GetUInt(reader, entry, &u) || u > 1'000'000) {
        bad(entry.tag == kTagPixelXDimension ? "PixelXDimension" : "PixelYDimension");
      } else {
        (entry.tag == kTagPixelXDimension ? info->pixel_x_dimension : info->pixel_y_dimension) = static_cast<int>(u);
      }
      break;
    case kTagFocalPlaneXResolution:
    case kTagFocalPlaneYResolution:
      if (!GetRational(reader, entry, &d) || !std::isfinite(d) || d < 0) {
        bad(entry.tag == kTagFocalPlaneXResolution ? "FocalPlaneXResolution" : "FocalPlaneYResolution");
      } else {
        (entry.tag == kTagFocalPlaneXResolution ? info->focal_plane_x_resolution : info->focal_plane_y_resolution) = d;
      }
      break;
    case kTagExposureTime:
      if (!GetRational(reader, entry, &d) || !std::isfinite(d) || d < 0 || d > 3600) {
        bad("ExposureTime");
      } else {
        info->exposure_time_s = d;
      }
      break;
    case kTagFNumber:
      if (!GetRational(reader, entry, &d) || !std::isfinite(d) || d < 0 || d > 1000) {
        bad("FNumber");
      } else {
        info->f_number = d;
      }
      break;
    case kTagIsoSpeedRatings:
      if (!GetUInt(reader, entry, &u) || u > 10'000'000) {
        bad("ISOSpeedRatings");
      } else {
        info->iso = static_cast<int>(u);
      }
      break;
    case kTagFocalPlaneResolutionUnit:
      if (!GetUInt(reader, entry, &u) || u < 1 || u > 5) {
        bad("FocalPlaneResolutionUnit");
      } else {
        info->focal_plane_resolution_unit = static_cast<int>(u);
      }
      break;
    default:
      break;
  }
}

}  // namespace

ExifInfo ParseExifTiff(std::string_view tiff) {
  ExifInfo info;
  Warnings warnings;
  if (tiff.size() < 8) {
    info.warning = "EXIF block too short (" + std::to_string(tiff.size()) + " bytes)";
    return info;
  }
  bool big_endian;
  if (tiff.substr(0, 2) == "MM") {
    big_endian = true;
  } else if (tiff.substr(0, 2) == "II") {
    big_endian = false;
  } else {
    info.warning = "EXIF block has no TIFF byte-order mark";
    return info;
  }
  const TiffReader reader(tiff, big_endian);
  uint16_t magic = 0;
  uint32_t ifd0 = 0;
  if (!reader.U16(2, &magic) || magic != 42 || !reader.U32(4, &ifd0)) {
    info.warning = "EXIF block has a bad TIFF header";
    return info;
  }
  std::vector<IfdEntry> entries;
  if (!ReadIfd(reader, ifd0, "IFD0", &entries, &warnings)) {
    info.warning = warnings.Take();
    return info;
  }
  info.present = true;
  uint32_t exif_ifd = 0;
  bool has_exif_ifd = false;
  for (const IfdEntry& entry : entries) ApplyEntry(reader, entry, &info, &warnings, &exif_ifd, &has_exif_ifd);
  if (has_exif_ifd) {
    std::vector<IfdEntry> exif_entries;
    if (ReadIfd(reader, exif_ifd, "ExifIFD", &exif_entries, &warnings)) {
      bool ignored_flag = false;
      uint32_t ignored_offset = 0;
      // The ExifIFD pointer is only honoured once, so a block pointing at itself cannot loop.
      for (const IfdEntry& entry : exif_entries) {
        if (entry.tag == kTagExifIfdPointer) continue;
        ApplyEntry(reader, entry, &info, &warnings, &ignored_offset, &ignored_flag);
      }
    }
  }
  info.warning = warnings.Take();
  return info;
}

ExifInfo ParseExifApp1(std::string_view app1_payload) {
  // "Exif\0" followed by a pad byte that is normally \0.
  if (app1_payload.size() < 6 || app1_payload.substr(0, 5) != std::string_view("Exif\0", 5)) {
    ExifInfo info;
    info.warning = "APP1 segment is not EXIF";
    return info;
  }
  return ParseExifTiff(app1_payload.substr(6));
}

ExifInfo ReadExifFromJpeg(std::string_view jpeg) {
  ExifInfo none;
  const auto byte = [&](size_t i) { return static_cast<uint8_t>(jpeg[i]); };
  if (jpeg.size() < 4 || byte(0) != 0xFF || byte(1) != 0xD8) {
    none.warning = "not a JPEG stream";
    return none;
  }
  size_t pos = 2;
  while (pos < jpeg.size()) {
    if (byte(pos) != 0xFF) {
      none.warning = "JPEG marker expected at byte " + std::to_string(pos);
      return none;
    }
    while (pos < jpeg.size() && byte(pos) == 0xFF) ++pos;  // fill bytes
    if (pos >= jpeg.size()) break;
    const uint8_t marker = byte(pos++);
    if (marker == 0xDA || marker == 0xD9) return none;  // scan data or end: no EXIF before it
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) continue;  // no length field
    if (jpeg.size() - pos < 2) break;
    const size_t length = static_cast<size_t>(byte(pos)) << 8 | byte(pos + 1);
    if (length < 2 || length > jpeg.size() - pos) break;
    const std::string_view payload = jpeg.substr(pos + 2, length - 2);
    if (marker == 0xE1 && payload.size() >= 5 && payload.substr(0, 5) == std::string_view("Exif\0", 5)) {
      return ParseExifApp1(payload);
    }
    pos += length;
  }
  none.warning = "JPEG marker segment runs past the end of the data";
  return none;
}

namespace {

// One IFD entry to write: its value bytes (little-endian), inline when at most 4 bytes.
struct EntryToWrite {
  uint16_t tag;
  uint16_t type;
  uint32_t count;
  std::string value;
};

void PutU16(std::string* out, uint16_t v) { out->append({static_cast<char>(v & 0xFF), static_cast<char>(v >> 8)}); }
void PutU32(std::string* out, uint32_t v) {
  for (int shift = 0; shift < 32; shift += 8) out->push_back(static_cast<char>((v >> shift) & 0xFF));
}
void SetU32(std::string* out, size_t at, uint32_t v) {
  for (int k = 0; k < 4; ++k) (*out)[at + static_cast<size_t>(k)] = static_cast<char>((v >> (8 * k)) & 0xFF);
}

EntryToWrite Ascii(uint16_t tag, const std::string& text) {
  std::string value = text.substr(0, kMaxStringLength - 1);
  value.push_back('\0');
  return {tag, kAscii, static_cast<uint32_t>(value.size()), value};
}
EntryToWrite Short(uint16_t tag, int v) {
  std::string value;
  PutU16(&value, static_cast<uint16_t>(std::clamp(v, 0, 65535)));
  return {tag, kShort, 1, value};
}
EntryToWrite Long(uint16_t tag, uint32_t v) {
  std::string value;
  PutU32(&value, v);
  return {tag, kLong, 1, value};
}
// A positive rational with a denominator of 10000 (four decimals).
EntryToWrite Rational(uint16_t tag, double v) {
  std::string value;
  PutU32(&value, static_cast<uint32_t>(std::lround(std::clamp(v, 0.0, 4e5) * 10000.0)));
  PutU32(&value, 10000);
  return {tag, kRational, 1, value};
}

// Appends an IFD (entries sorted by tag, as TIFF requires) at the end of `tiff`, then the values
// that do not fit inline; returns the offset of the "next IFD" field (0 written).
size_t AppendIfd(std::string* tiff, std::vector<EntryToWrite> entries) {
  std::sort(entries.begin(), entries.end(), [](const EntryToWrite& a, const EntryToWrite& b) { return a.tag < b.tag; });
  const size_t start = tiff->size();
  const size_t data_start = start + 2 + 12 * entries.size() + 4;
  std::string data;
  PutU16(tiff, static_cast<uint16_t>(entries.size()));
  for (const EntryToWrite& e : entries) {
    PutU16(tiff, e.tag);
    PutU16(tiff, e.type);
    PutU32(tiff, e.count);
    if (e.value.size() <= 4) {
      std::string inline_value = e.value;
      inline_value.resize(4, '\0');
      tiff->append(inline_value);
    } else {
      PutU32(tiff, static_cast<uint32_t>(data_start + data.size()));
      data.append(e.value);
      if (data.size() % 2 != 0) data.push_back('\0');  // values start on a word boundary
    }
  }
  const size_t next_ifd = tiff->size();
  PutU32(tiff, 0);
  tiff->append(data);
  return next_ifd;
}

}  // namespace

std::string BuildExifApp1(const ExifInfo& info) {
  std::vector<EntryToWrite> ifd0, exif_ifd;
  if (!info.make.empty()) ifd0.push_back(Ascii(kTagMake, info.make));
  if (!info.model.empty()) ifd0.push_back(Ascii(kTagModel, info.model));
  ifd0.push_back(Short(kTagOrientation, info.orientation >= 1 && info.orientation <= 8 ? info.orientation : 1));
  if (info.focal_length_mm > 0) exif_ifd.push_back(Rational(kTagFocalLength, info.focal_length_mm));
  if (info.focal_length_35mm > 0)
    exif_ifd.push_back(Short(kTagFocalLengthIn35mm, static_cast<int>(std::lround(info.focal_length_35mm))));
  if (info.pixel_x_dimension > 0)
    exif_ifd.push_back(Long(kTagPixelXDimension, static_cast<uint32_t>(info.pixel_x_dimension)));
  if (info.pixel_y_dimension > 0)
    exif_ifd.push_back(Long(kTagPixelYDimension, static_cast<uint32_t>(info.pixel_y_dimension)));
  if (info.focal_plane_x_resolution > 0 && info.focal_plane_y_resolution > 0) {
    exif_ifd.push_back(Rational(kTagFocalPlaneXResolution, info.focal_plane_x_resolution));
    exif_ifd.push_back(Rational(kTagFocalPlaneYResolution, info.focal_plane_y_resolution));
    exif_ifd.push_back(Short(kTagFocalPlaneResolutionUnit, info.focal_plane_resolution_unit));
  }
  std::string tiff = "II*";
  tiff.push_back('\0');
  PutU32(&tiff, 8);
  size_t pointer_value = 0;
  if (!exif_ifd.empty()) {
    ifd0.push_back(Long(kTagExifIfdPointer, 0));  // patched below
  }
  std::sort(ifd0.begin(), ifd0.end(), [](const EntryToWrite& a, const EntryToWrite& b) { return a.tag < b.tag; });
  for (size_t k = 0; k < ifd0.size(); ++k) {
    if (ifd0[k].tag == kTagExifIfdPointer) pointer_value = 8 + 2 + 12 * k + 8;
  }
  AppendIfd(&tiff, ifd0);
  if (!exif_ifd.empty()) {
    SetU32(&tiff, pointer_value, static_cast<uint32_t>(tiff.size()));
    AppendIfd(&tiff, exif_ifd);
  }
  std::string app1("Exif\0\0", 6);
  return app1 + tiff;
}

}  // namespace reconar
