#include "core/sfm/next_image.h"

#include <gtest/gtest.h>

#include <vector>

namespace reconar {
namespace {

// Seven images, 0 and 1 registered; tracks 0-9 have points, tracks 10-11 do not. The images
// see (through track_of) these many triangulated points: 2: 5, 3: 8, 4: 1, 5: 8 (but it failed
// with 8 before), 6: 8, with 3 and 6 tied.
MapperModel HandMadeModel() {
  MapperModel model;
  model.rec.cameras.resize(1);
  model.rec.images.resize(7);
  model.rec.images[0].registered = model.rec.images[1].registered = true;
  model.tracks.tracks.resize(12);
  model.tracks.track_of = {
      {0, 1, 2, 3, 4, 5, 6, 7, 8, 9},  // the registered images see all
      {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11},
      {0, 1, 2, 3, 4, 10, -1},
      {0, 1, 2, 3, 4, 5, 6, 7, 11},
      {-1, 0, 10, 11},
      {0, 1, 2, 3, 4, 5, 6, 7},
      {-1, 2, 3, 4, 5, 6, 7, 8, 9, 10},
  };
  model.point_of_track = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, -1, -1};
  model.failure.assign(7, "not connected to the reconstructed images");
  model.tried_with.assign(7, -1);
  model.tried_with[5] = 8;
  return model;
}

// The candidates when 2 points suffice to try.
std::vector<NextImageCandidate> CandidatesOf(MapperModel* model) {
  MapperOptions options;
  options.registration_min_inliers = 2;
  options.registration_min_verified_inliers = 2;
  return NextImageCandidates(model, {}, options);
}

TEST(NextImageTest, MostVisiblePointsFirstTiesByIndex) {
  MapperModel model = HandMadeModel();
  const std::vector<NextImageCandidate> candidates = CandidatesOf(&model);
  ASSERT_EQ(candidates.size(), 3u);
  EXPECT_EQ(candidates[0].image, 3);
  EXPECT_EQ(candidates[0].visible, 8);
  EXPECT_EQ(candidates[1].image, 6);
  EXPECT_EQ(candidates[1].visible, 8);
  EXPECT_EQ(candidates[2].image, 2);
  EXPECT_EQ(candidates[2].visible, 5);
  // Image 4 sees too few, and says so; image 5 keeps its earlier reason.
  EXPECT_EQ(model.failure[4], "sees only 1 reconstructed points (need 2)");
  EXPECT_EQ(model.failure[5], "not connected to the reconstructed images");
}

TEST(NextImageTest, NewPointsMakeAFailedImageACandidateAgain) {
  MapperModel model = HandMadeModel();
  model.tracks.track_of[5].push_back(8);  // image 5 now sees 9 points, more than when it failed
  const std::vector<NextImageCandidate> candidates = CandidatesOf(&model);
  ASSERT_EQ(candidates.size(), 4u);
  EXPECT_EQ(candidates[0].image, 5);
  EXPECT_EQ(candidates[0].visible, 9);
}

TEST(NextImageTest, RegisteredImagesAreNeverCandidates) {
  MapperModel model = HandMadeModel();
  for (SfmImage& image : model.rec.images) image.registered = true;
  EXPECT_TRUE(NextImageCandidates(&model, {}, MapperOptions()).empty());
}

}  // namespace
}  // namespace reconar
