// ReadPly on the Stanford bunny files (../shared/data/stanford_bunny, see SOURCE.txt): the counts
// their headers declare, values from their text, and a write/read round trip of the real mesh.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>

#include "core/mesh/mesh_io.h"
#include "tests/core/mesh/mesh_test_util.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;

const std::string kBunnyDir = std::string(RECONAR_SHARED_DATA_DIR) + "/stanford_bunny";

TEST(PlyDataTest, BunZipperMatchesItsHeaderAndText) {
  const std::string path = kBunnyDir + "/reconstruction/bun_zipper.ply";
  const auto start = std::chrono::steady_clock::now();
  const Result<Mesh> mesh = ReadPly(path);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  std::printf("bun_zipper.ply (ASCII, 3.0 MB): read in %.1f ms\n", 1e3 * seconds);
  // "element vertex 35947", "element face 69451", all lines "3 a b c".
  EXPECT_EQ(mesh->positions.size(), 35947u);
  EXPECT_EQ(mesh->triangles.size(), 69451u);
  EXPECT_TRUE(mesh->normals.empty());  // x y z confidence intensity: no normals, no colours
  EXPECT_TRUE(mesh->colors.empty());
  // First and last vertex and face lines of the file.
  EXPECT_EQ(mesh->positions.front(), Eigen::Vector3f(-0.0378297f, 0.12794f, 0.00447467f));
  EXPECT_EQ(mesh->positions.back(), Eigen::Vector3f(-0.0400442f, 0.15362f, -0.00816685f));
  EXPECT_EQ(mesh->triangles.front(), (std::array<uint32_t, 3>{21216, 21215, 20399}));
  EXPECT_EQ(mesh->triangles.back(), (std::array<uint32_t, 3>{17277, 17346, 17345}));
  // SOURCE.txt: the object is about 0.15 m wide (metres).
  Eigen::Vector3f lo = mesh->positions[0], hi = mesh->positions[0];
  for (const Eigen::Vector3f& p : mesh->positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  EXPECT_GT((hi - lo).maxCoeff(), 0.14f);
  EXPECT_LT((hi - lo).maxCoeff(), 0.17f);
}

TEST(PlyDataTest, DecimatedReconstructionsMatchTheirHeaders) {
  const struct {
    const char* name;
    size_t vertices;
    size_t faces;
  } files[] = {{"bun_zipper_res2.ply", 8171, 16301}, {"bun_zipper_res3.ply", 1889, 3851},
               {"bun_zipper_res4.ply", 453, 948}};
  for (const auto& file : files) {
    const Result<Mesh> mesh = ReadPly(kBunnyDir + "/reconstruction/" + file.name);
    ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
    EXPECT_EQ(mesh->positions.size(), file.vertices) << file.name;
    EXPECT_EQ(mesh->triangles.size(), file.faces) << file.name;
  }
}

TEST(PlyDataTest, RangeScansAreVertexOnlyWithTheirRangeGridSkipped) {
  // "element vertex N" of each scan; "element range_grid 204800" (512 x 400) is not a face list.
  const struct {
    const char* name;
    size_t vertices;
  } scans[] = {{"bun000.ply", 40256}, {"bun045.ply", 40097}, {"bun090.ply", 30379}, {"bun180.ply", 40251},
               {"bun270.ply", 31701}, {"bun315.ply", 35336}, {"chin.ply", 37738},  {"ear_back.ply", 32193},
               {"top2.ply", 38298},   {"top3.ply", 36023}};
  for (const auto& scan : scans) {
    const Result<Mesh> mesh = ReadPly(kBunnyDir + "/range_scans/" + scan.name);
    ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
    EXPECT_EQ(mesh->positions.size(), scan.vertices) << scan.name;
    EXPECT_TRUE(mesh->is_point_cloud()) << scan.name;
  }
  // First vertex line of bun000.ply.
  const Result<Mesh> bun000 = ReadPly(kBunnyDir + "/range_scans/bun000.ply");
  ASSERT_TRUE(bun000.ok());
  EXPECT_EQ(bun000->positions.front(), Eigen::Vector3f(-0.06325f, 0.0359793f, 0.0420873f));
}

TEST(PlyDataTest, BunZipperRoundTripsInBothFormats) {
  const Result<Mesh> mesh = ReadPly(kBunnyDir + "/reconstruction/bun_zipper.ply");
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  const fs::path dir = fs::temp_directory_path() / ("reconar_ply_data_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  for (const PlyFormat format : {PlyFormat::kBinaryLittleEndian, PlyFormat::kAscii}) {
    const std::string path = (dir / "bunny.ply").string();
    const auto start = std::chrono::steady_clock::now();
    ASSERT_TRUE(WritePly(path, *mesh, format).ok());
    const auto written = std::chrono::steady_clock::now();
    const Result<Mesh> read = ReadPly(path);
    const auto end = std::chrono::steady_clock::now();
    ASSERT_TRUE(read.ok()) << read.status().ToString();
    std::printf("%s: %ju bytes, write %.1f ms, read %.1f ms\n",
                format == PlyFormat::kAscii ? "ascii" : "binary", static_cast<uintmax_t>(fs::file_size(path)),
                1e3 * std::chrono::duration<double>(written - start).count(),
                1e3 * std::chrono::duration<double>(end - written).count());
    testing::ExpectMeshesEqual(*read, *mesh);
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace reconar
