#include "core/mesh/mesh_file.h"

#include <cctype>
#include <filesystem>

#include "core/mesh/glb_io.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/obj_io.h"
#include "core/mesh/vrml_io.h"

namespace reconar {

namespace {

std::string LowercaseExtensionOf(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension;
}

}  // namespace

Result<MeshFileFormat> MeshFileFormatOf(const std::string& path) {
  const std::string extension = LowercaseExtensionOf(path);
  if (extension == ".ply") return MeshFileFormat::kPly;
  if (extension == ".obj") return MeshFileFormat::kObj;
  if (extension == ".glb") return MeshFileFormat::kGlb;
  if (extension == ".wrl") return MeshFileFormat::kVrml;
  return FileError(StatusCode::kUnsupported, path,
                   (extension.empty() ? std::string("no file extension") : "unknown mesh extension '" + extension + "'") +
                       " (expected .ply, .obj, .glb or .wrl)");
}

Result<MeshFileFormat> ReadableMeshFileFormatOf(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(const MeshFileFormat format, MeshFileFormatOf(path));
  if (format == MeshFileFormat::kVrml) {
    return FileError(StatusCode::kUnsupported, path, "reading VRML is not supported (read .ply, .obj or .glb)");
  }
  return format;
}

Status WriteMeshFile(const std::string& path, const Mesh& mesh, const MeshFileOptions& options) {
  RECONAR_ASSIGN_OR_RETURN(const MeshFileFormat format, MeshFileFormatOf(path));
  switch (format) {
    case MeshFileFormat::kPly:
      return WritePly(path, mesh, options.ply_ascii ? PlyFormat::kAscii : PlyFormat::kBinaryLittleEndian);
    case MeshFileFormat::kObj: return WriteObj(path, mesh);
    case MeshFileFormat::kGlb: return WriteGlb(path, mesh);
    case MeshFileFormat::kVrml: return WriteVrml(path, mesh);
  }
  return Internal("WriteMeshFile: unhandled format");
}

Result<Mesh> ReadMeshFile(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(const MeshFileFormat format, ReadableMeshFileFormatOf(path));
  switch (format) {
    case MeshFileFormat::kPly: return ReadPly(path);
    case MeshFileFormat::kObj: return ReadObj(path);
    case MeshFileFormat::kGlb: return ReadGlb(path);
    case MeshFileFormat::kVrml: break;
  }
  return Internal("ReadMeshFile: unhandled format");
}

}  // namespace reconar
