#include "core/mesh/mesh_conversion.h"

#include <algorithm>
#include <chrono>
#include <filesystem>

#include "core/base/atomic_file.h"
#include "core/mesh/glb_io.h"
#include "core/mesh/obj_io.h"

namespace reconar {
namespace {

double SecondsBetween(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

}  // namespace

Result<MeshConversionReport> ConvertMeshFile(const std::string& input, const std::string& output,
                                             const MeshConversionOptions& options) {
  RECONAR_ASSIGN_OR_RETURN(const MeshFileFormat input_format, ReadableMeshFileFormatOf(input));
  RECONAR_ASSIGN_OR_RETURN(const MeshFileFormat output_format, MeshFileFormatOf(output));
  if (options.file.ply_ascii && output_format != MeshFileFormat::kPly) {
    return InvalidArgument(output + ": --ascii applies only to .ply output");
  }
  MeshConversionReport report;
  const auto start = std::chrono::steady_clock::now();
  Mesh mesh;
  std::vector<EncodedTexturePage> texture_pngs;
  if (input_format == MeshFileFormat::kGlb) {
    RECONAR_ASSIGN_OR_RETURN(TexturedGlb textured, ReadTexturedGlb(input));
    mesh = std::move(textured.mesh);
    if (!textured.pages.empty() && std::all_of(textured.pages.begin(), textured.pages.end(), [](const auto& page) {
          return IsPngSignature(page.image);
        })) {
      texture_pngs = std::move(textured.pages);
    } else {
      mesh.texcoords.clear();  // a JPEG texture (another tool's) is not carried over
    }
  } else {
    RECONAR_ASSIGN_OR_RETURN(mesh, ReadMeshFile(input));
  }
  const auto read = std::chrono::steady_clock::now();
  report.seconds_read = SecondsBetween(start, read);
  report.vertices_read = mesh.positions.size();
  report.triangles_read = mesh.triangles.size();
  report.textured = !texture_pngs.empty();
  if (report.textured && options.max_faces > 0 && mesh.triangles.size() > options.max_faces) {
    return FileError(StatusCode::kInvalidArgument, input,
                     "a textured model is not simplified (its texture charts would tear): export it without "
                     "--max-faces, or texture the project again with `reconar texture PROJECT --max-faces N`");
  }
  Result<SimplifyReport> simplified = SimplifyToFaceBudget(options.max_faces, &mesh);
  if (!simplified.ok()) return simplified.status().WithContext(input);
  report.simplify = *simplified;
  const auto write = std::chrono::steady_clock::now();
  const std::string parent = std::filesystem::path(output).parent_path().string();
  if (!parent.empty()) RECONAR_RETURN_IF_ERROR(CreateDirectories(parent));
  if (report.textured && output_format == MeshFileFormat::kGlb) {
    RECONAR_RETURN_IF_ERROR(WriteTexturedGlb(output, mesh, texture_pngs));
  } else if (report.textured && output_format == MeshFileFormat::kObj) {
    // The texture's pages beside the OBJ, named after it, as its material library names them.
    const std::filesystem::path obj(output);
    std::vector<ObjTextureFile> page_files;
    for (size_t k = 0; k < texture_pngs.size(); ++k) {
      const std::string name = obj.stem().string() + (k == 0 ? "" : "_" + std::to_string(k)) + ".png";
      report.texture_paths.push_back((obj.parent_path() / name).string());
      RECONAR_RETURN_IF_ERROR(WriteFileAtomically(report.texture_paths.back(), texture_pngs[k].image));
      page_files.push_back({texture_pngs[k].first_triangle, name});
    }
    RECONAR_RETURN_IF_ERROR(WriteTexturedObj(output, mesh, page_files));
  } else {
    report.texture_dropped = report.textured;
    mesh.texcoords.clear();
    RECONAR_RETURN_IF_ERROR(WriteMeshFile(output, mesh, options.file));
  }
  report.seconds_write = SecondsBetween(write, std::chrono::steady_clock::now());
  report.vertices = mesh.positions.size();
  report.triangles = mesh.triangles.size();
  report.normals = !mesh.normals.empty();
  report.colors = !mesh.colors.empty();
  std::error_code error;
  const uintmax_t bytes = std::filesystem::file_size(output, error);
  report.bytes = error ? 0 : bytes;
  return report;
}

}  // namespace reconar
