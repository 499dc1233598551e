// PaintOutTags on synthetic frames (tests/tracker/synthetic_tag_image.h): tilted tags drawn with
// their white border on a uniform background, detected, painted out. Afterwards no tag is found
// and every pixel is either the background or a tag's fill: nothing of the printed tag is left.
#include "tests/support/tag_paint.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>

#include "tests/tracker/synthetic_tag_image.h"

namespace reconar {
namespace {

constexpr uint8_t kBackground = 170;

Image<uint8_t> ToRgb(const Image<uint8_t>& gray) {
  Image<uint8_t> rgb(gray.width(), gray.height(), 3);
  for (int y = 0; y < gray.height(); ++y) {
    for (int x = 0; x < gray.width(); ++x) {
      for (int c = 0; c < 3; ++c) rgb.row(y)[3 * x + c] = gray.row(y)[x];
    }
  }
  return rgb;
}

Image<uint8_t> RedChannel(const Image<uint8_t>& rgb) {
  Image<uint8_t> gray(rgb.width(), rgb.height());
  for (int y = 0; y < rgb.height(); ++y) {
    for (int x = 0; x < rgb.width(); ++x) gray.row(y)[x] = rgb.row(y)[3 * x];
  }
  return gray;
}

std::vector<TagDetection> Detect(const Image<uint8_t>& gray) {
  TagDetectorOptions options;
  options.quad_decimate = 1.0f;
  auto detector = TagDetector::Create(options);
  EXPECT_TRUE(detector.ok());
  TagDetectionList list(16);
  EXPECT_TRUE((*detector)->Detect(gray.view(), &list).ok());
  return std::vector<TagDetection>(list.begin(), list.end());
}

// The grey values left in `rgb`, with R = G = B checked for every pixel.
std::set<int> Values(const Image<uint8_t>& rgb) {
  std::set<int> values;
  for (int y = 0; y < rgb.height(); ++y) {
    for (int x = 0; x < rgb.width(); ++x) {
      const uint8_t* p = rgb.row(y) + 3 * x;
      EXPECT_TRUE(p[0] == p[1] && p[1] == p[2]);
      values.insert(p[0]);
    }
  }
  return values;
}

TEST(TagPaint, TiltedTagsLeaveNothingOfTheirPrint) {
  const CameraIntrinsics camera = testing::TestCamera();
  const testing::SyntheticTag tags[2] = {testing::TiltedTag(3, Eigen::Vector3d(-0.12, 0.0, 0.6), 35.0),
                                         testing::TiltedTag(11, Eigen::Vector3d(0.14, 0.03, 0.5), -40.0)};
  testing::SyntheticRenderOptions render;
  render.background = kBackground;
  render.blur_sigma = 0.8;
  const Image<uint8_t> gray = testing::RenderTags(tags, 2, camera, render);
  const std::vector<TagDetection> detections = Detect(gray);
  ASSERT_EQ(detections.size(), 2u);
  Image<uint8_t> rgb = ToRgb(gray);
  testing::PaintOutTags(detections, &rgb);
  EXPECT_TRUE(Detect(RedChannel(rgb)).empty());
  // The background (within the blur's last grey level beyond the painted margin) and one fill per
  // tag: the white border and its blurred edge are covered.
  std::set<int> fills;
  for (int value : Values(rgb)) {
    if (std::abs(value - kBackground) > 1) fills.insert(value);
  }
  EXPECT_EQ(fills.size(), 2u);
}

TEST(TagPaint, QuadsBeyondTheImageAndDegenerateDetectionsAreClipped) {
  const CameraIntrinsics camera = testing::TestCamera();
  // Detected in the whole frame, then painted on a crop that cuts through the tag.
  const testing::SyntheticTag tag = testing::TiltedTag(5, Eigen::Vector3d(0.0, 0.0, 0.5), 10.0);
  testing::SyntheticRenderOptions render;
  render.background = kBackground;
  const Image<uint8_t> gray = testing::RenderTags(&tag, 1, camera, render);
  const std::vector<TagDetection> detections = Detect(gray);
  ASSERT_EQ(detections.size(), 1u);
  Image<uint8_t> crop(camera.width / 2, camera.height / 2);
  for (int y = 0; y < crop.height(); ++y) {
    for (int x = 0; x < crop.width(); ++x) crop.row(y)[x] = gray.row(y)[x];
  }
  Image<uint8_t> rgb = ToRgb(crop);
  testing::PaintOutTags(detections, &rgb);
  EXPECT_LE(Values(rgb).size(), 2u);

  // A detection with no finite geometry paints nothing.
  TagDetection broken = detections[0];
  const double nan = std::numeric_limits<double>::quiet_NaN();
  broken.homography.setConstant(nan);
  for (Eigen::Vector2d& corner : broken.corners) corner.setConstant(nan);
  broken.center.setConstant(nan);
  Image<uint8_t> untouched = ToRgb(gray);
  testing::PaintOutTags({broken}, &untouched);
  const Image<uint8_t> original = ToRgb(gray);
  for (int y = 0; y < gray.height(); ++y) {
    for (int x = 0; x < 3 * gray.width(); ++x) ASSERT_EQ(untouched.row(y)[x], original.row(y)[x]);
  }
}

}  // namespace
}  // namespace reconar
