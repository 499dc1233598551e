#include "core/compare/design.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>

#include "core/base/atomic_file.h"
#include "core/mesh/glb_io.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/obj_io.h"

namespace reconar {

Result<Design> ReadDesign(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
  Design design;
  if (extension == ".glb" || extension == ".gltf") {
    RECONAR_ASSIGN_OR_RETURN(design.elements, ReadGltfScene(path));
  } else if (extension == ".obj") {
    RECONAR_ASSIGN_OR_RETURN(design.elements, ReadObjGroups(path));
  } else if (extension == ".ply") {
    RECONAR_ASSIGN_OR_RETURN(Mesh mesh, ReadPly(path));
    design.elements.push_back({std::filesystem::path(path).stem().string(), std::move(mesh)});
  } else {
    return InvalidArgument(path + ": a design is read from .glb, .gltf, .obj or .ply, not '" + extension + "'");
  }
  design.elements.erase(std::remove_if(design.elements.begin(), design.elements.end(),
                                       [](const NamedMesh& element) { return element.mesh.triangles.empty(); }),
                        design.elements.end());
  if (design.elements.empty()) return FileError(StatusCode::kCorruptData, path, "no element of the design has a triangle");
  for (const NamedMesh& element : design.elements) {
    for (const std::array<uint32_t, 3>& triangle : element.mesh.triangles) {
      for (const uint32_t v : triangle) {
        if (v >= element.mesh.positions.size() || !element.mesh.positions[v].allFinite()) {
          return FileError(StatusCode::kCorruptData, path,
                           "element '" + element.name + "': vertex " + std::to_string(v) +
                               (v >= element.mesh.positions.size() ? " does not exist" : " is not a finite point"));
        }
      }
    }
  }
  return design;
}

Result<std::vector<ControlTag>> ParseControl(const std::string& text, const std::string& name_for_errors) {
  std::vector<ControlTag> tags;
  std::set<int> ids;
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  while (std::getline(lines, line)) {
    ++number;
    const size_t comment = line.find('#');
    if (comment != std::string::npos) line.resize(comment);
    std::istringstream fields(line);
    std::vector<std::string> words;
    for (std::string word; fields >> word;) words.push_back(word);
    if (words.empty()) continue;
    const auto error = [&](const std::string& reason) {
      return FileError(StatusCode::kCorruptData, name_for_errors, "line " + std::to_string(number) + ": " + reason);
    };
    const bool picked = words[0] == "point";
    if (picked ? words.size() != 7 : words.size() != 4 && words.size() != 13) {
      return error(picked ? "expected 'point' and 6 coordinates (design X Y Z, then world X Y Z), got " +
                                std::to_string(words.size() - 1)
                          : "expected 'ID X Y Z' (the tag's centre), 'ID' and its 4 corners' 12 coordinates, or "
                            "'point' and a picked point's design and world coordinates, got " +
                                std::to_string(words.size()) + " fields");
    }
    ControlTag tag;
    tag.line = number;
    char* end = nullptr;
    if (!picked) {
      const long id = std::strtol(words[0].c_str(), &end, 10);
      if (*end != '\0' || id < 0 || id > 1000000) return error("bad tag id '" + words[0] + "'");
      tag.id = static_cast<int>(id);
      if (!ids.insert(tag.id).second) return error("tag " + words[0] + " given twice");
    }
    std::vector<Eigen::Vector3d> points;
    for (size_t k = 1; k + 2 < words.size(); k += 3) {
      Eigen::Vector3d point;
      for (int c = 0; c < 3; ++c) {
        const std::string& word = words[k + static_cast<size_t>(c)];
        point[c] = std::strtod(word.c_str(), &end);
        if (*end != '\0' || !std::isfinite(point[c])) return error("bad coordinate '" + word + "'");
      }
      points.push_back(point);
    }
    if (picked) {
      tag.design_points = {points[0]};
      tag.world_point = points[1];
    } else {
      tag.design_points = points;
    }
    tags.push_back(tag);
  }
  if (tags.empty()) return FileError(StatusCode::kCorruptData, name_for_errors, "no control tag or point");
  return tags;
}

Result<std::vector<ControlTag>> ReadControlFile(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
  return ParseControl(text, path);
}

}  // namespace reconar
