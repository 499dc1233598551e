#include "core/mesh/obj_io.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string_view>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/base/number_format.h"
#include "core/mesh/text_format.h"

namespace reconar {


namespace {

// ---------------------------------------------------------------------------------------------
// Writing.

void AppendIndex(std::string* out, uint64_t one_based) {
  char buffer[24];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), one_based);
  out->append(buffer, result.ptr);
}

// The material of texture page k in the library WriteTexturedObj writes.
std::string TextureMaterial(size_t page) { return page == 0 ? "texture" : "texture_" + std::to_string(page); }

// `material_library`: when not empty, the mesh's texcoords are written ("vt u 1-v") and the faces
// of page k use the library's material TextureMaterial(k).
std::string ObjText(const Mesh& mesh, const std::string& material_library = "",
                    const std::vector<ObjTextureFile>& pages = {}) {
  std::string out = "# reconar\n# " + std::to_string(mesh.positions.size()) + " vertices, " +
                    std::to_string(mesh.triangles.size()) + " triangles\n";
  const bool with_texcoords = !material_library.empty();
  if (with_texcoords) out += "mtllib " + material_library + "\n";
  const bool with_colours = !mesh.colors.empty();
  const bool with_normals = !mesh.normals.empty();
  out.reserve(out.size() + mesh.positions.size() * (with_colours ? 60 : 36) * (with_normals ? 2 : 1) +
              mesh.triangles.size() * (with_normals ? 40 : 24));
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    out += "v ";
    mesh_internal::AppendShortestText(&out, mesh.positions[i]);
    if (with_colours) {
      for (int channel = 0; channel < 3; ++channel) {
        out.push_back(' ');
        AppendShortest(&out, mesh_internal::ColourChannel(mesh.colors[i][channel]));
      }
    }
    out.push_back('\n');
  }
  for (const Eigen::Vector3f& normal : mesh.normals) {
    out += "vn ";
    mesh_internal::AppendShortestText(&out, normal);
    out.push_back('\n');
  }
  if (with_texcoords) {
    for (const Eigen::Vector2f& uv : mesh.texcoords) {
      out += "vt ";
      AppendShortest(&out, uv.x());
      out.push_back(' ');
      AppendShortest(&out, 1.0f - uv.y());  // OBJ's v runs up the image
      out.push_back('\n');
    }
  }
  size_t page = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    while (with_texcoords && page < pages.size() && pages[page].first_triangle == t) {
      out += "usemtl " + TextureMaterial(page++) + "\n";
    }
    const std::array<uint32_t, 3>& triangle = mesh.triangles[t];
    out.push_back('f');
    for (const uint32_t index : triangle) {
      out.push_back(' ');
      AppendIndex(&out, uint64_t{index} + 1);
      if (with_texcoords) {
        out.push_back('/');
        AppendIndex(&out, uint64_t{index} + 1);
        if (with_normals) out.push_back('/');
      } else if (with_normals) {
        out += "//";
      }
      if (with_normals) AppendIndex(&out, uint64_t{index} + 1);
    }
    out.push_back('\n');
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Reading.

bool ParseFloat(std::string_view text, float* value) {
  const char* first = text.data();
  const char* last = text.data() + text.size();
  if (last - first > 1 && *first == '+' && first[1] != '-') ++first;  // from_chars takes no '+'
  const auto result = std::from_chars(first, last, *value);  // as float, so shortest float text is exact
  // from_chars also reads "nan" and "inf", which are no coordinates.
  return result.ec == std::errc() && result.ptr == last && std::isfinite(*value);
}

bool ParseInt(std::string_view text, int64_t* value) {
  const char* first = text.data();
  const char* last = text.data() + text.size();
  if (last - first > 1 && *first == '+' && first[1] != '-') ++first;
  const auto result = std::from_chars(first, last, *value);
  return result.ec == std::errc() && result.ptr == last;
}

uint8_t ChannelByte(float channel) {
  if (!(channel > 0.0f)) return 0;  // also NaN
  if (channel >= 1.0f) return 255;
  return static_cast<uint8_t>(std::lround(channel * 255.0f));
}

// One face corner: 0-based vertex and normal indices, resolved once the whole file is read
// (positive indices may name vertices defined further down). kNoNormal when the corner names none.
struct Corner {
  int64_t vertex;
  int64_t normal;
  int line;
};
constexpr int64_t kNoNormal = -1;

class ObjParser {
 public:
  explicit ObjParser(const std::string& path) : path_(path) {}

  // Per triangle of the parsed mesh, its group; the groups' names.
  const std::vector<int>& triangle_groups() const { return triangle_group_; }
  const std::vector<std::string>& group_names() const { return group_names_; }

  Result<Mesh> Parse(std::string_view text) {
    size_t position = 0;
    while (position < text.size()) {
      size_t end = text.find('\n', position);
      if (end == std::string_view::npos) end = text.size();
      ++line_;
      RECONAR_RETURN_IF_ERROR(ParseLine(text.substr(position, end - position)));
      position = end + 1;
    }
    if (mesh_.positions.empty()) return FileError(StatusCode::kCorruptData, path_, "no vertex ('v') lines");
    RECONAR_RETURN_IF_ERROR(BuildTriangles());
    AssignNormals();
    if (num_coloured_ != mesh_.positions.size()) mesh_.colors.clear();
    return std::move(mesh_);
  }

 private:
  Status Error(const std::string& reason) const {
    return FileError(StatusCode::kCorruptData, path_, "OBJ line " + std::to_string(line_) + ": " + reason);
  }

  Status ParseLine(std::string_view line) {
    const size_t comment = line.find('#');
    if (comment != std::string_view::npos) line = line.substr(0, comment);
    const std::vector<std::string_view> fields = SplitFields(line);
    if (fields.empty()) return Status::Ok();
    if (fields[0] == "v") return ParseVertex(fields);
    if (fields[0] == "vn") return ParseNormal(fields);
    if (fields[0] == "f") return ParseFace(fields);
    if (fields[0] == "g" || fields[0] == "o") return ParseGroup(line, fields);
    return Status::Ok();
  }

  Status ParseGroup(std::string_view line, const std::vector<std::string_view>& fields) {
    std::string name = "default";
    if (fields.size() > 1) {
      const size_t begin = static_cast<size_t>(fields[1].data() - line.data());
      const size_t end = static_cast<size_t>(fields.back().data() + fields.back().size() - line.data());
      name = std::string(line.substr(begin, end - begin));
    }
    const auto known = std::find(group_names_.begin(), group_names_.end(), name);
    group_ = static_cast<int>(known - group_names_.begin());
    if (known == group_names_.end()) group_names_.push_back(name);
    return Status::Ok();
  }

  Status ParseNumbers(const std::vector<std::string_view>& fields, float* values) const {
    for (size_t k = 1; k < fields.size(); ++k) {
      if (!ParseFloat(fields[k], &values[k - 1])) {
        return Error("malformed number '" + std::string(fields[k]) + "'");
      }
    }
    return Status::Ok();
  }

  Status ParseVertex(const std::vector<std::string_view>& fields) {
    const size_t count = fields.size() - 1;
    if (count != 3 && count != 4 && count != 6) {
      return Error("'v' needs 3, 4 (x y z w) or 6 (x y z r g b) numbers, got " + std::to_string(count));
    }
    float values[6];
    RECONAR_RETURN_IF_ERROR(ParseNumbers(fields, values));
    mesh_.positions.emplace_back(values[0], values[1], values[2]);
    if (count == 6) {
      mesh_.colors.resize(mesh_.positions.size(), {255, 255, 255, 255});
      mesh_.colors.back() = {ChannelByte(values[3]), ChannelByte(values[4]), ChannelByte(values[5]), 255};
      ++num_coloured_;
    }
    return Status::Ok();
  }

  Status ParseNormal(const std::vector<std::string_view>& fields) {
    if (fields.size() != 4) return Error("'vn' needs 3 numbers, got " + std::to_string(fields.size() - 1));
    float values[3];
    RECONAR_RETURN_IF_ERROR(ParseNumbers(fields, values));
    file_normals_.emplace_back(values[0], values[1], values[2]);
    return Status::Ok();
  }

  // A relative (negative) index counts back from the last element read so far.
  Result<int64_t> ResolveIndex(std::string_view text, size_t count_so_far, const char* what) const {
    int64_t index = 0;
    if (!ParseInt(text, &index) || index == 0) {
      return Error(std::string("bad ") + what + " index '" + std::string(text) + "'");
    }
    if (index > 0) return index - 1;
    const int64_t resolved = static_cast<int64_t>(count_so_far) + index;
    if (resolved < 0) {
      return Error(std::string("relative ") + what + " index " + std::to_string(index) + " before the first " + what);
    }
    return resolved;
  }

  Status ParseFace(const std::vector<std::string_view>& fields) {
    if (fields.size() < 4) return Error("a face needs at least 3 corners");
    const size_t first_corner = corners_.size();
    for (size_t k = 1; k < fields.size(); ++k) {
      const std::string_view corner = fields[k];
      const size_t slash = corner.find('/');
      Corner parsed{0, kNoNormal, line_};
      RECONAR_ASSIGN_OR_RETURN(parsed.vertex, ResolveIndex(corner.substr(0, slash), mesh_.positions.size(), "vertex"));
      if (slash != std::string_view::npos) {
        const size_t second_slash = corner.find('/', slash + 1);
        if (second_slash != std::string_view::npos) {
          RECONAR_ASSIGN_OR_RETURN(parsed.normal,
                                   ResolveIndex(corner.substr(second_slash + 1), file_normals_.size(), "normal"));
        }
      }
      corners_.push_back(parsed);
    }
    faces_.push_back({first_corner, corners_.size()});
    face_group_.push_back(group_);
    return Status::Ok();
  }

  Status BuildTriangles() {
    const int64_t num_vertices = static_cast<int64_t>(mesh_.positions.size());
    const int64_t num_normals = static_cast<int64_t>(file_normals_.size());
    for (const Corner& corner : corners_) {
      if (corner.vertex >= num_vertices) {
        return FileError(StatusCode::kCorruptData, path_,
                         "OBJ line " + std::to_string(corner.line) + ": vertex index " +
                             std::to_string(corner.vertex + 1) + " out of range [1, " + std::to_string(num_vertices) +
                             "]");
      }
      if (corner.normal >= num_normals) {
        return FileError(StatusCode::kCorruptData, path_,
                         "OBJ line " + std::to_string(corner.line) + ": normal index " +
                             std::to_string(corner.normal + 1) + " out of range [1, " + std::to_string(num_normals) +
                             "]");
      }
    }
    for (size_t f = 0; f < faces_.size(); ++f) {
      const auto& [begin, end] = faces_[f];
      for (size_t k = begin + 2; k < end; ++k) {
        mesh_.triangles.push_back({static_cast<uint32_t>(corners_[begin].vertex),
                                   static_cast<uint32_t>(corners_[k - 1].vertex),
                                   static_cast<uint32_t>(corners_[k].vertex)});
        triangle_group_.push_back(face_group_[f]);
      }
    }
    return Status::Ok();
  }

  void AssignNormals() {
    if (file_normals_.empty()) return;
    const size_t num_vertices = mesh_.positions.size();
    std::vector<int64_t> normal_of_vertex(num_vertices, kNoNormal);
    for (const Corner& corner : corners_) {
      if (corner.normal == kNoNormal) continue;
      int64_t& assigned = normal_of_vertex[static_cast<size_t>(corner.vertex)];
      if (assigned != kNoNormal && file_normals_[assigned] != file_normals_[corner.normal]) return;  // ambiguous
      assigned = corner.normal;
    }
    const bool aligned = file_normals_.size() == num_vertices;
    mesh_.normals.resize(num_vertices);
    for (size_t i = 0; i < num_vertices; ++i) {
      if (normal_of_vertex[i] == kNoNormal && !aligned) {
        mesh_.normals.clear();
        return;
      }
      mesh_.normals[i] = file_normals_[normal_of_vertex[i] != kNoNormal ? normal_of_vertex[i] : i];
    }
  }

  const std::string& path_;
  int line_ = 0;
  Mesh mesh_;
  std::vector<std::string> group_names_ = {"default"};
  int group_ = 0;                    // index into group_names_ of the faces now read
  std::vector<int> face_group_;      // per face
  std::vector<int> triangle_group_;  // per triangle of mesh_
  size_t num_coloured_ = 0;
  std::vector<Eigen::Vector3f> file_normals_;
  std::vector<Corner> corners_;
  std::vector<std::pair<size_t, size_t>> faces_;  // [begin, end) in corners_
};

}  // namespace

Status WriteObj(const std::string& path, const Mesh& mesh) {
  const Status valid = ValidateMesh(mesh);
  if (!valid.ok()) return valid.WithContext(path);
  RECONAR_RETURN_IF_ERROR(mesh_internal::CheckFiniteVertices(path, mesh));
  return WriteFileAtomically(path, ObjText(mesh));
}

Status WriteTexturedObj(const std::string& obj_path, const Mesh& mesh, const std::vector<ObjTextureFile>& pages) {
  const Status valid = ValidateMesh(mesh);
  if (!valid.ok()) return valid.WithContext(obj_path);
  RECONAR_RETURN_IF_ERROR(mesh_internal::CheckFiniteVertices(obj_path, mesh));
  if (mesh.texcoords.empty()) return FileError(StatusCode::kInvalidArgument, obj_path, "the mesh has no texcoords");
  const Status ordered = ValidateTexturePages(pages, mesh.triangles.size());
  if (!ordered.ok()) return ordered.WithContext(obj_path);
  const std::filesystem::path obj(obj_path);
  const std::string library = obj.stem().string() + ".mtl";
  const std::string library_path = (obj.parent_path() / library).string();
  // Ka, Kd white: the texture's colours unchanged; illum 1: no specular highlight.
  std::string materials = "# reconar\n";
  for (size_t k = 0; k < pages.size(); ++k) {
    materials += "newmtl " + TextureMaterial(k) + "\nKa 1 1 1\nKd 1 1 1\nKs 0 0 0\nillum 1\nmap_Kd " +
                 pages[k].file_name + "\n";
  }
  RECONAR_RETURN_IF_ERROR(WriteFileAtomically(library_path, materials));
  return WriteFileAtomically(obj_path, ObjText(mesh, library, pages));
}

Result<Mesh> ReadObj(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
  return ObjParser(path).Parse(text);
}

Result<std::vector<NamedMesh>> ReadObjGroups(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
  ObjParser parser(path);
  RECONAR_ASSIGN_OR_RETURN(const Mesh mesh, parser.Parse(text));
  if (mesh.triangles.empty()) return FileError(StatusCode::kCorruptData, path, "no faces ('f' lines)");
  const std::vector<std::string>& names = parser.group_names();
  std::vector<std::vector<size_t>> triangles_of(names.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    triangles_of[static_cast<size_t>(parser.triangle_groups()[t])].push_back(t);
  }
  std::vector<NamedMesh> groups;
  for (size_t g = 0; g < names.size(); ++g) {
    if (triangles_of[g].empty()) continue;
    groups.push_back({names[g], SubMesh(mesh, triangles_of[g])});
  }
  return groups;
}

}  // namespace reconar
