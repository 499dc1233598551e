// WriteGlb / ReadGlb on the Stanford bunny (../shared/data/stanford_bunny): exact round trip, and
// the Khronos glTF validator's verdict on the files we write, also through WriteMeshFile (when node
// and the npm package gltf-validator are available: RECONAR_GLTF_VALIDATOR_DIR, CMake cache
// variable or environment; scripts/install-deps.sh installs it and scripts/test.sh passes it).
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>

#include "core/base/json_reader.h"
#include "core/io/image_write.h"
#include "core/mesh/glb_io.h"
#include "core/mesh/mesh_file.h"
#include "core/mesh/mesh_io.h"
#include "tests/core/mesh/mesh_test_util.h"
#include "tests/support/run_command.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;

const std::string kBunnyDir = std::string(RECONAR_SHARED_DATA_DIR) + "/stanford_bunny";

class GlbDataTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("reconar_glb_data_" + std::to_string(::getpid())) / info->name();
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_.parent_path()); }

  fs::path dir_;
};

// The bunny with area-weighted normals and a colour derived from each normal.
Mesh ShadedBunny() {
  Result<Mesh> mesh = ReadPly(kBunnyDir + "/reconstruction/bun_zipper.ply");
  EXPECT_TRUE(mesh.ok()) << mesh.status().ToString();
  if (!mesh.ok()) return Mesh();
  ComputeVertexNormals(&*mesh);
  for (const Eigen::Vector3f& n : mesh->normals) {
    const Eigen::Vector3f c = 127.5f * (n + Eigen::Vector3f::Ones());
    mesh->colors.push_back({static_cast<uint8_t>(c.x()), static_cast<uint8_t>(c.y()), static_cast<uint8_t>(c.z()), 255});
  }
  return std::move(mesh).value();
}

TEST_F(GlbDataTest, BunnyRoundTripIsExact) {
  const Mesh bunny = ShadedBunny();
  ASSERT_EQ(bunny.positions.size(), 35947u);
  const std::string path = (dir_ / "bunny.glb").string();
  const auto start = std::chrono::steady_clock::now();
  ASSERT_TRUE(WriteGlb(path, bunny).ok());
  const auto written = std::chrono::steady_clock::now();
  const Result<Mesh> read = ReadGlb(path);
  const auto end = std::chrono::steady_clock::now();
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  std::printf("bunny.glb: %ju bytes, write %.1f ms, read %.1f ms\n", static_cast<uintmax_t>(fs::file_size(path)),
              1e3 * std::chrono::duration<double>(written - start).count(),
              1e3 * std::chrono::duration<double>(end - written).count());
  testing::ExpectMeshesEqual(*read, bunny);
}

std::string ValidatorDir() {
  if (const char* env = std::getenv("RECONAR_GLTF_VALIDATOR_DIR"); env != nullptr && *env != '\0') return env;
  return RECONAR_GLTF_VALIDATOR_DIR;
}

TEST_F(GlbDataTest, KhronosValidatorAcceptsOurFiles) {
  const std::string validator_dir = ValidatorDir();
  if (validator_dir.empty() || !fs::exists(fs::path(validator_dir) / "node_modules" / "gltf-validator")) {
    GTEST_SKIP() << "glTF validator not found: run `npm install gltf-validator` in a directory and pass it as "
                    "-DRECONAR_GLTF_VALIDATOR_DIR=<dir> or the environment variable RECONAR_GLTF_VALIDATOR_DIR "
                    "(now: '" << validator_dir << "')";
  }
  if (testing::RunCommand("node --version").exit_code != 0) GTEST_SKIP() << "node not found on PATH";

  // The bunny (uint16 indices, normals, colours), a range scan as a bare point cloud, the bunny's
  // vertices as a point cloud with normals and colours, and a grid large enough for uint32 indices.
  std::vector<std::pair<std::string, Mesh>> meshes;
  const Mesh bunny = ShadedBunny();
  meshes.emplace_back("bunny.glb", bunny);
  Result<Mesh> scan = ReadPly(kBunnyDir + "/range_scans/bun000.ply");
  ASSERT_TRUE(scan.ok()) << scan.status().ToString();
  meshes.emplace_back("bun000_points.glb", *scan);
  Mesh bunny_points = bunny;
  bunny_points.triangles.clear();
  meshes.emplace_back("bunny_points.glb", bunny_points);
  Mesh grid;
  const int side = 300;  // 90,000 vertices
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) grid.positions.emplace_back(0.01f * x, 0.01f * y, 0.0f);
  }
  for (uint32_t y = 0; y + 1 < side; ++y) {
    for (uint32_t x = 0; x + 1 < side; ++x) {
      const uint32_t i = y * side + x;
      grid.triangles.push_back({i, i + 1, i + side + 1});
      grid.triangles.push_back({i, i + side + 1, i + side});
    }
  }
  ComputeVertexNormals(&grid);
  meshes.emplace_back("grid_uint32.glb", grid);

  std::string files;
  for (const auto& [name, mesh] : meshes) {
    const std::string path = (dir_ / name).string();
    ASSERT_TRUE(WriteGlb(path, mesh).ok()) << name;
    files += " " + path;
  }
  // The coloured bunny through the extension dispatch the `reconar export` and `mesh` commands use.
  const std::string dispatched = (dir_ / "bunny_mesh_file.GLB").string();
  ASSERT_TRUE(WriteMeshFile(dispatched, bunny).ok());
  files += " " + dispatched;
  meshes.emplace_back("bunny_mesh_file.GLB", Mesh());
  // A design of named elements, one node each: a mesh with uint16 indices, one with uint32, a
  // point cloud, and an unnamed element.
  const std::string scene = (dir_ / "design_scene.glb").string();
  ASSERT_TRUE(WriteGlbScene(scene, {{"bunny", bunny}, {"floor \"A\"", grid}, {"points", *scan}, {"", bunny}}).ok());
  files += " " + scene;
  meshes.emplace_back("design_scene.glb", Mesh());
  // The bunny textured: texcoords from its normals over a real PNG, vertex colours kept.
  Mesh textured = bunny;
  for (const Eigen::Vector3f& n : bunny.normals) textured.texcoords.emplace_back(0.5f + 0.5f * n.x(), 0.5f - 0.5f * n.y());
  Image<uint8_t> checker(64, 32, 3);
  for (int y = 0; y < checker.height(); ++y) {
    for (int x = 0; x < checker.width() * 3; ++x) checker.row(y)[x] = ((x / 3 / 8 + y / 8) % 2) ? 230 : 40;
  }
  const Result<std::string> png = EncodePng(checker.view(), 3);
  ASSERT_TRUE(png.ok());
  const std::string textured_path = (dir_ / "bunny_textured.glb").string();
  ASSERT_TRUE(WriteTexturedGlb(textured_path, textured, {{0, *png}}).ok());
  files += " " + textured_path;
  meshes.emplace_back("bunny_textured.glb", Mesh());
  const testing::CommandRun run = testing::RunCommand("node " + std::string(RECONAR_SOURCE_DIR) +
                                                      "/tests/core/mesh/validate_glb.js " + validator_dir + files,
                                                      testing::StderrMode::kSeparate);
  ASSERT_EQ(run.exit_code, 0) << run.output << run.error;
  std::printf("%s", run.output.c_str());
  size_t line_start = 0;
  int reports = 0;
  while (line_start < run.output.size()) {
    size_t line_end = run.output.find('\n', line_start);
    if (line_end == std::string::npos) line_end = run.output.size();
    const Result<JsonValue> report = ParseJson(run.output.substr(line_start, line_end - line_start), "validator");
    line_start = line_end + 1;
    ASSERT_TRUE(report.ok()) << report.status().ToString();
    ++reports;
    EXPECT_EQ(report->Find("numErrors")->AsInteger(), 0) << report->Find("file")->string();
    EXPECT_EQ(report->Find("numWarnings")->AsInteger(), 0) << report->Find("file")->string();
  }
  EXPECT_EQ(reports, static_cast<int>(meshes.size()));
}

}  // namespace
}  // namespace reconar
