// templeRing's ground-truth cameras imported as a project and read back through the COLMAP text
// reader: the README's tight bounding box of the temple must project into every image, around
// its middle, in front of the camera, and enclose the bright plaster in the photograph (the
// background is black cloth and a dark stand).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "core/io/image_io.h"

#include "core/pipeline/project.h"
#include "core/sfm/model_io.h"
#include "tests/dense/dense_runs.h"
#include "tests/dense/middlebury_import.h"
#include "tests/support/run_command.h"

namespace reconar {
namespace testing {
namespace {

const std::string kParPath = std::string(RECONAR_SHARED_DATA_DIR) + "/middlebury_templeRing/templeR_par.txt";

TEST(TempleRingImportTest, BoundingBoxProjectsIntoEveryView) {
  const std::string dir = MakeTestDirectory("reconar_templering_import");
  auto report = ImportMiddleburyProject(kParPath, dir);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->views, 47);
  EXPECT_EQ(report->cameras, 1);

  auto model = ReadColmapTextModel(dir + "/sparse");
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  ASSERT_EQ(model->images.size(), 47u);
  EXPECT_EQ(model->points.size(), 0u);
  const SfmCamera& camera = model->cameras[0];
  EXPECT_EQ(camera.width, 640);
  EXPECT_EQ(camera.height, 480);
  auto list = Project(dir).ReadImageList();
  ASSERT_TRUE(list.ok()) << list.status().ToString();
  ASSERT_EQ(list->size(), 47u);

  const Box3 box = TempleRingBoundingBox();
  for (const SfmImage& image : model->images) {
    const Eigen::Vector2d center = camera.Project(image.cam_from_world * (0.5 * (box.min + box.max)));
    EXPECT_NEAR(center.x(), 320.0, 80.0) << image.name;
    EXPECT_NEAR(center.y(), 240.0, 80.0) << image.name;
    Eigen::Vector2d lo = Eigen::Vector2d::Constant(INFINITY), hi = -lo;
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d world((corner & 1) ? box.max.x() : box.min.x(), (corner & 2) ? box.max.y() : box.min.y(),
                                  (corner & 4) ? box.max.z() : box.min.z());
      const Eigen::Vector3d cam = image.cam_from_world * world;
      ASSERT_GT(cam.z(), 0.3) << image.name;
      const Eigen::Vector2d pixel = camera.Project(cam);
      lo = lo.cwiseMin(pixel);
      hi = hi.cwiseMax(pixel);
    }
    // Bright pixels (plaster) outside the rectangle around the projected box, 2 px margin for
    // blur: the box is tight around the temple, so a wrong pose or convention shows here.
    auto photo = ReadImage((*list)[&image - model->images.data()].path);
    ASSERT_TRUE(photo.ok()) << photo.status().ToString();
    int bright = 0, bright_outside = 0;
    for (int y = 0; y < photo->rgb.height(); ++y) {
      for (int x = 0; x < photo->rgb.width(); ++x) {
        const uint8_t* p = photo->rgb.row(y) + 3 * x;
        if ((p[0] + p[1] + p[2]) / 3 < 100) continue;
        ++bright;
        bright_outside += (x < lo.x() - 2 || x > hi.x() + 2 || y < lo.y() - 2 || y > hi.y() + 2) ? 1 : 0;
      }
    }
    ASSERT_GT(bright, 10000) << image.name;
    EXPECT_LT(bright_outside, 0.005 * bright) << image.name << ": " << bright_outside << " of " << bright;
  }
}

}  // namespace
}  // namespace testing
}  // namespace reconar
