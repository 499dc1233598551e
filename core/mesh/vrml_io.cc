#include "core/mesh/vrml_io.h"

#include <charconv>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/base/number_format.h"
#include "core/mesh/text_format.h"

namespace reconar {

namespace {

// "<indent><name> [\n<indent>  v, ...\n<indent>]\n" with one triple per line.
void AppendVectorField(const std::string& indent, const char* name, const std::vector<Eigen::Vector3f>& values,
                       std::string* out) {
  *out += indent + name + " [\n";
  for (const Eigen::Vector3f& value : values) {
    *out += indent;
    *out += "  ";
    mesh_internal::AppendShortestText(out, value);
    *out += ",\n";
  }
  *out += indent + "]\n";
}

void AppendColorNode(const std::string& indent, const Mesh& mesh, std::string* out) {
  *out += indent + "color Color {\n" + indent + "  color [\n";
  for (const std::array<uint8_t, 4>& colour : mesh.colors) {
    *out += indent;
    *out += "    ";
    for (int channel = 0; channel < 3; ++channel) {
      if (channel > 0) out->push_back(' ');
      AppendShortest(out, mesh_internal::ColourChannel(colour[channel]));
    }
    *out += ",\n";
  }
  *out += indent + "  ]\n" + indent + "}\n";
}

void AppendCoordIndex(const std::string& indent, const Mesh& mesh, std::string* out) {
  *out += indent + "coordIndex [\n";
  char buffer[16];
  for (const std::array<uint32_t, 3>& triangle : mesh.triangles) {
    *out += indent;
    *out += " ";
    for (const uint32_t index : triangle) {
      out->push_back(' ');
      out->append(buffer, std::to_chars(buffer, buffer + sizeof(buffer), index).ptr);
      out->push_back(',');
    }
    *out += " -1,\n";
  }
  *out += indent + "]\n";
}

std::string VrmlText(const Mesh& mesh) {
  const bool points = mesh.is_point_cloud();
  std::string out = "#VRML V2.0 utf8\n# reconar: " + std::to_string(mesh.positions.size()) + " vertices, " +
                    std::to_string(mesh.triangles.size()) + " triangles\n";
  out.reserve(out.size() + 40 * mesh.positions.size() * (1 + !mesh.normals.empty() + !mesh.colors.empty()) +
              32 * mesh.triangles.size());
  out += "Shape {\n  appearance Appearance {\n";
  out += points ? "    material Material { emissiveColor 0.8 0.8 0.8 }\n"
                : "    material Material { diffuseColor 0.8 0.8 0.8 }\n";
  out += "  }\n";
  const std::string indent = "    ";
  if (points) {
    out += "  geometry PointSet {\n";
  } else {
    out += "  geometry IndexedFaceSet {\n";
    out += indent + "solid FALSE\n" + indent + "ccw TRUE\n";
    if (!mesh.colors.empty()) out += indent + "colorPerVertex TRUE\n";
    if (!mesh.normals.empty()) out += indent + "normalPerVertex TRUE\n";
  }
  out += indent + "coord Coordinate {\n";
  AppendVectorField(indent + "  ", "point", mesh.positions, &out);
  out += indent + "}\n";
  if (!mesh.colors.empty()) AppendColorNode(indent, mesh, &out);
  if (!points) {
    if (!mesh.normals.empty()) {
      out += indent + "normal Normal {\n";
      AppendVectorField(indent + "  ", "vector", mesh.normals, &out);
      out += indent + "}\n";
    }
    AppendCoordIndex(indent, mesh, &out);
  }
  out += "  }\n}\n";
  return out;
}

}  // namespace

Status WriteVrml(const std::string& path, const Mesh& mesh) {
  const Status valid = ValidateMesh(mesh);
  if (!valid.ok()) return valid.WithContext(path);
  RECONAR_RETURN_IF_ERROR(mesh_internal::CheckFiniteVertices(path, mesh));
  return WriteFileAtomically(path, VrmlText(mesh));
}

}  // namespace reconar
