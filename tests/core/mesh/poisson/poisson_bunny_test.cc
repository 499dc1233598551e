// Screened Poisson on the Stanford Bunny's ten real range scans, scored against the zippered
// reference surface (../shared/data/stanford_bunny, see SOURCE.txt) with the same harness and
// settings as the peer, COLMAP 3.8's PoissonRecon.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/mesh/mesh_io.h"
#include "core/mesh/poisson/point_normals.h"
#include "core/mesh/poisson/poisson.h"
#include "tests/core/mesh/poisson/poisson_test_util.h"
#include "tests/support/bunny_scans.h"
#include "tests/support/mesh_distance.h"

namespace reconar {
namespace {

const std::string kBunnyDir = std::string(RECONAR_SHARED_DATA_DIR) + "/stanford_bunny";

struct BunnyRun {
  testing::MeshComparison score;
  double finest_cell_edge_m = 0.0;
};

// Depth 8, trim 7, point weight 1 on the ten scans, scored with 1,000,000 samples per surface.
BunnyRun MeshTheBunny() {
  BunnyRun run;
  Result<Mesh> points = testing::LoadBunnyRangeScans(kBunnyDir + "/range_scans");
  EXPECT_TRUE(points.ok()) << points.status().ToString();
  Result<Mesh> reference = ReadPly(kBunnyDir + "/reconstruction/bun_zipper.ply");
  EXPECT_TRUE(reference.ok()) << reference.status().ToString();
  if (!points.ok() || !reference.ok()) return run;

  PoissonOptions options;
  options.depth = 8;
  options.point_weight = 1.0;  // what the peer ran: COLMAP's --PoissonMeshing.point_weight default
  if (const char* threads = std::getenv("RECONAR_POISSON_THREADS")) options.num_threads = std::atoi(threads);
  // RECONAR_POISSON_DEGREE=1 measures the first-order elements (the default is 2).
  if (const char* degree = std::getenv("RECONAR_POISSON_DEGREE")) options.degree = std::atoi(degree);
  // The trim value means "estimated sample depth" (poisson.h), as PoissonRecon's; 7 = depth - 1
  // keeps surface with at least ~1/4 of a finest cell's nominal sampling, as in the peer run.
  options.trim = 7.0;
  PoissonReport report;
  const auto start = std::chrono::steady_clock::now();
  const std::clock_t cpu_start = std::clock();
  Result<Mesh> mesh = ReconstructPoissonSurface(*points, options, &report);
  const double cpu_seconds = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(mesh.ok()) << mesh.status().ToString();
  if (!mesh.ok()) return run;

  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& p : points->positions) box.extend(p);
  run.finest_cell_edge_m = options.scale * box.sizes().maxCoeff() / static_cast<double>(1 << options.depth);

  testing::MeshComparisonOptions compare;
  compare.samples = 1'000'000;
  const testing::MeshComparison score = testing::CompareMeshes(*mesh, *reference, compare);
  std::printf("poisson bunny: %zu points -> %zu vertices, %zu triangles in %.2f s (%.2f s CPU) "
              "(octree %.2f, solve %.2f, extract %.2f, trim %.2f; %d nodes, %d unknowns, %d CG iterations)\n"
              "  mean mesh->reference %.4f mm, reference->mesh %.4f mm\n",
              points->positions.size(), report.vertices, report.triangles, seconds, cpu_seconds, report.seconds_octree,
              report.seconds_solve, report.seconds_extract, report.seconds_trim, report.octree_nodes,
              report.unknowns, report.solver_iterations, 1e3 * score.mean_mesh_to_reference,
              1e3 * score.mean_reference_to_mesh);
  if (const char* out = std::getenv("RECONAR_POISSON_BUNNY_OUT")) {
    EXPECT_TRUE(WritePly(out, *mesh).ok());
  }
  run.score = score;
  return run;
}

// One run, two bars (CTest runs every case in its own process, so they share one case):
// - sub-cell: the scans lie a median 0.06 mm from the reference (bunny_scans.h); a mesh that
//   follows them must lie well inside one finest cell (about 0.67 mm at depth 8): a tenth of a
//   cell both ways;
// - the bar against the peer, with the default second-order B-splines
//   (PoissonOptions::degree 2: 0.0458 / 0.0443 mm, 2.6-4.9 s CPU for the reconstruction on the
//   loaded 2-core build machine; degree 1 misses it on reference->mesh: 0.0495 / 0.0480 mm).
TEST(PoissonBunnyTest, SubCellAndAtLeastAsAccurateAsPoissonRecon) {
  const BunnyRun run = MeshTheBunny();
  ASSERT_GT(run.finest_cell_edge_m, 0.0);
  EXPECT_LT(run.score.mean_mesh_to_reference, 0.1 * run.finest_cell_edge_m);
  EXPECT_LT(run.score.mean_reference_to_mesh, 0.1 * run.finest_cell_edge_m);
  const testing::MeshComparison& score = run.score;

  // The peer's figures, measured with this harness (1,000,000 samples per surface, seed 1) on the
  // same input (bench/mesh/compare_poisson.sh; bench/mesh/bunny_oriented_points writes the points):
  //   colmap poisson_mesher --input_path pts.ply --output_path colmap_d8_t7.ply
  //       --PoissonMeshing.depth 8 --PoissonMeshing.trim 7 --PoissonMeshing.num_threads 1
  //   evaluate_mesh colmap_d8_t7.ply bun_zipper.ply
  // COLMAP 3.8 runs its bundled PoissonRecon 8.0 with --pointWeight 1 (COLMAP's default
  // --PoissonMeshing.point_weight), --depth 8, --color 32, --density, and PoissonRecon 8.0's own
  // defaults otherwise: --degree 2 (second-order B-splines), non-linear iso-surface fit,
  // --samplesPerNode 1.5, --scale 1.1, Neumann boundary; then SurfaceTrimmer --trim 7.
  // (16.3 s CPU, 186,126 vertices). The bar: at least as accurate both ways.
  constexpr double kPeerMeshToReferenceMm = 0.0500;
  constexpr double kPeerReferenceToMeshMm = 0.0452;
  EXPECT_LE(1e3 * score.mean_mesh_to_reference, kPeerMeshToReferenceMm);
  EXPECT_LE(1e3 * score.mean_reference_to_mesh, kPeerReferenceToMeshMm);
}

// Normals estimated from the scan points alone (k-NN PCA, MST orientation) against the normals of
// each scan's own range-grid triangulation (bunny_scans.h), which face the scanner.
TEST(PoissonBunnyTest, EstimatedNormalsAgreeWithTheScanNormals) {
  Result<Mesh> scans = testing::LoadBunnyRangeScans(kBunnyDir + "/range_scans");
  ASSERT_TRUE(scans.ok()) << scans.status().ToString();
  Mesh points;
  points.positions = scans->positions;
  const auto start = std::chrono::steady_clock::now();
  ASSERT_TRUE(EstimateNormals(&points, NormalEstimationOptions()).ok());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  size_t flipped = 0;
  std::vector<float> degrees;
  for (size_t i = 0; i < points.positions.size(); ++i) {
    const float cosine = points.normals[i].dot(scans->normals[i].normalized());
    if (cosine < 0.0f) ++flipped;
    degrees.push_back(std::acos(std::min(1.0f, std::abs(cosine))) * 180.0f / static_cast<float>(M_PI));
  }
  std::nth_element(degrees.begin(), degrees.begin() + degrees.size() / 2, degrees.end());
  const float median = degrees[degrees.size() / 2];
  std::nth_element(degrees.begin(), degrees.begin() + degrees.size() * 9 / 10, degrees.end());
  const float p90 = degrees[degrees.size() * 9 / 10];
  const double flipped_share = static_cast<double>(flipped) / static_cast<double>(points.positions.size());
  std::printf("bunny normals: %zu points in %.2f s, angle to scan normals median %.2f p90 %.2f degrees, "
              "%.3f %% flipped\n", points.positions.size(), seconds, median, p90, 100.0 * flipped_share);
  EXPECT_LT(flipped_share, 0.01);
  EXPECT_LT(median, 10.0f);
}

}  // namespace
}  // namespace reconar
