// evaluate_mesh: distances between a mesh's surface and a reference surface, both ways
// (tests/support/mesh_distance.h CompareMeshes), in millimetres for meshes in metres.
//
//   evaluate_mesh MESH.ply REFERENCE.ply [--samples N] [--seed S] [--threads T]
//
// Prints one line per direction: "mesh->reference mean M median D rms R p90 P max X (mm)" and
// "reference->mesh ...". Exit codes: 0 ok, 1 a mesh has no surface, 2 bad usage or input.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/mesh/mesh_io.h"
#include "tests/support/mesh_distance.h"

namespace reconar {
namespace {

int Usage(const std::string& message) {
  if (!message.empty()) std::fprintf(stderr, "evaluate_mesh: %s\n", message.c_str());
  std::fprintf(stderr,
               "usage: evaluate_mesh MESH.ply REFERENCE.ply [--samples N] [--seed S] [--threads T]\n"
               "  --samples N  area-uniform samples per surface (default 1000000)\n"
               "  --seed S     sampling seed (default 1)\n"
               "  --threads T  0 = one per core (default)\n");
  return message.empty() ? 0 : 2;
}

bool ParseCount(const char* text, unsigned long long* value) {
  char* end = nullptr;
  *value = std::strtoull(text, &end, 10);
  return end != text && *end == '\0';
}

int Run(int argc, char** argv) {
  std::string paths[2];
  int num_paths = 0;
  testing::MeshComparisonOptions options;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    unsigned long long value = 0;
    if (arg == "--help" || arg == "-h") return Usage("");
    if ((arg == "--samples" || arg == "--seed" || arg == "--threads") && i + 1 < argc) {
      if (!ParseCount(argv[++i], &value)) return Usage("bad number for " + arg);
      if (arg == "--samples") options.samples = value;
      if (arg == "--seed") options.seed = value;
      if (arg == "--threads") options.num_threads = static_cast<int>(value);
    } else if (!arg.empty() && arg[0] != '-' && num_paths < 2) {
      paths[num_paths++] = arg;
    } else {
      return Usage("unexpected argument " + arg);
    }
  }
  if (num_paths != 2) return Usage("need MESH.ply and REFERENCE.ply");
  Mesh meshes[2];
  for (int k = 0; k < 2; ++k) {
    Result<Mesh> mesh = ReadPly(paths[k]);
    if (!mesh.ok()) {
      std::fprintf(stderr, "evaluate_mesh: %s\n", mesh.status().ToString().c_str());
      return 2;
    }
    meshes[k] = std::move(mesh).value();
    std::printf("%s: %zu vertices, %zu triangles\n", paths[k].c_str(), meshes[k].positions.size(),
                meshes[k].triangles.size());
  }
  const testing::MeshComparison c = testing::CompareMeshes(meshes[0], meshes[1], options);
  if (c.samples == 0) {
    std::fprintf(stderr, "evaluate_mesh: a mesh has no triangle of non-zero area\n");
    return 1;
  }
  constexpr double kMm = 1e3;
  std::printf("samples %zu per surface\n", c.samples);
  std::printf("mesh->reference mean %.4f median %.4f rms %.4f p90 %.4f max %.4f (mm)\n",
              c.mean_mesh_to_reference * kMm, c.median_mesh_to_reference * kMm, c.rms_mesh_to_reference * kMm,
              c.p90_mesh_to_reference * kMm, c.max_mesh_to_reference * kMm);
  std::printf("reference->mesh mean %.4f median %.4f rms %.4f p90 %.4f max %.4f (mm)\n",
              c.mean_reference_to_mesh * kMm, c.median_reference_to_mesh * kMm, c.rms_reference_to_mesh * kMm,
              c.p90_reference_to_mesh * kMm, c.max_reference_to_mesh * kMm);
  return 0;
}

}  // namespace
}  // namespace reconar

int main(int argc, char** argv) { return reconar::Run(argc, argv); }
