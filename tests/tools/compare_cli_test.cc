// `reconar compare` end to end on a project made here with exact truth: dense points sampled from
// what was built (a ground and three boxes, one of them moved 4 cm), three tags in tags.layout, and
// a design written as a GLB in millimetres in a frame of its own, placed by a control file of the
// tags' corners. Then the errors a person meets: a control tag the project does not hold, a project
// without dense points, a design file that is no design.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/base/json_reader.h"
#include "core/io/image_io.h"
#include "core/mesh/glb_io.h"
#include "core/mesh/mesh_io.h"
#include "core/sfm/tag_layout.h"
#include "core/sfm/tag_squares.h"
#include "tests/support/design_scene.h"
#include "tests/support/run_command.h"

namespace reconar {
namespace {

constexpr double kTagSize = 0.2;

class CompareCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTestDirectory("reconar_compare_cli");
    project_ = dir_ + "/project";
    std::filesystem::create_directories(project_ + "/dense");
    // The design in the world frame (metres): the ground and three boxes.
    const std::vector<NamedMesh> world = {
        {"ground", Ground()},
        {"column", testing::BoxMesh({-1.5, -1.5, 0}, {-1.1, -1.1, 2.0})},
        {"wall", testing::BoxMesh({0.0, 1.0, 0}, {2.0, 1.2, 1.5})},
        {"plinth", testing::BoxMesh({0.5, -1.5, 0}, {1.5, -0.5, 0.4})}};
    // Built: the column 4 cm off along +x, the rest as designed.
    std::mt19937 random(3);
    std::vector<Eigen::Vector3d> points, normals;
    const Rigid3 column_moved{Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.04, 0, 0)};
    testing::SampleMeshFaces(testing::MovedMesh(world[1].mesh, column_moved), 0.02, 0.001, &random, &points, &normals);
    for (size_t e = 2; e < world.size(); ++e) testing::SampleMeshFaces(world[e].mesh, 0.02, 0.001, &random, &points, &normals);
    testing::SampleMeshFaces(world[0].mesh, 0.05, 0.001, &random, &points, &normals);
    Mesh cloud;
    for (size_t i = 0; i < points.size(); ++i) {
      cloud.positions.push_back(points[i].cast<float>());
      cloud.normals.push_back(normals[i].cast<float>());
    }
    ASSERT_TRUE(WritePly(project_ + "/dense/points.ply", cloud).ok());
    // Three tags flat on the ground, registered in the world frame.
    std::vector<LayoutTag> tags;
    for (int id = 0; id < 3; ++id) {
      tags.push_back({id, kTagSize, Rigid3{Eigen::Matrix3d::Identity(), Eigen::Vector3d(-2.0 + 2.0 * id, 2.0 - id, 0.0)}});
    }
    std::ofstream(project_ + "/tags.layout") << FormatTagLayout(tags);
    std::ofstream(project_ + "/tags.json") << "{\"metric\": true, \"tag_size_m\": 0.2, \"world_tag\": 0}\n";
    // The design as delivered: millimetres, turned 30 degrees about the vertical and moved.
    design_from_world_ = Rigid3{Eigen::AngleAxisd(0.52, Eigen::Vector3d::UnitZ()).toRotationMatrix(),
                                Eigen::Vector3d(0.3, -0.8, 0.1)};
    std::vector<NamedMesh> design;
    for (const NamedMesh& element : world) {
      Mesh mm = testing::MovedMesh(element.mesh, design_from_world_);
      for (Eigen::Vector3f& p : mm.positions) p *= 1000.0f;
      design.push_back({element.name, mm});
    }
    ASSERT_TRUE(WriteGlbScene(dir_ + "/design.glb", design).ok());
    std::ofstream control(dir_ + "/control.txt");
    control << "# the tags' corners in the design (mm)\n";
    for (const LayoutTag& tag : tags) {
      control << tag.id;
      for (const Eigen::Vector3d& corner : TagSquareCorners(kTagSize)) {
        const Eigen::Vector3d design_mm = 1000.0 * (design_from_world_ * (tag.layout_from_tag * corner));
        control << " " << design_mm.x() << " " << design_mm.y() << " " << design_mm.z();
      }
      control << "\n";
    }
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  static Mesh Ground() {
    Mesh ground;
    ground.positions = {{-3, -3, 0}, {3, -3, 0}, {3, 3, 0}, {-3, 3, 0}};
    ground.triangles = {{0, 1, 2}, {0, 2, 3}};
    return ground;
  }

  std::string dir_, project_;
  Rigid3 design_from_world_;
};

TEST_F(CompareCliTest, FindsTheMovedColumnInADesignDrawnInMillimetres) {
  const testing::CommandRun run =
      testing::RunReconar("compare " + project_ + " " + dir_ + "/design.glb --control " + dir_ + "/control.txt --json",
                          testing::StderrMode::kSeparate);
  ASSERT_EQ(run.exit_code, 0) << run.error;
  const Result<JsonValue> report = ParseJson(run.output, "stdout");
  ASSERT_TRUE(report.ok()) << run.output;
  const JsonValue& registration = *report->Find("registration");
  EXPECT_EQ(registration.Find("units")->string(), "mm");
  EXPECT_NEAR(registration.Find("scale")->number(), 0.001, 1e-9);
  EXPECT_LT(registration.Find("control_rms_m")->number(), 0.002);
  EXPECT_EQ(registration.Find("control_tags")->AsInteger(), 3);
  std::map<std::string, std::string> verdicts;
  for (size_t e = 0; e < report->Find("elements")->size(); ++e) {
    const JsonValue& element = (*report->Find("elements"))[e];
    verdicts[element.Find("name")->string()] = element.Find("verdict")->string();
    if (element.Find("name")->string() == "column") {
      EXPECT_NEAR((*element.Find("shift_m"))[0].number(), 0.04, 0.005);
    }
  }
  EXPECT_EQ(verdicts["column"], "deviates");
  EXPECT_EQ(verdicts["wall"], "as_designed");
  EXPECT_EQ(verdicts["plinth"], "as_designed");
  EXPECT_EQ(verdicts["ground"], "as_designed");
  for (const char* output : {"report.json", "deviation.ply", "design_registered.glb", "report.png"}) {
    EXPECT_TRUE(std::filesystem::exists(project_ + "/compare/" + output)) << output;
  }
  // The picture's table says the verdicts in their colours: red for the column, green for the rest.
  const Result<DecodedImage> picture = ReadImage(project_ + "/compare/report.png");
  ASSERT_TRUE(picture.ok()) << picture.status().message();
  EXPECT_EQ(picture->rgb.width(), 1280);
  int red = 0, green = 0;
  for (int y = 600; y < picture->rgb.height(); ++y) {
    for (int x = 0; x < picture->rgb.width(); ++x) {
      const uint8_t* p = picture->rgb.row(y) + 3 * x;
      red += p[0] == 200 && p[1] == 40 && p[2] == 30;
      green += p[0] == 30 && p[1] == 140 && p[2] == 60;
    }
  }
  EXPECT_GT(red, 100);
  EXPECT_GT(green, 3 * 100);  // three elements as designed
  // The registered design lands on the world frame: its wall where the world design has it.
  const Result<std::vector<NamedMesh>> placed = ReadGltfScene(project_ + "/compare/design_registered.glb");
  ASSERT_TRUE(placed.ok()) << placed.status().message();
  ASSERT_EQ(placed->size(), 4u);
  EXPECT_EQ((*placed)[2].name, "wall");
  const Mesh wall = testing::BoxMesh({0.0, 1.0, 0}, {2.0, 1.2, 1.5});
  for (size_t v = 0; v < wall.positions.size(); ++v) {
    EXPECT_LT(((*placed)[2].mesh.positions[v] - wall.positions[v]).norm(), 0.002f) << v;
  }
  // The table for a person.
  const testing::CommandRun table =
      testing::RunReconar("compare " + project_ + " " + dir_ + "/design.glb --control " + dir_ + "/control.txt");
  EXPECT_EQ(table.exit_code, 0);
  EXPECT_NE(table.output.find("units mm"), std::string::npos) << table.output;
  EXPECT_NE(table.output.find("deviates (moved"), std::string::npos) << table.output;
}

TEST_F(CompareCliTest, BadInputIsNamed) {
  std::ofstream(dir_ + "/unknown.txt") << "0 0 0 0\n1 1 0 0\n7 5 5 0\n";
  testing::CommandRun run =
      testing::RunReconar("compare " + project_ + " " + dir_ + "/design.glb --control " + dir_ + "/unknown.txt");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("unknown.txt"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("tag 7"), std::string::npos) << run.output;

  std::ofstream(dir_ + "/notes.txt") << "not a design\n";
  run = testing::RunReconar("compare " + project_ + " " + dir_ + "/notes.txt");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("notes.txt"), std::string::npos) << run.output;

  std::ofstream(dir_ + "/broken.glb") << "glTF but not really";
  run = testing::RunReconar("compare " + project_ + " " + dir_ + "/broken.glb");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("broken.glb"), std::string::npos) << run.output;

  // A design with a vertex that is not a number: the OBJ reader refuses the number, a PLY's reads
  // as NaN and the design refuses the vertex.
  std::ofstream(dir_ + "/nan.obj") << "g slab\nv 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n";
  run = testing::RunReconar("compare " + project_ + " " + dir_ + "/nan.obj");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("nan.obj: OBJ line 4"), std::string::npos) << run.output;
  std::ofstream(dir_ + "/nan.ply") << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                      "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                                      "end_header\n0 0 0\n1 0 0\nnan 1 0\n3 0 1 2\n";
  run = testing::RunReconar("compare " + project_ + " " + dir_ + "/nan.ply");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("nan.ply"), std::string::npos) << run.output;

  // A design in no unit: the control's scale is 2.5 mm per design unit.
  {
    std::ifstream control_in(dir_ + "/control.txt");
    std::ofstream control_out(dir_ + "/odd_unit.txt");
    for (std::string line; std::getline(control_in, line);) {
      std::istringstream fields(line);
      std::string word;
      fields >> word;
      control_out << word;
      for (double value; fields >> value;) control_out << " " << value / 2.5;
      control_out << "\n";
    }
  }
  run = testing::RunReconar("compare " + project_ + " " + dir_ + "/design.glb --control " + dir_ + "/odd_unit.txt");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("no metre, centimetre, millimetre, inch or foot"), std::string::npos) << run.output;

  // A design far from the model: no as-built point near it.
  Mesh far_away = testing::BoxMesh({100, 100, 0}, {101, 101, 1});
  ASSERT_TRUE(WriteGlbScene(dir_ + "/far.glb", {{"far", far_away}}).ok());
  run = testing::RunReconar("compare " + project_ + " " + dir_ + "/far.glb");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("does not overlap the model"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(project_ + "/compare/report.json"));

  std::filesystem::remove(project_ + "/dense/points.ply");
  run = testing::RunReconar("compare " + project_ + " " + dir_ + "/design.glb");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("dense"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(project_ + "/compare/report.json"));
}

}  // namespace
}  // namespace reconar
