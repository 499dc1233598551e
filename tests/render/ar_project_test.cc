// Loading what the AR view draws (render/ar/ar_project.h): a glTF scene of several nodes as one
// model, each node where the scene puts it; the design `reconar compare` registered, refused with
// what to run when the project holds no comparison with that design.
#include "render/ar/ar_project.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <unistd.h>

#include "core/base/atomic_file.h"
#include "core/mesh/glb_io.h"
#include "core/mesh/mesh_io.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;

Mesh Triangle(float x) {
  Mesh mesh;
  mesh.positions = {{x, 0, 0}, {x + 1, 0, 0}, {x, 1, 0}};
  mesh.triangles = {{0, 1, 2}};
  return mesh;
}

class ArProjectTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (fs::temp_directory_path() / ("reconar_ar_project_" + std::to_string(::getpid()))).string();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string dir_;
};

TEST_F(ArProjectTest, AGltfSceneIsDrawnWhole) {
  ASSERT_TRUE(WriteGlbScene(dir_ + "/design.glb", {{"a", Triangle(0)}, {"b", Triangle(5)}}).ok());
  const Result<ArModel> model = LoadArModel(dir_ + "/design.glb", 0);
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  ASSERT_EQ(model->mesh.triangles.size(), 2u);
  ASSERT_EQ(model->mesh.positions.size(), 6u);
  EXPECT_EQ(model->mesh.positions[3].x(), 5.0f);
  EXPECT_EQ(model->mesh.triangles[1][0], 3u);
}

TEST_F(ArProjectTest, TheDesignComesFromTheProjectsComparisonWithIt) {
  const std::string project = dir_ + "/project";
  Result<ArDesign> design = LoadArDesign(project, dir_ + "/plan.glb");
  ASSERT_FALSE(design.ok());
  EXPECT_EQ(design.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(design.status().message().find("reconar compare " + project + " " + dir_ + "/plan.glb"), std::string::npos)
      << design.status().message();

  fs::create_directories(project + "/compare");
  ASSERT_TRUE(WriteFileAtomically(project + "/compare/report.json", "{\"design\": \"/elsewhere/other.glb\"}\n").ok());
  design = LoadArDesign(project, dir_ + "/plan.glb");
  ASSERT_FALSE(design.ok());
  EXPECT_NE(design.status().message().find("/elsewhere/other.glb"), std::string::npos) << design.status().message();

  ASSERT_TRUE(WriteFileAtomically(project + "/compare/report.json", "{\"design\": \"/office/plan.glb\"}\n").ok());
  ASSERT_TRUE(WriteGlbScene(project + "/compare/design_registered.glb", {{"a", Triangle(0)}, {"b", Triangle(2)}}).ok());
  Mesh points;
  points.positions = {{0, 0, 0}, {1, 1, 1}};
  points.colors = {{255, 0, 0, 255}, {0, 0, 255, 255}};
  ASSERT_TRUE(WritePly(project + "/compare/deviation.ply", points).ok());
  design = LoadArDesign(project, dir_ + "/plan.glb");  // the same file name: the same design
  ASSERT_TRUE(design.ok()) << design.status().ToString();
  EXPECT_EQ(design->design.triangles.size(), 2u);
  EXPECT_EQ(design->deviation.positions.size(), 2u);
  EXPECT_EQ(design->deviation.colors[1][2], 255);
}

}  // namespace
}  // namespace reconar
