#include "core/mvs/merge_points.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/mvs/dense_memory.h"
#include "core/mvs/undistort.h"

namespace reconar {
namespace {

void Add(MergeInput* part, const Eigen::Vector3f& position, const Eigen::Vector3f& normal, float score,
         float footprint) {
  part->points.positions.push_back(position);
  part->points.normals.push_back(normal);
  part->points.colors.push_back({static_cast<uint8_t>(100 * score), 0, 0});
  part->points.scores.push_back(score);
  part->footprints.push_back(footprint);
}

TEST(MergePoints, DropsDuplicatesWithinOneFootprintAndKeepsTheBetter) {
  const Eigen::Vector3f up = Eigen::Vector3f::UnitZ();
  std::vector<MergeInput> parts(2);
  for (int i = 0; i < 10; ++i) {
    // A row of points 3 footprints apart; the second cluster saw the same surface 0.3 footprint off.
    Add(&parts[0], Eigen::Vector3f(0.03f * i, 0, 0), up, 0.8f, 0.01f);
    Add(&parts[1], Eigen::Vector3f(0.03f * i + 0.003f, 0, 0), up, 0.9f, 0.01f);
  }
  Add(&parts[1], Eigen::Vector3f(0, 0, 0.002f), -up, 0.95f, 0.01f);  // the other side of a thin sheet
  MergeReport report;
  std::vector<float> kept_footprints;
  const OrientedPoints merged = MergeOrientedPoints(parts, &report, &kept_footprints);
  EXPECT_EQ(kept_footprints, std::vector<float>(merged.size(), 0.01f));
  EXPECT_EQ(report.input_points, 21u);
  EXPECT_EQ(report.duplicates_dropped, 10u);
  ASSERT_EQ(merged.size(), 11u);
  for (size_t i = 0; i < merged.size(); ++i) {
    EXPECT_GE(merged.scores[i], 0.9f);  // the better-scored copy survived
    EXPECT_EQ(merged.colors[i][0], static_cast<uint8_t>(100 * merged.scores[i]));
  }
}

// Merging a merged result again, with the footprints it reports, changes nothing: the dense stage
// relies on it for a single thinned cluster.
TEST(MergePoints, MergingAMergedResultAgainKeepsIt) {
  const Eigen::Vector3f up = Eigen::Vector3f::UnitZ();
  std::vector<MergeInput> parts(1);
  for (int i = 0; i < 200; ++i) {
    const float t = 0.37f * static_cast<float>(i);
    Add(&parts[0], Eigen::Vector3f(0.004f * std::cos(t) * i / 20, 0.004f * std::sin(t) * i / 20, 0.0f),
        i % 7 == 0 ? -up : up, 0.5f + 0.002f * static_cast<float>(i % 13), 0.005f + 0.0001f * (i % 5));
  }
  std::vector<MergeInput> once(1);
  once[0].points = MergeOrientedPoints(parts, nullptr, &once[0].footprints);
  ASSERT_LT(once[0].points.size(), parts[0].points.size());
  MergeReport report;
  const OrientedPoints twice = MergeOrientedPoints(once, &report);
  EXPECT_EQ(report.duplicates_dropped, 0u);
  EXPECT_EQ(twice.positions, once[0].points.positions);
  EXPECT_EQ(twice.scores, once[0].points.scores);
}

TEST(MergePoints, PixelFootprintIsDepthOverFocalInTheClosestView) {
  DenseView near, far;
  for (DenseView* view : {&near, &far}) {
    view->gray = Image<uint8_t>(100, 100, 1);
    view->fx = view->fy = 200.0;
    view->cx = view->cy = 49.5;
  }
  near.cam_from_world.translation = Eigen::Vector3d(0, 0, 2);
  far.cam_from_world.translation = Eigen::Vector3d(0, 0, 8);
  EXPECT_FLOAT_EQ(PixelFootprint({&far, &near}, Eigen::Vector3f::Zero()), 2.0f / 200.0f);
  EXPECT_EQ(PixelFootprint({&far, &near}, Eigen::Vector3f(0, 0, -10)), 0.0f);  // behind both
}

// 30 photos of 6 megapixels, clusters of 20, 2 threads.
DenseMemoryInput ThirtyPhotos() {
  DenseMemoryInput input;
  input.image_sizes.assign(30, {3072, 2048});
  input.max_cluster_size = 20;
  input.num_threads = 2;
  return input;
}

TEST(DenseMemory, FinestLevelThatFitsThenSmallerClusters) {
  const DenseMemoryInput input = ThirtyPhotos();
  const size_t level0 = EstimateDenseBytes(input, 0, 20);
  const size_t level1 = EstimateDenseBytes(input, 1, 20);
  const size_t level2 = EstimateDenseBytes(input, 2, 20);
  EXPECT_GT(level0, 3 * level1);
  EXPECT_GT(level1, 2 * level2);
  auto choice = ChooseDenseLevel(input, -1, level0, 3);
  ASSERT_TRUE(choice.ok());
  EXPECT_EQ(choice->level, 0);
  choice = ChooseDenseLevel(input, -1, level0 - 1, 3);
  ASSERT_TRUE(choice.ok());
  EXPECT_EQ(choice->level, 1);
  choice = ChooseDenseLevel(input, -1, level2 - 1, 3);
  ASSERT_TRUE(choice.ok());
  EXPECT_EQ(choice->level, 2);
  EXPECT_TRUE(choice->reduced_cluster_size);
  EXPECT_EQ(choice->max_cluster_size, 19);
  choice = ChooseDenseLevel(input, 0, level1, 3);  // a fixed level keeps the level, shrinks clusters
  ASSERT_TRUE(choice.ok());
  EXPECT_EQ(choice->level, 0);
  EXPECT_LT(choice->max_cluster_size, 20);
  EXPECT_EQ(ChooseDenseLevel(input, -1, 1 << 20, 3).status().code(), StatusCode::kResourceExhausted);
  EXPECT_EQ(ChooseDenseLevel(input, 3, level0, 3).status().code(), StatusCode::kInvalidArgument);
}

TEST(DenseMemory, TheAutomaticLevelKeepsTheLongestSideWithinTheLimit) {
  const std::vector<std::pair<int, int>> fountain(11, {3072, 2048});
  EXPECT_EQ(FinestLevelWithinSize(fountain, 0), 0);
  EXPECT_EQ(FinestLevelWithinSize(fountain, 3072), 0);
  EXPECT_EQ(FinestLevelWithinSize(fountain, 2400), 1);
  EXPECT_EQ(FinestLevelWithinSize(fountain, 1000), 2);
  EXPECT_EQ(FinestLevelWithinSize(fountain, 100), kMaxDenseLevel);       // the coarsest when none fits
  EXPECT_EQ(FinestLevelWithinSize({{640, 480}, {480, 3000}}, 2400), 1);  // portrait photos count their height
  DenseMemoryInput input = ThirtyPhotos();
  input.max_image_size = 2400;
  const size_t plenty = EstimateDenseBytes(input, 0, 30) * 2;
  auto choice = ChooseDenseLevel(input, -1, plenty, 3);
  ASSERT_TRUE(choice.ok());
  EXPECT_EQ(choice->level, 1);
  EXPECT_EQ(choice->finest_level_within_size, 1);
  choice = ChooseDenseLevel(input, 0, plenty, 3);  // a given level is kept
  ASSERT_TRUE(choice.ok());
  EXPECT_EQ(choice->level, 0);
}

TEST(DenseMemory, ClustersGrowToWhatTheBudgetHolds) {
  const DenseMemoryInput input = ThirtyPhotos();
  const size_t level1_of_25 = EstimateDenseBytes(input, 1, 25);
  auto choice = ChooseDenseLevel(input, -1, level1_of_25, 3);
  ASSERT_TRUE(choice.ok());
  ASSERT_EQ(choice->level, 1);
  const DenseLevelChoice grown = GrowClusterToBudget(input, *choice, level1_of_25);
  EXPECT_EQ(grown.level, 1);
  EXPECT_EQ(grown.max_cluster_size, 25);
  EXPECT_EQ(grown.estimated_bytes, level1_of_25);
  EXPECT_EQ(GrowClusterToBudget(input, *choice, EstimateDenseBytes(input, 1, 30) * 2).max_cluster_size, 30);
  // A cluster size already reduced for the budget stays.
  auto reduced = ChooseDenseLevel(input, 0, EstimateDenseBytes(input, 0, 10), 3);
  ASSERT_TRUE(reduced.ok() && reduced->reduced_cluster_size);
  EXPECT_EQ(GrowClusterToBudget(input, *reduced, EstimateDenseBytes(input, 0, 10)).max_cluster_size,
            reduced->max_cluster_size);
}

}  // namespace
}  // namespace reconar
