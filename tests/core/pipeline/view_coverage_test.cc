// ViewCoverage (core/pipeline/live_reconstruction.h): the capture's coverage indicator, on cameras
// placed around an object at known azimuths.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/math/rigid3.h"
#include "core/pipeline/live_reconstruction.h"

namespace reconar {
namespace {

// Cameras on a circle of radius 5 about the vertical (+z) through the origin, at the given
// azimuths in degrees, each looking at the origin, upright; a few points about the origin.
Reconstruction CamerasAt(const std::vector<double>& azimuths_deg) {
  Reconstruction model;
  model.cameras.resize(1);
  for (const double azimuth : azimuths_deg) {
    const double a = azimuth * M_PI / 180.0;
    SfmImage image;
    image.registered = true;
    image.cam_from_world = CamFromWorldLookingAt(Eigen::Vector3d(5.0 * std::cos(a), 5.0 * std::sin(a), 0.3),
                                                 Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ());
    model.images.push_back(image);
  }
  for (int k = -2; k <= 2; ++k) {
    SfmPoint point;
    point.position = Eigen::Vector3d(0.1 * k, -0.05 * k, 0.2 * k);
    model.points.push_back(point);
  }
  return model;
}

int Covered(const std::vector<bool>& sectors) {
  int count = 0;
  for (const bool covered : sectors) count += covered ? 1 : 0;
  return count;
}

// Sector k spans 30 k +- 15 degrees from the first camera; these cameras stay 5 degrees or more
// inside the sectors' edges (the mean up direction of a half ring tilts by a degree or two).
TEST(ViewCoverageTest, HalfARingCoversHalfTheSectorsFromTheFirstCamera) {
  const std::vector<double> azimuths = {0, 10, 30, 40, 60, 70, 90, 100, 120, 130, 150, 160};
  const std::vector<bool> coverage = ViewCoverage(CamerasAt(azimuths), 12);
  ASSERT_EQ(coverage.size(), 12u);
  EXPECT_EQ(Covered(coverage), 6);
  for (int s = 0; s < 6; ++s) EXPECT_TRUE(coverage[static_cast<size_t>(s)]) << s;
}

TEST(ViewCoverageTest, AWholeRingCoversEverySector) {
  std::vector<double> azimuths;
  for (double a = 0.0; a < 360.0; a += 15.0) azimuths.push_back(a);
  EXPECT_EQ(Covered(ViewCoverage(CamerasAt(azimuths), 12)), 12);
}

TEST(ViewCoverageTest, OneCameraOrNoPointsCoverNothing) {
  EXPECT_EQ(Covered(ViewCoverage(CamerasAt({30.0}), 12)), 0);
  Reconstruction no_points = CamerasAt({0.0, 40.0, 80.0});
  no_points.points.clear();
  EXPECT_EQ(Covered(ViewCoverage(no_points, 12)), 0);
  EXPECT_TRUE(ViewCoverage(CamerasAt({0.0, 40.0}), 0).empty());
}

}  // namespace
}  // namespace reconar
