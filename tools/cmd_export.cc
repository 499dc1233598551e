// `reconar export`: converts a mesh or point cloud between the file formats of core/mesh/mesh_file.h.
#include <cstdio>
#include <string>

#include "core/base/json_writer.h"
#include "core/mesh/mesh_conversion.h"
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
    "A textured .glb (mesh/textured.glb of `reconar texture`) keeps its texture into .glb, and into\n"
    "  .obj with .mtl and the texture as OUTPUT's name with .png; .ply and .wrl drop it.\n"
    "  .wrl   VRML 2.0 IndexedFaceSet, or PointSet for a point cloud (write only)\n"
    "The output is written atomically; missing parent directories are created.\n"
    "  --max-faces N  simplify a mesh of more triangles to N (quadric edge collapse; borders and\n"
    "            colours kept): e.g. 500000 for a handheld\n"
    "  --ascii   write .ply as ASCII\n"
    "  --json    print a JSON summary on stdout\n";

}  // namespace

int RunExport(int argc, char** argv, int first) {
  Args args({"max-faces"}, {"ascii", "json"});
  if (const auto exit_code = ParseCommand(&args, argc, argv, first, kHelp, 2, 2)) return *exit_code;
  const std::string& input = args.positionals()[0];
  const std::string& output = args.positionals()[1];
  MeshConversionOptions options;
  options.file.ply_ascii = args.Has("ascii");
  auto max_faces = args.GetInt("max-faces", 0, 0, 1 << 30);
  if (!max_faces.ok()) return Fail(max_faces.status());
  options.max_faces = static_cast<size_t>(*max_faces);

  auto report = ConvertMeshFile(input, output, options);
  if (!report.ok()) return Fail(report.status());
  const MeshConversionReport& r = *report;
  if (args.Has("json")) {
    JsonWriter json(2);
    json.BeginObject();
    json.Key("input").String(input).Key("output").String(output);
    json.Key("vertices").Int(static_cast<long long>(r.vertices));
    json.Key("triangles").Int(static_cast<long long>(r.triangles));
    json.Key("triangles_read").Int(static_cast<long long>(r.triangles_read));
    json.Key("seconds_simplify").Double(r.simplify.seconds);
    json.Key("normals").Bool(r.normals).Key("colors").Bool(r.colors);
    json.Key("textured").Bool(r.textured && !r.texture_dropped);
    json.Key("bytes").Int(static_cast<long long>(r.bytes));
    json.Key("seconds_read").Double(r.seconds_read).Key("seconds_write").Double(r.seconds_write);
    json.EndObject();
    std::printf("%s\n", json.str().c_str());
    return 0;
  }
  std::printf("read %s: %zu vertices, %zu triangles%s%s\n", input.c_str(), r.vertices_read, r.triangles_read,
              r.normals ? ", normals" : "", r.colors ? ", colours" : "");
  if (r.simplify.collapses > 0) {
    std::printf("simplified to %zu vertices, %zu triangles (%.2fs)\n", r.vertices, r.triangles, r.simplify.seconds);
  }
  std::printf("wrote %s: %ju bytes (read %.2fs, write %.2fs)\n", output.c_str(), r.bytes, r.seconds_read,
              r.seconds_write);
  for (const std::string& path : r.texture_paths) std::printf("wrote %s: its texture\n", path.c_str());
  if (r.texture_dropped) std::printf("note: %s holds no texture; the texture was left out\n", output.c_str());
  return 0;
}

}  // namespace reconar::tools
