// `reconar export`: converts a mesh or point cloud between the file formats of core/mesh/mesh_file.h.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>

#include "core/base/atomic_file.h"
#include "core/base/json_writer.h"
#include "core/mesh/mesh_file.h"
#include "core/mesh/simplify.h"
#include "tools/args.h"
#include "tools/commands.h"

namespace reconar::tools {
namespace {

constexpr char kHelp[] =
    "usage: reconar export INPUT.{ply,glb,obj} OUTPUT.{ply,obj,glb,wrl} [--max-faces N] [--ascii] [--json]\n"
    "\n"
    "Converts a triangle mesh or point cloud (positions, per-vertex normals and RGBA colours) from\n"
    "one format to another; the extensions choose the formats (any case):\n"
    "  .ply   Stanford PLY, binary little-endian (ASCII with --ascii)\n"
    "  .obj   Wavefront OBJ, colours as 'v x y z r g b' (no alpha)\n"
    "  .glb   glTF 2.0 binary (normals must be unit length)\n"
    "  .wrl   VRML 2.0 IndexedFaceSet, or PointSet for a point cloud (write only)\n"
    "The output is written atomically; missing parent directories are created.\n"
    "  --max-faces N  simplify a mesh of more triangles to N (quadric edge collapse; borders and\n"
    "            colours kept): e.g. 500000 for a handheld\n"
    "  --ascii   write .ply as ASCII\n"
    "  --json    print a JSON summary on stdout\n";

}  // namespace

// The parent directory of `path` (created when missing) so that writing fails only for real reasons.
Status CreateParentDirectory(const std::string& path) {
  const std::string parent = std::filesystem::path(path).parent_path().string();
  return parent.empty() ? Status::Ok() : CreateDirectories(parent);
}

uintmax_t FileSize(const std::string& path) {
  std::error_code error;
  const uintmax_t size = std::filesystem::file_size(path, error);
  return error ? 0 : size;
}

void PrintMeshSummary(const char* verb, const std::string& path, const Mesh& mesh) {
  std::printf("%s %s: %zu vertices, %zu triangles%s%s\n", verb, path.c_str(), mesh.positions.size(),
              mesh.triangles.size(), mesh.normals.empty() ? "" : ", normals", mesh.colors.empty() ? "" : ", colours");
}

int RunExport(int argc, char** argv, int first) {
  Args args({"max-faces"}, {"ascii", "json"});
  if (const auto exit_code = ParseCommand(&args, argc, argv, first, kHelp, 2, 2)) return *exit_code;
  const std::string& input = args.positionals()[0];
  const std::string& output = args.positionals()[1];
  // Both extensions are checked before anything is read.
  if (auto format = ReadableMeshFileFormatOf(input); !format.ok()) return Fail(format.status());
  auto output_format = MeshFileFormatOf(output);
  if (!output_format.ok()) return Fail(output_format.status());
  MeshFileOptions options;
  options.ply_ascii = args.Has("ascii");
  if (options.ply_ascii && *output_format != MeshFileFormat::kPly) {
    return Fail(InvalidArgument(output + ": --ascii applies only to .ply output"));
  }
  auto max_faces = args.GetInt("max-faces", 0, 0, 1 << 30);
  if (!max_faces.ok()) return Fail(max_faces.status());

  const auto start = std::chrono::steady_clock::now();
  auto mesh = ReadMeshFile(input);
  if (!mesh.ok()) return Fail(mesh.status());
  const auto read = std::chrono::steady_clock::now();
  const size_t triangles_read = mesh->triangles.size();
  if (!args.Has("json")) PrintMeshSummary("read", input, *mesh);
  auto simplify_report = SimplifyToFaceBudget(static_cast<size_t>(*max_faces), &*mesh);
  if (!simplify_report.ok()) return Fail(simplify_report.status().WithContext(input));
  const SimplifyReport simplified = *simplify_report;
  if (Status s = CreateParentDirectory(output); !s.ok()) return Fail(s);
  if (Status s = WriteMeshFile(output, *mesh, options); !s.ok()) return Fail(s);
  const auto written = std::chrono::steady_clock::now();
  const auto seconds = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };

  if (args.Has("json")) {
    JsonWriter json(2);
    json.BeginObject();
    json.Key("input").String(input).Key("output").String(output);
    json.Key("vertices").Int(static_cast<long long>(mesh->positions.size()));
    json.Key("triangles").Int(static_cast<long long>(mesh->triangles.size()));
    json.Key("triangles_read").Int(static_cast<long long>(triangles_read));
    json.Key("seconds_simplify").Double(simplified.seconds);
    json.Key("normals").Bool(!mesh->normals.empty()).Key("colors").Bool(!mesh->colors.empty());
    json.Key("bytes").Int(static_cast<long long>(FileSize(output)));
    json.Key("seconds_read").Double(seconds(start, read)).Key("seconds_write").Double(seconds(read, written));
    json.EndObject();
    std::printf("%s\n", json.str().c_str());
  } else {
    if (simplified.collapses > 0) {
      std::printf("simplified to %zu vertices, %zu triangles (%.2fs)\n", mesh->positions.size(),
                  mesh->triangles.size(), simplified.seconds);
    }
    std::printf("wrote %s: %ju bytes (read %.2fs, write %.2fs)\n", output.c_str(), FileSize(output),
                seconds(start, read), seconds(read, written) - simplified.seconds);
  }
  return 0;
}

}  // namespace reconar::tools
