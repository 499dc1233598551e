#include "core/mesh/mesh_conversion.h"

#include <chrono>
#include <filesystem>

#include "core/base/atomic_file.h"

namespace reconar {
namespace {

double SecondsBetween(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

}  // namespace

Result<MeshConversionReport> ConvertMeshFile(const std::string& input, const std::string& output,
                                             const MeshConversionOptions& options) {
  RECONAR_RETURN_IF_ERROR(ReadableMeshFileFormatOf(input).status());
  RECONAR_ASSIGN_OR_RETURN(const MeshFileFormat output_format, MeshFileFormatOf(output));
  if (options.file.ply_ascii && output_format != MeshFileFormat::kPly) {
    return InvalidArgument(output + ": --ascii applies only to .ply output");
  }
  MeshConversionReport report;
  const auto start = std::chrono::steady_clock::now();
  RECONAR_ASSIGN_OR_RETURN(Mesh mesh, ReadMeshFile(input));
  const auto read = std::chrono::steady_clock::now();
  report.seconds_read = SecondsBetween(start, read);
  report.vertices_read = mesh.positions.size();
  report.triangles_read = mesh.triangles.size();
  Result<SimplifyReport> simplified = SimplifyToFaceBudget(options.max_faces, &mesh);
  if (!simplified.ok()) return simplified.status().WithContext(input);
  report.simplify = *simplified;
  const auto write = std::chrono::steady_clock::now();
  const std::string parent = std::filesystem::path(output).parent_path().string();
  if (!parent.empty()) RECONAR_RETURN_IF_ERROR(CreateDirectories(parent));
  RECONAR_RETURN_IF_ERROR(WriteMeshFile(output, mesh, options.file));
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
