#include "tests/support/bunny_scans.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>
#include <string_view>
#include <vector>

#include "core/base/atomic_file.h"

namespace reconar::testing {
namespace {

// A triangle edge longer than this many median grid spacings spans a depth discontinuity.
constexpr float kMaxEdgeInGridSpacings = 4.0f;

struct ScanPlacement {
  std::string file;
  Eigen::Vector3f translation;
  Eigen::Quaternionf rotation;  // as written in bun.conf; applied conjugated
};

struct RangeScan {
  std::vector<Eigen::Vector3f> positions;
  int rows = 0;
  int cols = 0;
  std::vector<int32_t> grid;  // rows * cols vertex indices, -1 for an empty cell
};

// Whitespace-separated numbers of an ASCII PLY body.
class NumberReader {
 public:
  explicit NumberReader(std::string_view text) : text_(text) {}

  template <typename T>
  bool Next(T* value) {
    while (position_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[position_]))) ++position_;
    const char* begin = text_.data() + position_;
    const char* end = text_.data() + text_.size();
    const std::from_chars_result parsed = std::from_chars(begin, end, *value);
    if (parsed.ec != std::errc() || (parsed.ptr != end && !std::isspace(static_cast<unsigned char>(*parsed.ptr)))) {
      return false;
    }
    position_ = static_cast<size_t>(parsed.ptr - text_.data());
    return true;
  }

 private:
  std::string_view text_;
  size_t position_ = 0;
};

Result<std::vector<ScanPlacement>> ReadBunConf(const std::string& path) {
  Result<std::string> text = ReadFileToString(path);
  if (!text.ok()) return text.status();
  std::vector<ScanPlacement> placements;
  std::istringstream lines(*text);
  std::string line;
  int line_number = 0;
  while (std::getline(lines, line)) {
    ++line_number;
    std::istringstream fields(line);
    std::string keyword;
    if (!(fields >> keyword) || keyword != "bmesh") continue;
    ScanPlacement placement;
    float qx, qy, qz, qw;
    if (!(fields >> placement.file >> placement.translation.x() >> placement.translation.y() >>
          placement.translation.z() >> qx >> qy >> qz >> qw)) {
      return FileError(StatusCode::kCorruptData, path,
                       "line " + std::to_string(line_number) + ": expected \"bmesh FILE tx ty tz qx qy qz qw\"");
    }
    placement.rotation = Eigen::Quaternionf(qw, qx, qy, qz);
    if (!(placement.rotation.norm() > 0.5f)) {
      return FileError(StatusCode::kCorruptData, path, "line " + std::to_string(line_number) + ": not a rotation");
    }
    placement.rotation.normalize();
    placements.push_back(std::move(placement));
  }
  if (placements.empty()) return FileError(StatusCode::kCorruptData, path, "no \"bmesh\" line");
  return placements;
}

Result<RangeScan> ReadRangeScan(const std::string& path) {
  Result<std::string> text = ReadFileToString(path);
  if (!text.ok()) return text.status();
  auto corrupt = [&](const std::string& reason) { return FileError(StatusCode::kCorruptData, path, reason); };
  const size_t header_end = text->find("end_header\n");
  if (text->rfind("ply\n", 0) != 0 || header_end == std::string::npos) return corrupt("not an ASCII PLY file");
  std::istringstream header(text->substr(0, header_end));
  std::string line;
  RangeScan scan;
  long num_vertices = -1;
  long num_cells = -1;
  std::vector<std::string> vertex_properties;
  std::string element;
  while (std::getline(header, line)) {
    std::istringstream fields(line);
    std::string keyword;
    fields >> keyword;
    if (keyword == "format") {
      std::string format;
      fields >> format;
      if (format != "ascii") return corrupt("format \"" + format + "\": only ascii range scans are read");
    } else if (keyword == "obj_info") {
      std::string name;
      fields >> name;
      if (name == "num_cols") fields >> scan.cols;
      if (name == "num_rows") fields >> scan.rows;
    } else if (keyword == "element") {
      long count = -1;
      fields >> element >> count;
      if (element == "vertex" && num_cells < 0) {
        num_vertices = count;
      } else if (element == "range_grid" && num_vertices >= 0) {
        num_cells = count;
      } else {
        return corrupt("unexpected element \"" + element + "\" (want vertex, then range_grid)");
      }
    } else if (keyword == "property") {
      std::string type, name;
      fields >> type;
      if (element == "vertex") {
        if (type == "list") return corrupt("list property in element vertex");
        fields >> name;
        vertex_properties.push_back(name);
      } else if (element == "range_grid") {
        std::string count_type, index_type;
        fields >> count_type >> index_type >> name;
        if (type != "list" || name != "vertex_indices") return corrupt("range_grid must be \"list ... vertex_indices\"");
      }
    }
  }
  const auto property_index = [&](const char* name) {
    return std::find(vertex_properties.begin(), vertex_properties.end(), name) - vertex_properties.begin();
  };
  const long x = property_index("x"), y = property_index("y"), z = property_index("z");
  const long num_properties = static_cast<long>(vertex_properties.size());
  if (x == num_properties || y == num_properties || z == num_properties) return corrupt("vertex without x y z");
  if (num_vertices < 0 || num_cells < 0) return corrupt("missing element vertex or range_grid");
  if (scan.rows <= 0 || scan.cols <= 0 || static_cast<long>(scan.rows) * scan.cols != num_cells) {
    return corrupt("range_grid has " + std::to_string(num_cells) + " cells, not num_rows x num_cols = " +
                   std::to_string(scan.rows) + " x " + std::to_string(scan.cols));
  }

  NumberReader body(std::string_view(*text).substr(header_end + std::string_view("end_header\n").size()));
  scan.positions.resize(static_cast<size_t>(num_vertices));
  std::vector<float> values(static_cast<size_t>(num_properties));
  for (Eigen::Vector3f& position : scan.positions) {
    for (float& value : values) {
      if (!body.Next(&value)) return corrupt("bad or missing vertex number");
    }
    position = Eigen::Vector3f(values[x], values[y], values[z]);
  }
  scan.grid.assign(static_cast<size_t>(num_cells), -1);
  for (int32_t& cell : scan.grid) {
    int count = 0;
    if (!body.Next(&count) || count < 0 || count > 1) return corrupt("range_grid cell without a count of 0 or 1");
    if (count == 1 && (!body.Next(&cell) || cell < 0 || cell >= num_vertices)) {
      return corrupt("range_grid vertex index missing or out of range");
    }
  }
  return scan;
}

// Area-weighted vertex normals of the grid triangulation (counter-clockwise as seen from +z of
// the scan, i.e. from the scanner); zero for vertices in no kept triangle.
std::vector<Eigen::Vector3f> GridNormals(const RangeScan& scan) {
  const auto cell = [&](int row, int col) { return scan.grid[static_cast<size_t>(row) * scan.cols + col]; };
  std::vector<float> spacings;
  for (int row = 0; row + 1 < scan.rows; ++row) {
    for (int col = 0; col + 1 < scan.cols; ++col) {
      const int32_t here = cell(row, col);
      if (here < 0) continue;
      for (const int32_t neighbour : {cell(row, col + 1), cell(row + 1, col)}) {
        if (neighbour >= 0) spacings.push_back((scan.positions[here] - scan.positions[neighbour]).norm());
      }
    }
  }
  std::vector<Eigen::Vector3f> normals(scan.positions.size(), Eigen::Vector3f::Zero());
  if (spacings.empty()) return normals;
  std::nth_element(spacings.begin(), spacings.begin() + spacings.size() / 2, spacings.end());
  const float max_edge = kMaxEdgeInGridSpacings * spacings[spacings.size() / 2];

  const auto add_triangle = [&](int32_t a, int32_t b, int32_t c) {
    if (a < 0 || b < 0 || c < 0) return;
    const Eigen::Vector3f& pa = scan.positions[a];
    const Eigen::Vector3f& pb = scan.positions[b];
    const Eigen::Vector3f& pc = scan.positions[c];
    if ((pa - pb).norm() > max_edge || (pb - pc).norm() > max_edge || (pc - pa).norm() > max_edge) return;
    const Eigen::Vector3f weighted = (pb - pa).cross(pc - pa);  // length = twice the area
    normals[a] += weighted;
    normals[b] += weighted;
    normals[c] += weighted;
  };
  for (int row = 0; row + 1 < scan.rows; ++row) {
    for (int col = 0; col + 1 < scan.cols; ++col) {
      // a b     row
      // c d     row + 1
      const int32_t a = cell(row, col), b = cell(row, col + 1), c = cell(row + 1, col), d = cell(row + 1, col + 1);
      const bool split_ad = a >= 0 && d >= 0 &&
                            (b < 0 || c < 0 ||
                             (scan.positions[a] - scan.positions[d]).squaredNorm() <
                                 (scan.positions[b] - scan.positions[c]).squaredNorm());
      if (split_ad) {
        add_triangle(a, d, c);
        add_triangle(a, b, d);
      } else {
        add_triangle(a, b, c);
        add_triangle(b, d, c);
      }
    }
  }
  return normals;
}

}  // namespace

Result<Mesh> LoadBunnyRangeScans(const std::string& range_scans_dir) {
  Result<std::vector<ScanPlacement>> placements = ReadBunConf(range_scans_dir + "/bun.conf");
  if (!placements.ok()) return placements.status();
  Mesh cloud;
  for (const ScanPlacement& placement : *placements) {
    Result<RangeScan> scan = ReadRangeScan(range_scans_dir + "/" + placement.file);
    if (!scan.ok()) return scan.status();
    const std::vector<Eigen::Vector3f> normals = GridNormals(*scan);
    const Eigen::Matrix3f aligned_from_scan = placement.rotation.toRotationMatrix().transpose();
    for (size_t i = 0; i < normals.size(); ++i) {
      const float length = normals[i].norm();
      if (!(length > 0.0f) || !std::isfinite(length)) continue;
      cloud.positions.push_back(aligned_from_scan * scan->positions[i] + placement.translation);
      cloud.normals.push_back(aligned_from_scan * (normals[i] / length));
    }
  }
  return cloud;
}

}  // namespace reconar::testing
