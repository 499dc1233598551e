#include "tests/support/bunny_scans.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>

#include "core/mesh/mesh_io.h"
#include "tests/support/mesh_distance.h"
#include "tests/support/run_command.h"

namespace reconar::testing {
namespace {

const std::string kBunnyDir = std::string(RECONAR_SHARED_DATA_DIR) + "/stanford_bunny";

class BunnyScansTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const auto start = std::chrono::steady_clock::now();
    Result<Mesh> loaded = LoadBunnyRangeScans(kBunnyDir + "/range_scans");
    load_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
    cloud_ = new Mesh(std::move(loaded).value());
    Result<Mesh> reference = ReadPly(kBunnyDir + "/reconstruction/bun_zipper.ply");
    ASSERT_TRUE(reference.ok()) << reference.status().ToString();
    reference_ = new Mesh(std::move(reference).value());
    ComputeVertexNormals(reference_);
  }
  static void TearDownTestSuite() {
    delete cloud_;
    delete reference_;
  }

  static Mesh* cloud_;
  static Mesh* reference_;
  static double load_seconds_;
};

Mesh* BunnyScansTest::cloud_ = nullptr;
Mesh* BunnyScansTest::reference_ = nullptr;
double BunnyScansTest::load_seconds_ = 0.0;

TEST_F(BunnyScansTest, OrientedPointsFromAllTenScans) {
  ASSERT_NE(cloud_, nullptr);
  std::printf("loaded %zu oriented points in %.2f s\n", cloud_->positions.size(), load_seconds_);
  // The ten scans hold 362,272 vertices; only isolated ones (in no triangle) are dropped.
  EXPECT_GT(cloud_->positions.size(), 340000u);
  EXPECT_LE(cloud_->positions.size(), 362272u);
  ASSERT_EQ(cloud_->normals.size(), cloud_->positions.size());
  EXPECT_TRUE(cloud_->triangles.empty());
  for (const Eigen::Vector3f& normal : cloud_->normals) ASSERT_NEAR(normal.norm(), 1.0f, 1e-5f);
}

TEST_F(BunnyScansTest, AlignedOntoTheZipperedReference) {
  ASSERT_NE(cloud_, nullptr);
  const std::vector<double> distances = DistancesTo(MeshDistanceField(*reference_), cloud_->positions, 2);
  std::vector<double> sorted = distances;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[sorted.size() / 2];
  const double within_1mm =
      static_cast<double>(std::lower_bound(sorted.begin(), sorted.end(), 0.001) - sorted.begin()) / sorted.size();
  std::printf("point-to-reference distance: median %.3f mm, 90%% %.3f mm, within 1 mm %.1f %%\n", median * 1e3,
              sorted[sorted.size() * 9 / 10] * 1e3, within_1mm * 100);
  // Scan noise and the reference's own error are a few tenths of a millimetre (SOURCE.txt: 0.5 mm
  // median to the nearest reference vertex); a misaligned scan would put its points centimetres off.
  EXPECT_LT(median, 0.0005);
  EXPECT_GT(within_1mm, 0.9);
}

TEST_F(BunnyScansTest, NormalsPointOutOfTheReferenceSurface) {
  ASSERT_NE(cloud_, nullptr);
  const MeshDistanceField field(*reference_);
  size_t compared = 0;
  size_t agreeing = 0;
  for (size_t i = 0; i < cloud_->positions.size(); ++i) {
    const ClosestSurfacePoint closest = field.Closest(cloud_->positions[i]);
    if (closest.distance > 0.001) continue;  // holes of the reference (the base), outliers
    const auto& triangle = reference_->triangles[closest.primitive];
    Eigen::Vector3f reference_normal = Eigen::Vector3f::Zero();
    for (const uint32_t v : triangle) reference_normal += reference_->normals[v];
    ++compared;
    agreeing += reference_normal.dot(cloud_->normals[i]) > 0.0f;
  }
  const double agreement = static_cast<double>(agreeing) / compared;
  std::printf("normals agreeing with the reference's outward normals: %.2f %% of %zu\n", agreement * 100, compared);
  EXPECT_GT(agreement, 0.95);
}

TEST(BunnyScansErrorsTest, MissingAndCorruptFilesAreReported) {
  const std::string dir = MakeTestDirectory("bunny_scans_errors");
  Result<Mesh> missing = LoadBunnyRangeScans(dir + "/nowhere");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);

  std::ofstream(dir + "/bun.conf") << "bmesh scan.ply 0 0 0 0 0 0 1\n";
  std::ofstream(dir + "/scan.ply") << "ply\nformat ascii 1.0\nobj_info num_cols 2\nobj_info num_rows 2\n"
                                      "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
                                      "element range_grid 4\nproperty list uchar int vertex_indices\nend_header\n"
                                      "0 0 0\n1 0\n0\n1 7\n0\n";
  Result<Mesh> corrupt = LoadBunnyRangeScans(dir);
  ASSERT_FALSE(corrupt.ok());
  EXPECT_EQ(corrupt.status().code(), StatusCode::kCorruptData);
  EXPECT_NE(corrupt.status().message().find("scan.ply"), std::string::npos) << corrupt.status().message();
}

}  // namespace
}  // namespace reconar::testing
