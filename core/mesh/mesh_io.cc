#include "core/mesh/mesh_io.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <string_view>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/base/number_format.h"
#include "core/mesh/byte_order.h"
#include "core/mesh/text_format.h"

namespace reconar {

namespace {

// ---------------------------------------------------------------------------------------------
// Header.

enum class PlyType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

bool ParseType(std::string_view name, PlyType* type) {
  struct Named {
    const char* name;
    PlyType type;
  };
  static constexpr Named kTypes[] = {
      {"char", PlyType::kInt8},     {"int8", PlyType::kInt8},       {"uchar", PlyType::kUint8},
      {"uint8", PlyType::kUint8},   {"short", PlyType::kInt16},     {"int16", PlyType::kInt16},
      {"ushort", PlyType::kUint16}, {"uint16", PlyType::kUint16},   {"int", PlyType::kInt32},
      {"int32", PlyType::kInt32},   {"uint", PlyType::kUint32},     {"uint32", PlyType::kUint32},
      {"float", PlyType::kFloat32}, {"float32", PlyType::kFloat32}, {"double", PlyType::kFloat64},
      {"float64", PlyType::kFloat64},
  };
  for (const Named& named : kTypes) {
    if (name == named.name) {
      *type = named.type;
      return true;
    }
  }
  return false;
}

size_t TypeSize(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
    case PlyType::kUint8: return 1;
    case PlyType::kInt16:
    case PlyType::kUint16: return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32: return 4;
    case PlyType::kFloat64: return 8;
  }
  return 0;
}

bool IsFloatType(PlyType type) { return type == PlyType::kFloat32 || type == PlyType::kFloat64; }

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;  // for a list: the type of its items
  bool is_list = false;
  PlyType count_type = PlyType::kUint8;
};

struct PlyElement {
  std::string name;
  int64_t count = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyEncoding { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::kAscii;
  std::vector<PlyElement> elements;
  size_t body_offset = 0;
};

Result<PlyHeader> ParseHeader(std::string_view bytes, const std::string& path) {
  PlyHeader header;
  size_t position = 0;
  int line_number = 0;
  bool format_seen = false;
  const auto error = [&](const std::string& reason) {
    return FileError(StatusCode::kCorruptData, path, "PLY header line " + std::to_string(line_number) + ": " + reason);
  };
  while (true) {
    const size_t end = bytes.find('\n', position);
    if (end == std::string_view::npos) {
      return FileError(StatusCode::kCorruptData, path,
                       line_number == 0 ? "empty file, not a PLY file" : "PLY header has no end_header line");
    }
    const std::string_view line = bytes.substr(position, end - position);
    position = end + 1;
    ++line_number;
    const std::vector<std::string_view> fields = SplitFields(line);
    if (line_number == 1) {
      if (fields.size() != 1 || fields[0] != "ply") {
        return FileError(StatusCode::kCorruptData, path, "not a PLY file (no \"ply\" magic line)");
      }
      continue;
    }
    if (fields.empty()) continue;
    const std::string_view keyword = fields[0];
    if (keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "end_header") break;
    if (keyword == "format") {
      if (fields.size() != 3) return error("expected 'format <encoding> 1.0'");
      if (fields[1] == "ascii") {
        header.encoding = PlyEncoding::kAscii;
      } else if (fields[1] == "binary_little_endian") {
        header.encoding = PlyEncoding::kBinaryLittleEndian;
      } else if (fields[1] == "binary_big_endian") {
        header.encoding = PlyEncoding::kBinaryBigEndian;
      } else {
        return error("unknown format '" + std::string(fields[1]) + "'");
      }
      if (fields[2] != "1.0") return error("unsupported version '" + std::string(fields[2]) + "'");
      format_seen = true;
    } else if (keyword == "element") {
      if (fields.size() != 3) return error("expected 'element <name> <count>'");
      PlyElement element;
      element.name = std::string(fields[1]);
      const auto parsed = std::from_chars(fields[2].data(), fields[2].data() + fields[2].size(), element.count);
      if (parsed.ec != std::errc() || parsed.ptr != fields[2].data() + fields[2].size() || element.count < 0) {
        return error("bad element count '" + std::string(fields[2]) + "'");
      }
      header.elements.push_back(std::move(element));
    } else if (keyword == "property") {
      if (header.elements.empty()) return error("property before any element");
      PlyProperty property;
      if (fields.size() == 5 && fields[1] == "list") {
        property.is_list = true;
        if (!ParseType(fields[2], &property.count_type) || IsFloatType(property.count_type)) {
          return error("bad list count type '" + std::string(fields[2]) + "'");
        }
        if (!ParseType(fields[3], &property.type)) return error("unknown type '" + std::string(fields[3]) + "'");
        property.name = std::string(fields[4]);
      } else if (fields.size() == 3) {
        if (!ParseType(fields[1], &property.type)) return error("unknown type '" + std::string(fields[1]) + "'");
        property.name = std::string(fields[2]);
      } else {
        return error("expected 'property <type> <name>' or 'property list <type> <type> <name>'");
      }
      header.elements.back().properties.push_back(std::move(property));
    } else {
      return error("unknown keyword '" + std::string(keyword) + "'");
    }
  }
  if (!format_seen) return FileError(StatusCode::kCorruptData, path, "PLY header has no format line");
  header.body_offset = position;
  return header;
}

// ---------------------------------------------------------------------------------------------
// Body values.

enum class ReadOutcome { kOk, kEnd, kMalformed };

// Reads scalar values one at a time from an ascii or binary body, as doubles (exact for every PLY
// type). ASCII tokens are separated by any white space; line structure is not enforced.
class PlyValueReader {
 public:
  PlyValueReader(std::string_view body, PlyEncoding encoding)
      : body_(body),
        encoding_(encoding),
        swap_(encoding != PlyEncoding::kAscii &&
              (encoding == PlyEncoding::kBinaryLittleEndian) != mesh_internal::HostIsLittleEndian()) {}

  ReadOutcome Read(PlyType type, double* value) {
    return encoding_ == PlyEncoding::kAscii ? ReadAscii(type, value) : ReadBinary(type, value);
  }

  size_t remaining() const { return body_.size() - position_; }
  // The ASCII token that failed to parse (for messages).
  std::string_view last_token() const { return last_token_; }

 private:
  ReadOutcome ReadAscii(PlyType type, double* value) {
    while (position_ < body_.size() && IsSpace(body_[position_])) ++position_;
    if (position_ >= body_.size()) return ReadOutcome::kEnd;
    size_t end = position_;
    while (end < body_.size() && !IsSpace(body_[end])) ++end;
    const char* first = body_.data() + position_;
    const char* last = body_.data() + end;
    last_token_ = std::string_view(first, end - position_);
    position_ = end;
    if (*first == '+' && last - first > 1 && first[1] != '-') ++first;  // from_chars takes no '+'
    if (type == PlyType::kFloat32) {
      float parsed = 0.0f;  // parsed as float directly, so the shortest float text is exact
      const auto result = std::from_chars(first, last, parsed);
      if (result.ec != std::errc() || result.ptr != last) return ReadOutcome::kMalformed;
      *value = parsed;
      return ReadOutcome::kOk;
    }
    if (type == PlyType::kFloat64) {
      const auto result = std::from_chars(first, last, *value);
      return result.ec == std::errc() && result.ptr == last ? ReadOutcome::kOk : ReadOutcome::kMalformed;
    }
    int64_t parsed = 0;
    const auto result = std::from_chars(first, last, parsed);
    if (result.ec != std::errc() || result.ptr != last || !InRange(type, parsed)) return ReadOutcome::kMalformed;
    *value = static_cast<double>(parsed);
    return ReadOutcome::kOk;
  }

  ReadOutcome ReadBinary(PlyType type, double* value) {
    const size_t size = TypeSize(type);
    if (remaining() < size) return ReadOutcome::kEnd;
    const char* data = body_.data() + position_;
    position_ += size;
    switch (type) {
      case PlyType::kInt8: *value = Load<int8_t>(data); break;
      case PlyType::kUint8: *value = Load<uint8_t>(data); break;
      case PlyType::kInt16: *value = Load<int16_t>(data); break;
      case PlyType::kUint16: *value = Load<uint16_t>(data); break;
      case PlyType::kInt32: *value = Load<int32_t>(data); break;
      case PlyType::kUint32: *value = Load<uint32_t>(data); break;
      case PlyType::kFloat32: *value = Load<float>(data); break;
      case PlyType::kFloat64: *value = Load<double>(data); break;
    }
    return ReadOutcome::kOk;
  }

  template <typename T>
  T Load(const char* data) const {
    return mesh_internal::LoadBytes<T>(data, swap_);
  }

  static bool IsSpace(char c) { return c == ' ' || c == '\n' || c == '\r' || c == '\t'; }

  static bool InRange(PlyType type, int64_t v) {
    switch (type) {
      case PlyType::kInt8: return v >= -128 && v <= 127;
      case PlyType::kUint8: return v >= 0 && v <= 255;
      case PlyType::kInt16: return v >= -32768 && v <= 32767;
      case PlyType::kUint16: return v >= 0 && v <= 65535;
      case PlyType::kInt32: return v >= std::numeric_limits<int32_t>::min() && v <= std::numeric_limits<int32_t>::max();
      case PlyType::kUint32: return v >= 0 && v <= std::numeric_limits<uint32_t>::max();
      default: return true;
    }
  }

  std::string_view body_;
  size_t position_ = 0;
  PlyEncoding encoding_;
  bool swap_;
  std::string_view last_token_;
};

// ---------------------------------------------------------------------------------------------
// Elements.

// What a vertex property feeds.
enum class VertexRole { kSkip, kX, kY, kZ, kNx, kNy, kNz, kRed, kGreen, kBlue, kAlpha };

VertexRole RoleOf(const std::string& name) {
  static constexpr std::pair<const char*, VertexRole> kRoles[] = {
      {"x", VertexRole::kX},       {"y", VertexRole::kY},         {"z", VertexRole::kZ},
      {"nx", VertexRole::kNx},     {"ny", VertexRole::kNy},       {"nz", VertexRole::kNz},
      {"red", VertexRole::kRed},   {"green", VertexRole::kGreen}, {"blue", VertexRole::kBlue},
      {"alpha", VertexRole::kAlpha},
  };
  for (const auto& [role_name, role] : kRoles) {
    if (name == role_name) return role;
  }
  return VertexRole::kSkip;
}

class PlyBodyParser {
 public:
  PlyBodyParser(const std::string& path, const PlyHeader& header, std::string_view body)
      : path_(path), header_(header), reader_(body, header.encoding) {}

  Result<Mesh> Parse() {
    const PlyElement* vertex = nullptr;
    for (const PlyElement& element : header_.elements) {
      if (element.name == "vertex" && vertex == nullptr) vertex = &element;
    }
    if (vertex == nullptr) return Error("PLY file has no vertex element");
    if (vertex->count > std::numeric_limits<uint32_t>::max()) {
      return FileError(StatusCode::kUnsupported, path_, std::to_string(vertex->count) + " vertices (at most 2^32-1)");
    }
    num_vertices_ = vertex->count;
    RECONAR_RETURN_IF_ERROR(PlanVertices(*vertex));

    bool faces_read = false;
    for (const PlyElement& element : header_.elements) {
      RECONAR_RETURN_IF_ERROR(CheckCountFits(element));
      if (&element == vertex) {
        RECONAR_RETURN_IF_ERROR(ReadVertices(element));
      } else if (element.name == "face" && !faces_read) {
        RECONAR_RETURN_IF_ERROR(ReadFaces(element));
        faces_read = true;
      } else {
        RECONAR_RETURN_IF_ERROR(SkipElement(element));
      }
    }
    return std::move(mesh_);
  }

 private:
  Status Error(const std::string& reason) const { return FileError(StatusCode::kCorruptData, path_, reason); }

  // A header that declares more rows than the remaining bytes could hold is truncated; checked
  // before any memory is reserved for the rows.
  Status CheckCountFits(const PlyElement& element) const {
    const bool ascii = header_.encoding == PlyEncoding::kAscii;
    size_t min_row_bytes = 0;
    for (const PlyProperty& property : element.properties) {
      min_row_bytes += ascii ? 2 : TypeSize(property.is_list ? property.count_type : property.type);
    }
    if (min_row_bytes == 0 || element.count == 0) return Status::Ok();
    const uint64_t max_rows = (reader_.remaining() + (ascii ? 1 : 0)) / min_row_bytes;
    if (static_cast<uint64_t>(element.count) > max_rows) {
      return Error("truncated: the header declares " + std::to_string(element.count) + " " + element.name +
                   " elements but only " + std::to_string(reader_.remaining()) + " bytes of data follow");
    }
    return Status::Ok();
  }

  Status PlanVertices(const PlyElement& vertex) {
    bool present[11] = {};
    for (const PlyProperty& property : vertex.properties) {
      const VertexRole role = RoleOf(property.name);
      roles_.push_back(role);
      if (role == VertexRole::kSkip) continue;
      if (property.is_list) {
        return FileError(StatusCode::kUnsupported, path_, "vertex property '" + property.name + "' is a list");
      }
      const bool is_colour = role >= VertexRole::kRed;
      if (is_colour && property.type != PlyType::kUint8 && !IsFloatType(property.type)) {
        return FileError(StatusCode::kUnsupported, path_,
                         "vertex colour '" + property.name + "' must be uchar or float/double");
      }
      present[static_cast<int>(role)] = true;
    }
    const auto has = [&](VertexRole role) { return present[static_cast<int>(role)]; };
    if (!has(VertexRole::kX) || !has(VertexRole::kY) || !has(VertexRole::kZ)) {
      return Error("vertex element lacks x, y or z");
    }
    has_normals_ = has(VertexRole::kNx) && has(VertexRole::kNy) && has(VertexRole::kNz);
    has_colors_ = has(VertexRole::kRed) && has(VertexRole::kGreen) && has(VertexRole::kBlue);
    return Status::Ok();
  }

  Status ValueError(ReadOutcome outcome, const std::string& where) const {
    if (outcome == ReadOutcome::kEnd) return Error("truncated data at " + where);
    return Error("malformed value '" + std::string(reader_.last_token()) + "' at " + where);
  }

  static uint8_t ColourByte(PlyType type, double value) {
    if (type == PlyType::kUint8) return static_cast<uint8_t>(value);
    if (!(value > 0.0)) return 0;  // also NaN
    if (value >= 1.0) return 255;
    return static_cast<uint8_t>(std::lround(value * 255.0));
  }

  Status ReadVertices(const PlyElement& element) {
    const size_t count = static_cast<size_t>(element.count);
    mesh_.positions.resize(count);
    if (has_normals_) mesh_.normals.resize(count);
    if (has_colors_) mesh_.colors.assign(count, {0, 0, 0, 255});
    for (size_t i = 0; i < count; ++i) {
      Eigen::Vector3f& position = mesh_.positions[i];
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        if (property.is_list) {
          RECONAR_RETURN_IF_ERROR(SkipList(property, "vertex " + std::to_string(i)));
          continue;
        }
        double value = 0.0;
        const ReadOutcome outcome = reader_.Read(property.type, &value);
        if (outcome != ReadOutcome::kOk) return ValueError(outcome, "vertex " + std::to_string(i));
        const VertexRole role = roles_[p];
        const bool is_position = role == VertexRole::kX || role == VertexRole::kY || role == VertexRole::kZ;
        // Also keeps the conversion to float defined; NaN fails the comparison.
        if (is_position && !(std::abs(value) <= std::numeric_limits<float>::max())) {
          return Error("vertex " + std::to_string(i) + ": " + property.name + " is not a finite float");
        }
        switch (role) {
          case VertexRole::kSkip: break;
          case VertexRole::kX: position.x() = static_cast<float>(value); break;
          case VertexRole::kY: position.y() = static_cast<float>(value); break;
          case VertexRole::kZ: position.z() = static_cast<float>(value); break;
          case VertexRole::kNx: if (has_normals_) mesh_.normals[i].x() = static_cast<float>(value); break;
          case VertexRole::kNy: if (has_normals_) mesh_.normals[i].y() = static_cast<float>(value); break;
          case VertexRole::kNz: if (has_normals_) mesh_.normals[i].z() = static_cast<float>(value); break;
          case VertexRole::kRed: if (has_colors_) mesh_.colors[i][0] = ColourByte(property.type, value); break;
          case VertexRole::kGreen: if (has_colors_) mesh_.colors[i][1] = ColourByte(property.type, value); break;
          case VertexRole::kBlue: if (has_colors_) mesh_.colors[i][2] = ColourByte(property.type, value); break;
          case VertexRole::kAlpha: if (has_colors_) mesh_.colors[i][3] = ColourByte(property.type, value); break;
        }
      }
    }
    return Status::Ok();
  }

  Status ReadFaces(const PlyElement& element) {
    int indices_property = -1;
    for (size_t p = 0; p < element.properties.size(); ++p) {
      const PlyProperty& property = element.properties[p];
      if (property.name == "vertex_indices" || property.name == "vertex_index") {
        if (!property.is_list || IsFloatType(property.type)) {
          return Error("face property '" + property.name + "' must be a list of integers");
        }
        indices_property = static_cast<int>(p);
        break;
      }
    }
    if (indices_property < 0) return Error("face element has no vertex_indices list");
    mesh_.triangles.reserve(static_cast<size_t>(element.count));
    for (int64_t f = 0; f < element.count; ++f) {
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        if (static_cast<int>(p) == indices_property) {
          RECONAR_RETURN_IF_ERROR(ReadPolygon(property, f));
        } else if (property.is_list) {
          RECONAR_RETURN_IF_ERROR(SkipList(property, "face " + std::to_string(f)));
        } else {
          double ignored;
          const ReadOutcome outcome = reader_.Read(property.type, &ignored);
          if (outcome != ReadOutcome::kOk) return ValueError(outcome, "face " + std::to_string(f));
        }
      }
    }
    return Status::Ok();
  }

  // Fan-triangulates one polygon (0, i, i+1) straight from the stream.
  Status ReadPolygon(const PlyProperty& property, int64_t face) {
    double count_value = 0.0;
    ReadOutcome outcome = reader_.Read(property.count_type, &count_value);
    if (outcome != ReadOutcome::kOk) return ValueError(outcome, "face " + std::to_string(face));
    if (count_value < 0) return Error("face " + std::to_string(face) + ": negative vertex count");
    const int64_t count = static_cast<int64_t>(count_value);
    uint32_t first = 0, previous = 0;
    for (int64_t k = 0; k < count; ++k) {
      double index = 0.0;
      outcome = reader_.Read(property.type, &index);
      if (outcome != ReadOutcome::kOk) return ValueError(outcome, "face " + std::to_string(face));
      if (index < 0 || index >= static_cast<double>(num_vertices_)) {
        return Error("face " + std::to_string(face) + ": vertex index " + std::to_string(static_cast<int64_t>(index)) +
                     " out of range [0, " + std::to_string(num_vertices_) + ")");
      }
      const uint32_t current = static_cast<uint32_t>(index);
      if (k == 0) first = current;
      if (k >= 2) mesh_.triangles.push_back({first, previous, current});
      previous = current;
    }
    return Status::Ok();
  }

  Status SkipList(const PlyProperty& property, const std::string& where) {
    double count = 0.0;
    ReadOutcome outcome = reader_.Read(property.count_type, &count);
    if (outcome != ReadOutcome::kOk) return ValueError(outcome, where);
    if (count < 0) return Error(where + ": negative list length");
    for (int64_t k = 0; k < static_cast<int64_t>(count); ++k) {
      double ignored;
      outcome = reader_.Read(property.type, &ignored);
      if (outcome != ReadOutcome::kOk) return ValueError(outcome, where);
    }
    return Status::Ok();
  }

  Status SkipElement(const PlyElement& element) {
    if (element.properties.empty()) return Status::Ok();  // rows of no bytes, however many
    for (int64_t i = 0; i < element.count; ++i) {
      const std::string where = element.name + " " + std::to_string(i);
      for (const PlyProperty& property : element.properties) {
        if (property.is_list) {
          RECONAR_RETURN_IF_ERROR(SkipList(property, where));
        } else {
          double ignored;
          const ReadOutcome outcome = reader_.Read(property.type, &ignored);
          if (outcome != ReadOutcome::kOk) return ValueError(outcome, where);
        }
      }
    }
    return Status::Ok();
  }

  const std::string& path_;
  const PlyHeader& header_;
  PlyValueReader reader_;
  int64_t num_vertices_ = 0;
  std::vector<VertexRole> roles_;  // per vertex property
  bool has_normals_ = false;
  bool has_colors_ = false;
  Mesh mesh_;
};

// ---------------------------------------------------------------------------------------------
// Writing.

std::string PlyHeaderText(const Mesh& mesh, PlyFormat format) {
  std::string header = "ply\nformat ";
  header += format == PlyFormat::kAscii ? "ascii" : "binary_little_endian";
  header += " 1.0\ncomment reconar\nelement vertex " + std::to_string(mesh.positions.size()) +
            "\nproperty float x\nproperty float y\nproperty float z\n";
  if (!mesh.normals.empty()) header += "property float nx\nproperty float ny\nproperty float nz\n";
  if (!mesh.colors.empty()) {
    header += "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n";
  }
  if (!mesh.triangles.empty()) {
    header += "element face " + std::to_string(mesh.triangles.size()) + "\nproperty list uchar int vertex_indices\n";
  }
  return header + "end_header\n";
}

void AppendBinaryBody(const Mesh& mesh, std::string* out) {
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    for (int axis = 0; axis < 3; ++axis) mesh_internal::AppendLittleEndian(out, mesh.positions[i][axis]);
    if (!mesh.normals.empty()) {
      for (int axis = 0; axis < 3; ++axis) mesh_internal::AppendLittleEndian(out, mesh.normals[i][axis]);
    }
    if (!mesh.colors.empty()) out->append(reinterpret_cast<const char*>(mesh.colors[i].data()), 4);
  }
  for (const std::array<uint32_t, 3>& triangle : mesh.triangles) {
    out->push_back(3);
    for (const uint32_t index : triangle) {
      mesh_internal::AppendLittleEndian(out, static_cast<int32_t>(index));
    }
  }
}

void AppendAsciiBody(const Mesh& mesh, std::string* out) {
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    for (int axis = 0; axis < 3; ++axis) {
      if (axis > 0) out->push_back(' ');
      AppendShortest(out, mesh.positions[i][axis]);
    }
    if (!mesh.normals.empty()) {
      for (int axis = 0; axis < 3; ++axis) {
        out->push_back(' ');
        AppendShortest(out, mesh.normals[i][axis]);
      }
    }
    if (!mesh.colors.empty()) {
      for (const uint8_t c : mesh.colors[i]) *out += ' ' + std::to_string(c);
    }
    out->push_back('\n');
  }
  for (const std::array<uint32_t, 3>& triangle : mesh.triangles) {
    *out += "3 " + std::to_string(triangle[0]) + ' ' + std::to_string(triangle[1]) + ' ' +
            std::to_string(triangle[2]) + '\n';
  }
}

}  // namespace

Result<Mesh> ReadPly(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(const std::string bytes, ReadFileToString(path));
  RECONAR_ASSIGN_OR_RETURN(const PlyHeader header, ParseHeader(bytes, path));
  PlyBodyParser parser(path, header, std::string_view(bytes).substr(header.body_offset));
  return parser.Parse();
}

Status WritePly(const std::string& path, const Mesh& mesh, PlyFormat format) {
  const Status valid = ValidateMesh(mesh);
  if (!valid.ok()) return valid.WithContext(path);
  if (mesh.positions.size() > static_cast<size_t>(std::numeric_limits<int32_t>::max())) {
    return FileError(StatusCode::kInvalidArgument, path, "more vertices than PLY 'int' indices can address");
  }
  std::string content = PlyHeaderText(mesh, format);
  if (format == PlyFormat::kAscii) {
    AppendAsciiBody(mesh, &content);
  } else {
    const size_t vertex_bytes = 12 + (mesh.normals.empty() ? 0 : 12) + (mesh.colors.empty() ? 0 : 4);
    content.reserve(content.size() + vertex_bytes * mesh.positions.size() + 13 * mesh.triangles.size());
    AppendBinaryBody(mesh, &content);
  }
  return WriteFileAtomically(path, content);
}

}  // namespace reconar
