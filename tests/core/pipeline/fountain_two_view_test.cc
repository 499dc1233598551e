// End to end on real photos with independent ground truth: Strecha fountain-P11 images 0004 and
// 0005 (CVPR 2008 benchmark; cameras in gt_cameras/). Every verified match should lie on the
// epipolar line the ground-truth cameras predict.
#include <gtest/gtest.h>

#include "core/features/matcher.h"
#include "core/features/sift/sift.h"
#include "core/io/image_io.h"
#include "core/pipeline/match_stage.h"
#include "tests/support/ground_truth.h"

namespace reconar {
namespace {

using testing::SharedDataPath;

SiftFeatures Extract(const std::string& path, int* width, int* height) {
  auto decoded = ReadImage(path);
  EXPECT_TRUE(decoded.ok()) << decoded.status().ToString();
  if (!decoded.ok()) return {};
  const Image<float> gray = ToGrayFloat(decoded->rgb);
  *width = gray.width();
  *height = gray.height();
  SiftExtractor sift(SiftOptions{});  // defaults: first octave -1, as the issue asks
  auto features = sift.Extract(gray.view());
  EXPECT_TRUE(features.ok()) << features.status().ToString();
  return features.ok() ? std::move(features).value() : SiftFeatures{};
}

TEST(FountainTwoView, VerifiedMatchesLieOnGroundTruthEpipolarLines) {
  const std::string dir = "strecha_fountain-P11/";
  auto camera_a = testing::ReadStrechaCamera(SharedDataPath(dir + "gt_cameras/0004.jpg.camera"));
  auto camera_b = testing::ReadStrechaCamera(SharedDataPath(dir + "gt_cameras/0005.jpg.camera"));
  ASSERT_TRUE(camera_a.ok()) << camera_a.status().ToString();
  ASSERT_TRUE(camera_b.ok()) << camera_b.status().ToString();
  int wa = 0, ha = 0, wb = 0, hb = 0;
  const SiftFeatures a = Extract(SharedDataPath(dir + "images/0004.jpg"), &wa, &ha);
  const SiftFeatures b = Extract(SharedDataPath(dir + "images/0005.jpg"), &wb, &hb);
  ASSERT_EQ(wa, camera_a->width);
  ASSERT_EQ(hb, camera_b->height);

  MatchOptions match_options;  // ratio 0.6, 4 trees, 200 checks
  auto putative = MatchDescriptors(a.descriptors.data(), static_cast<int>(a.keypoints.size()), b.descriptors.data(),
                                   static_cast<int>(b.keypoints.size()), match_options);
  ASSERT_TRUE(putative.ok());
  auto verified = VerifyMatches(a, wa, ha, b, wb, hb, *putative, TwoViewOptions{});
  ASSERT_TRUE(verified.ok());
  EXPECT_EQ(verified->geometry.config, TwoViewGeometry::Config::kVerified);

  const Eigen::Matrix3d F = testing::FundamentalFromCameras(*camera_a, *camera_b);
  int within_2px = 0;
  for (const FeatureMatch& m : verified->inlier_matches) {
    const SiftKeypoint& ka = a.keypoints[m.index_a];
    const SiftKeypoint& kb = b.keypoints[m.index_b];
    if (testing::SymmetricEpipolarDistance(F, {ka.x, ka.y}, {kb.x, kb.y}) <= 2.0) ++within_2px;
  }
  const int total = static_cast<int>(verified->inlier_matches.size());
  const double fraction = total > 0 ? static_cast<double>(within_2px) / total : 0.0;
  std::printf("fountain 0004-0005: %zu/%zu features, %d putative, %d verified, %d within 2 px of the "
              "ground-truth epipolar lines (%.2f %%)\n",
              a.keypoints.size(), b.keypoints.size(), verified->num_putative, total, within_2px, 100 * fraction);
  EXPECT_GE(within_2px, 1800);
  EXPECT_GE(fraction, 0.98);
}

}  // namespace
}  // namespace reconar
