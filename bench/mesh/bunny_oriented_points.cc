// bunny_oriented_points: the Stanford Bunny's ten range scans, aligned and with normals
// (tests/support/bunny_scans.h), written as one binary PLY point cloud (x y z nx ny nz).
//
//   bunny_oriented_points OUTPUT.ply [--range-scans DIR] [--grey]
//
// --grey adds a mid-grey colour to every point: COLMAP's poisson_mesher (PoissonRecon with
// --colors) rejects a PLY without red/green/blue ("Failed to validate properties in file").
// DIR defaults to ../shared/data/stanford_bunny/range_scans. Exit codes: 0 ok, 1 failed to
// write, 2 bad usage or input.
#include <cstdio>
#include <string>

#include "core/mesh/mesh_io.h"
#include "tests/support/bunny_scans.h"

namespace reconar {
namespace {

int Usage(const std::string& message) {
  if (!message.empty()) std::fprintf(stderr, "bunny_oriented_points: %s\n", message.c_str());
  std::fprintf(stderr,
               "usage: bunny_oriented_points OUTPUT.ply [--range-scans DIR] [--grey]\n"
               "  --range-scans DIR  bun.conf and the scans (default %s/stanford_bunny/range_scans)\n"
               "  --grey             give every point the colour (128, 128, 128) (COLMAP needs colours)\n",
               RECONAR_SHARED_DATA_DIR);
  return message.empty() ? 0 : 2;
}

int Run(int argc, char** argv) {
  std::string output;
  bool grey = false;
  std::string range_scans = std::string(RECONAR_SHARED_DATA_DIR) + "/stanford_bunny/range_scans";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") return Usage("");
    if (arg == "--grey") {
      grey = true;
    } else if (arg == "--range-scans" && i + 1 < argc) {
      range_scans = argv[++i];
    } else if (!arg.empty() && arg[0] != '-' && output.empty()) {
      output = arg;
    } else {
      return Usage("unexpected argument " + arg);
    }
  }
  if (output.empty()) return Usage("missing OUTPUT.ply");
  Result<Mesh> cloud = testing::LoadBunnyRangeScans(range_scans);
  if (!cloud.ok()) {
    std::fprintf(stderr, "bunny_oriented_points: %s\n", cloud.status().ToString().c_str());
    return 2;
  }
  if (grey) cloud->colors.assign(cloud->positions.size(), {128, 128, 128, 255});
  const Status written = WritePly(output, *cloud);
  if (!written.ok()) {
    std::fprintf(stderr, "bunny_oriented_points: %s\n", written.ToString().c_str());
    return 1;
  }
  std::printf("%zu oriented points -> %s\n", cloud->positions.size(), output.c_str());
  return 0;
}

}  // namespace
}  // namespace reconar

int main(int argc, char** argv) { return reconar::Run(argc, argv); }
