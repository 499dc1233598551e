#include "core/io/intrinsics_file.h"

#include <charconv>
#include <cmath>
#include <string_view>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/base/number_format.h"
#include "core/base/text_fields.h"

namespace reconar {
namespace {

constexpr const char* kFieldNames = "\"fx fy cx cy k1 k2 width height\"";

bool IsDataLine(std::string_view line) {
  const size_t start = line.find_first_not_of(" \t\r");
  return start != std::string_view::npos && line[start] != '#';
}

}  // namespace

Status WriteIntrinsics(const std::string& path, const CameraIntrinsics& intrinsics) {
  const double values[] = {intrinsics.fx, intrinsics.fy, intrinsics.cx, intrinsics.cy, intrinsics.k1, intrinsics.k2};
  for (double v : values) {
    if (!std::isfinite(v)) return InvalidArgument(path + ": refusing to write non-finite intrinsics");
  }
  if (!intrinsics.valid() || intrinsics.width < 0 || intrinsics.height < 0) {
    return InvalidArgument(path + ": refusing to write intrinsics with fx, fy <= 0 or a negative size");
  }
  std::string text =
      "# reconar camera intrinsics. Pixels: the centre of the top-left pixel is (0, 0), x right, y down.\n"
      "# A camera point X (z forward) maps to p = X.xy / X.z, d = 1 + k1 |p|^2 + k2 |p|^4,\n"
      "# u = fx d p.x + cx, v = fy d p.y + cy. width and height are 0 when unknown.\n"
      "# fx fy cx cy k1 k2 width height\n";
  for (double v : values) text += FormatShortest(v) + " ";
  text += std::to_string(intrinsics.width) + " " + std::to_string(intrinsics.height) + "\n";
  return WriteFileAtomically(path, text);
}

Result<CameraIntrinsics> ReadIntrinsics(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
  static constexpr const char* kNames[6] = {"fx", "fy", "cx", "cy", "k1", "k2"};
  std::vector<std::string_view> fields;
  std::string_view rest(text);
  int line_number = 0;
  bool have_data = false;
  CameraIntrinsics intrinsics;
  while (!rest.empty()) {
    const size_t end = rest.find('\n');
    const std::string_view line = rest.substr(0, end);
    rest = end == std::string_view::npos ? std::string_view() : rest.substr(end + 1);
    ++line_number;
    if (!IsDataLine(line)) continue;
    const std::string where = path + ":" + std::to_string(line_number);
    if (have_data) return CorruptData(where + ": unexpected second data line");
    have_data = true;
    SplitFields(line, &fields);
    if (fields.size() != 8) {
      return CorruptData(where + ": expected 8 fields " + kFieldNames + ", found " + std::to_string(fields.size()));
    }
    double values[6];
    for (int k = 0; k < 6; ++k) {
      const std::string_view field = fields[static_cast<size_t>(k)];
      const auto result = std::from_chars(field.data(), field.data() + field.size(), values[k]);
      if (result.ec != std::errc() || result.ptr != field.data() + field.size() || !std::isfinite(values[k])) {
        return CorruptData(where + ": " + kNames[k] + " '" + std::string(field) + "' is not a finite number");
      }
    }
    int size[2];
    for (int k = 0; k < 2; ++k) {
      const std::string_view field = fields[static_cast<size_t>(6 + k)];
      const auto result = std::from_chars(field.data(), field.data() + field.size(), size[k]);
      if (result.ec != std::errc() || result.ptr != field.data() + field.size() || size[k] < 0) {
        return CorruptData(where + ": " + (k == 0 ? "width" : "height") + " '" + std::string(field) +
                           "' is not a non-negative integer");
      }
    }
    intrinsics.fx = values[0];
    intrinsics.fy = values[1];
    intrinsics.cx = values[2];
    intrinsics.cy = values[3];
    intrinsics.k1 = values[4];
    intrinsics.k2 = values[5];
    intrinsics.width = size[0];
    intrinsics.height = size[1];
    if (!intrinsics.valid()) return CorruptData(where + ": fx and fy must be positive");
  }
  if (!have_data) return CorruptData(path + ": no data line " + kFieldNames);
  return intrinsics;
}

}  // namespace reconar
