// deviation_dump DESIGN POINTS.ply OUT_DIR [MAX_DISTANCE]: the per-point signed distances
// `reconar compare` computes (core/compare/deviation.h, the design already in the world frame:
// compare/design_registered.glb), without the normal check, for a peer's cloud-to-mesh distances
// on the same input: OUT_DIR/design.ply (the design's elements joined, for tools that read no glTF)
// and OUT_DIR/ours.f32 (one float32 per point in the file's order, NaN where no design surface lies
// within MAX_DISTANCE, default 0.1 m). Prints the distance computation's time on 1 and 2 threads.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/compare/design_registration.h"
#include "core/compare/deviation.h"
#include "core/mesh/mesh_io.h"

namespace reconar {
namespace {

int Run(int argc, char** argv) {
  if (argc != 4 && argc != 5) {
    std::fprintf(stderr, "usage: deviation_dump DESIGN POINTS.ply OUT_DIR [MAX_DISTANCE]\n");
    return 2;
  }
  const std::string out = argv[3];
  Result<Design> design = ReadDesign(argv[1]);
  if (!design.ok()) {
    std::fprintf(stderr, "%s\n", design.status().ToString().c_str());
    return 1;
  }
  Result<Mesh> cloud = ReadPly(argv[2]);
  if (!cloud.ok()) {
    std::fprintf(stderr, "%s\n", cloud.status().ToString().c_str());
    return 1;
  }
  std::vector<Eigen::Vector3d> points;
  points.reserve(cloud->positions.size());
  for (const Eigen::Vector3f& p : cloud->positions) points.push_back(p.cast<double>());
  const DesignSurface joined = PlaceDesign(*design, Sim3());
  Status written = WritePly(out + "/design.ply", joined.mesh);
  if (!written.ok()) {
    std::fprintf(stderr, "%s\n", written.ToString().c_str());
    return 1;
  }
  DeviationOptions options;
  if (argc == 5) options.max_distance = std::stod(argv[4]);
  options.max_normal_angle_deg = 180.0;
  Result<DeviationReport> report = InvalidArgument("not run");
  for (const int threads : {1, 2}) {
    options.num_threads = threads;
    const auto start = std::chrono::steady_clock::now();
    report = ComputeDeviation(*design, Sim3(), points, {}, nullptr, options);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!report.ok()) {
      std::fprintf(stderr, "%s\n", report.status().ToString().c_str());
      return 1;
    }
    std::printf("ours: %zu points against %zu triangles, %d thread(s): %.2f s\n", points.size(),
                joined.mesh.triangles.size(), threads, seconds);
  }
  std::vector<float> distances(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    distances[i] = report->element_of_point[i] < 0 ? NAN : static_cast<float>(report->signed_distance_m[i]);
  }
  written = WriteFileAtomically(out + "/ours.f32", std::string(reinterpret_cast<const char*>(distances.data()),
                                                               distances.size() * sizeof(float)));
  if (!written.ok()) {
    std::fprintf(stderr, "%s\n", written.ToString().c_str());
    return 1;
  }
  return 0;
}

}  // namespace
}  // namespace reconar

int main(int argc, char** argv) { return reconar::Run(argc, argv); }
