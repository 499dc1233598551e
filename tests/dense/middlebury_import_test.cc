// ImportMiddleburyProject on a small _par.txt written here: the cameras come back through the
// COLMAP text reader exactly, and malformed files are refused with the file and line named.
#include "tests/dense/middlebury_import.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <string>

#include "core/base/atomic_file.h"
#include "core/io/image_write.h"
#include "core/pipeline/project.h"
#include "core/sfm/model_io.h"
#include "tests/support/run_command.h"
#include "tests/support/sfm_evaluation.h"

namespace reconar {
namespace testing {
namespace {

std::string ParLine(const std::string& name, const Eigen::Matrix3d& k, const Eigen::Matrix3d& r,
                    const Eigen::Vector3d& t) {
  std::string line = name;
  auto append = [&line](double value) {
    char buffer[40];
    std::snprintf(buffer, sizeof(buffer), " %.17g", value);
    line += buffer;
  };
  for (int i = 0; i < 3; ++i) for (int j = 0; j < 3; ++j) append(k(i, j));
  for (int i = 0; i < 3; ++i) for (int j = 0; j < 3; ++j) append(r(i, j));
  for (int i = 0; i < 3; ++i) append(t[i]);
  return line + "\n";
}

void WriteBlackPng(const std::string& path, int width, int height) {
  Image<uint8_t> image(width, height, 3);
  ASSERT_TRUE(WritePng(path, image.view(), 3).ok());
}

TEST(MiddleburyImportTest, CamerasRoundTripThroughTheColmapReader) {
  const std::string dir = MakeTestDirectory("reconar_middlebury_import");
  Eigen::Matrix3d k;
  k << 1520.4, 0.0, 302.32, 0.0, 1525.9, 246.87, 0.0, 0.0, 1.0;
  const Eigen::Matrix3d r0 = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Matrix3d r1 = Eigen::AngleAxisd(-1.2, Eigen::Vector3d(0, 1, 0)).toRotationMatrix();
  const Eigen::Vector3d t0(-0.03, -0.02, 0.52);
  const Eigen::Vector3d t1(0.01, 0.04, 0.49);
  ASSERT_TRUE(WriteFileAtomically(dir + "/set_par.txt",
                                  "2\n" + ParLine("a.png", k, r0, t0) + ParLine("b.png", k, r1, t1)).ok());
  WriteBlackPng(dir + "/a.png", 64, 48);
  WriteBlackPng(dir + "/b.png", 64, 48);

  auto report = ImportMiddleburyProject(dir + "/set_par.txt", dir + "/project");
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->views, 2);
  EXPECT_EQ(report->cameras, 1);

  auto model = ReadColmapTextModel(dir + "/project/sparse");
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  ASSERT_EQ(model->cameras.size(), 1u);
  ASSERT_EQ(model->images.size(), 2u);
  EXPECT_EQ(model->points.size(), 0u);
  const SfmCamera& camera = model->cameras[0];
  EXPECT_EQ(camera.width, 64);
  EXPECT_EQ(camera.height, 48);
  EXPECT_NEAR(camera.focal, 1520.4, 1e-9);
  EXPECT_NEAR(camera.aspect * camera.focal, 1525.9, 1e-9);
  EXPECT_NEAR(camera.cx, 302.32, 1e-9);
  EXPECT_NEAR(camera.cy, 246.87, 1e-9);
  EXPECT_EQ(camera.k1, 0.0);
  EXPECT_EQ(camera.k2, 0.0);
  // The projection K [R | t] X of the file equals the model's.
  const Eigen::Vector3d world(0.02, 0.05, -0.05);
  for (int i = 0; i < 2; ++i) {
    const Eigen::Matrix3d& r = i == 0 ? r0 : r1;
    const Eigen::Vector3d& t = i == 0 ? t0 : t1;
    const Eigen::Vector3d h = k * (r * world + t);
    const Eigen::Vector2d expected = h.head<2>() / h.z();
    const Eigen::Vector2d got = camera.Project(model->images[i].cam_from_world * world);
    EXPECT_LT((got - expected).norm(), 1e-6) << i;
  }
  EXPECT_EQ(model->images[0].name, "a.png");

  auto list = Project(dir + "/project").ReadImageList();
  ASSERT_TRUE(list.ok()) << list.status().ToString();
  ASSERT_EQ(list->size(), 2u);
  EXPECT_EQ((*list)[1].name, "b.png");
  EXPECT_EQ((*list)[1].path, dir + "/b.png");
  EXPECT_EQ((*list)[1].width, 64);
}

TEST(MiddleburyImportTest, StrideKeepsEveryNthView) {
  const std::string dir = MakeTestDirectory("reconar_middlebury_stride");
  const Eigen::Matrix3d k = Eigen::Vector3d(500.0, 500.0, 1.0).asDiagonal();
  std::string text = "3\n";
  for (const char* name : {"a.png", "b.png", "c.png"}) {
    text += ParLine(name, k, Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 1));
    WriteBlackPng(dir + "/" + name, 8, 8);
  }
  ASSERT_TRUE(WriteFileAtomically(dir + "/s_par.txt", text).ok());
  MiddleburyImportOptions options;
  options.view_stride = 2;
  auto report = ImportMiddleburyProject(dir + "/s_par.txt", dir + "/project", options);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->views, 2);  // a and c
  auto model = ReadColmapTextModel(dir + "/project/sparse");
  ASSERT_TRUE(model.ok());
  ASSERT_EQ(model->images.size(), 2u);
  EXPECT_EQ(model->images[1].name, "c.png");
}

TEST(MiddleburyImportTest, MalformedFilesNameTheLine) {
  const std::string dir = MakeTestDirectory("reconar_middlebury_bad");
  const Eigen::Matrix3d k = Eigen::Vector3d(500.0, 500.0, 1.0).asDiagonal();
  const std::string good = ParLine("a.png", k, Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 1));
  struct Case {
    std::string text;
    StatusCode code;
    std::string needle;
  };
  Eigen::Matrix3d skewed = k;
  skewed(0, 1) = 0.5;
  const Case cases[] = {
      {"", StatusCode::kCorruptData, "empty"},
      {"2\n" + good, StatusCode::kCorruptData, "announces 2"},
      {"1\na.png 1 2 3\n", StatusCode::kCorruptData, ":2:"},
      {"1\n" + ParLine("a.png", k, 2.0 * Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()),
       StatusCode::kCorruptData, "rotation"},
      {"1\n" + ParLine("a.png", skewed, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()),
       StatusCode::kUnsupported, "skew"},
  };
  for (const Case& c : cases) {
    ASSERT_TRUE(WriteFileAtomically(dir + "/bad_par.txt", c.text).ok());
    auto views = ReadMiddleburyParInOrder(dir + "/bad_par.txt");
    ASSERT_FALSE(views.ok()) << c.text;
    EXPECT_EQ(views.status().code(), c.code) << views.status().ToString();
    EXPECT_NE(views.status().ToString().find(c.needle), std::string::npos) << views.status().ToString();
  }
  // A missing image is NotFound, naming it.
  ASSERT_TRUE(WriteFileAtomically(dir + "/bad_par.txt", "1\n" + good).ok());
  auto report = ImportMiddleburyProject(dir + "/bad_par.txt", dir + "/project");
  ASSERT_FALSE(report.ok());
  EXPECT_EQ(report.status().code(), StatusCode::kNotFound) << report.status().ToString();
  EXPECT_NE(report.status().ToString().find("a.png"), std::string::npos);
}

}  // namespace
}  // namespace testing
}  // namespace reconar
