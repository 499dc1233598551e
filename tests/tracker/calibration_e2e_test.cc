// End-to-end calibration on real photos: the 72 iPhone 4S photos of the swatbotics AprilTag
// mapping shoot (../shared/data/apriltag_swatbotics_mapping, SOURCE.txt): 20 wall tags
// (tag36h11, edge 0.127 m), 816x612. Tags are detected with TagDetector (decimate 1), each tag
// instance is its own planar target, and the result is compared with the upstream author's
// checkerboard calibration of the same camera (calibration/calib.txt: fx 765.00, fy 764.18,
// cx 393.72, cy 304.66, no distortion given), which nobody here wrote.
//
// The bar, fixed before the first run (not tuned to the result): two independent calibrations of
// the same camera by different methods and photo sets typically agree to about 2 % in focal length
// and 2 % of the image size in the principal point, so
//   |fx - 765.00| <= 2 % of 765.00, |fy - 764.18| <= 2 % of 764.18,
//   |cx - 393.72| <= 2 % of 816,    |cy - 304.66| <= 2 % of 612,
// and the RMS reprojection error below 1 px (sub-pixel corners on a correct model).
// The checkerboard values carry no stated uncertainty; the distance in units of our own sigma is
// printed for information only.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/io/gray.h"
#include "core/io/image_io.h"
#include "tests/support/ground_truth.h"
#include "tracker/calibration.h"
#include "tracker/tag_detector.h"

namespace reconar {
namespace {

const std::string kDataDir = std::string(RECONAR_SHARED_DATA_DIR) + "/apriltag_swatbotics_mapping";

struct Detected {
  CalibrationObservations observations;
  int instances = 0;
  int false_ids = 0;  // detected ids the upstream list does not have for that image
};

Detected DetectAll() {
  Detected detected;
  detected.observations.tag_size = 0.127;
  auto listed = testing::ReadListedTagIds(kDataDir + "/groundtruth.txt");
  EXPECT_TRUE(listed.ok()) << listed.status().ToString();
  if (!listed.ok()) return detected;
  const std::map<std::string, std::set<int>>& visible = *listed;
  EXPECT_EQ(visible.size(), 72u);
  TagDetectorOptions options;
  options.family = TagFamily::kTag36h11;
  options.quad_decimate = 1.0f;
  Result<std::unique_ptr<TagDetector>> detector = TagDetector::Create(options);
  EXPECT_TRUE(detector.ok()) << detector.status().ToString();
  if (!detector.ok()) return detected;
  TagDetectionList detections(64);
  for (const auto& [name, ids] : visible) {
    Result<DecodedImage> image = ReadImage(kDataDir + "/" + name);
    EXPECT_TRUE(image.ok()) << image.status().ToString();
    if (!image.ok()) continue;
    const Image<uint8_t> gray = ToGray8(image->rgb);
    EXPECT_TRUE((*detector)->Detect(gray.view(), &detections).ok());
    for (const TagDetection& detection : detections) {
      ++detected.instances;
      detected.false_ids += ids.count(detection.id) == 0 ? 1 : 0;
    }
    detected.observations.images.push_back(MakeCalibrationImage(name, gray.width(), gray.height(), detections));
  }
  return detected;
}

void Print(const char* label, const CalibrationReport& r) {
  std::printf(
      "%s:\n  fx %.2f +- %.2f  fy %.2f +- %.2f  cx %.2f +- %.2f  cy %.2f +- %.2f  k1 %.4f +- %.4f  k2 %.4f +- %.4f\n"
      "  rms %.3f px (closed form: fx %.1f fy %.1f cx %.1f cy %.1f, rms %.2f px, principal point %s)\n"
      "  %d targets, %d corners, %d images, %d iterations, converged %d\n",
      label, r.intrinsics.fx, r.stddev[0], r.intrinsics.fy, r.stddev[1], r.intrinsics.cx, r.stddev[2],
      r.intrinsics.cy, r.stddev[3], r.intrinsics.k1, r.stddev[4], r.intrinsics.k2, r.stddev[5], r.rms_px,
      r.closed_form.fx, r.closed_form.fy, r.closed_form.cx, r.closed_form.cy, r.initial_rms_px,
      r.principal_point_from_closed_form ? "estimated" : "at the centre", r.num_targets, r.num_corners,
      r.num_images_used, r.iterations, r.converged ? 1 : 0);
  const double truth[4] = {765.00, 764.18, 393.72, 304.66};
  const double values[4] = {r.intrinsics.fx, r.intrinsics.fy, r.intrinsics.cx, r.intrinsics.cy};
  const char* names[4] = {"fx", "fy", "cx", "cy"};
  for (int j = 0; j < 4; ++j) {
    std::printf("  %s - checkerboard = %+.2f px (%+.2f %% of %s, %.1f sigma)\n", names[j], values[j] - truth[j],
                100.0 * (values[j] - truth[j]) / (j < 2 ? truth[j] : (j == 2 ? 816.0 : 612.0)),
                j < 2 ? "the focal" : "the image size", std::abs(values[j] - truth[j]) / r.stddev[j]);
  }
}

TEST(CalibrationE2eTest, SwatboticsIphoneAgreesWithCheckerboardCalibration) {
  const Detected detected = DetectAll();
  std::printf("detected %d tag instances in %zu images (upstream list: 236), %d ids not in the list\n",
              detected.instances, detected.observations.images.size(), detected.false_ids);
  EXPECT_EQ(detected.false_ids, 0);
  ASSERT_GE(detected.instances, 200);

  Result<CalibrationReport> report = CalibrateIntrinsics(detected.observations, CalibrationOptions());
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  Print("fx fy cx cy k1 k2 (default options)", *report);
  EXPECT_TRUE(report->converged);
  EXPECT_EQ(report->intrinsics.width, 816);
  EXPECT_EQ(report->intrinsics.height, 612);
  EXPECT_NEAR(report->intrinsics.fx, 765.00, 0.02 * 765.00);
  EXPECT_NEAR(report->intrinsics.fy, 764.18, 0.02 * 764.18);
  EXPECT_NEAR(report->intrinsics.cx, 393.72, 0.02 * 816);
  EXPECT_NEAR(report->intrinsics.cy, 304.66, 0.02 * 612);
  EXPECT_LT(report->rms_px, 1.0);

  // For information: the checkerboard model has no distortion; the same fit without k1, k2.
  CalibrationOptions pinhole;
  pinhole.estimate_k1 = pinhole.estimate_k2 = false;
  Result<CalibrationReport> without_distortion = CalibrateIntrinsics(detected.observations, pinhole);
  if (without_distortion.ok()) Print("fx fy cx cy (k1 = k2 = 0)", *without_distortion);
}

}  // namespace
}  // namespace reconar
