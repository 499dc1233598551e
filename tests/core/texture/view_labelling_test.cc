// The per-face choices of texturing on hand-made candidate tables: the photo-consistency check,
// the data term's pull towards what most photos show, and a patch's offset towards their median.
#include "core/texture/view_labelling.h"

#include <gtest/gtest.h>

#include <cmath>

namespace reconar {
namespace {

FaceCandidate Grey(int face, int photo, float level) {
  FaceCandidate candidate;
  candidate.face = face;
  candidate.photo = photo;
  candidate.area = 100.0f;
  candidate.sharpness = 1.0f;
  candidate.colour = {level, level, level};
  return candidate;
}

// One face seen by five photos as grey levels 100, 105, 110, 115 and 140.
FaceCandidateTable FiveViewsOfOneFace() {
  std::vector<std::vector<FaceCandidate>> per_photo;
  const float levels[5] = {100.0f, 105.0f, 110.0f, 115.0f, 140.0f};
  for (int p = 0; p < 5; ++p) per_photo.push_back({Grey(0, p, levels[p])});
  return GroupByFace(1, per_photo);
}

TEST(ViewLabellingTest, TheOutlierGoesAndTheOthersWeighByTheirDistanceFromTheMedian) {
  FaceCandidateTable table = FiveViewsOfOneFace();
  // Distances from the median (110) are sqrt(3) times the level difference: 17.3, 8.7, 0, 8.7 and
  // 52.0; their robust sigma 1.4826 * 8.7 = 12.8 puts the limit at max(30, 3 * 12.8) = 38.5.
  EXPECT_EQ(DropInconsistentCandidates(&table), 1u);
  ASSERT_EQ(table.candidates.size(), 4u);
  WeighCandidates(&table);
  for (const FaceCandidate& candidate : table.candidates) {
    const double distance = std::sqrt(3.0) * std::abs(candidate.colour[0] - 110.0);
    const double off = distance / kMinColourDistance;
    EXPECT_NEAR(candidate.quality, 100.0 / (1.0 + off * off), 1e-3) << "photo " << candidate.photo;
  }
  LabellingReport report;
  const std::vector<int> labels = LabelFaces(table, {{-1, -1, -1}}, 0.3, 10, &report);
  EXPECT_EQ(labels[0], 2);  // the photo that shows the median
}

TEST(ViewLabellingTest, APatchIsPulledTowardsTheMedianOfItsPhotos) {
  // Two faces, each seen by photos 0, 1, 2; the patch takes photo 0, darker by 10 and 30 than the
  // median on the two faces: its consensus offset is their mean, +20.
  std::vector<std::vector<FaceCandidate>> per_photo(3);
  per_photo[0] = {Grey(0, 0, 90.0f), Grey(1, 0, 20.0f)};
  per_photo[1] = {Grey(0, 1, 100.0f), Grey(1, 1, 50.0f)};
  per_photo[2] = {Grey(0, 2, 104.0f), Grey(1, 2, 60.0f)};
  const FaceCandidateTable table = GroupByFace(2, per_photo);
  TexturePatches patches;
  patches.patch_of_face = {0, 0};
  patches.photo = {0};
  patches.faces = {{0, 1}};
  const PatchConsensus consensus = FindPatchConsensus(table, patches);
  ASSERT_EQ(consensus.faces.size(), 1u);
  EXPECT_EQ(consensus.faces[0], 2u);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(consensus.offset[0][c], 20.0f, 1e-4);
}

TEST(ViewLabellingTest, FacesSeenByFewerThanThreePhotosHaveNoConsensus) {
  std::vector<std::vector<FaceCandidate>> per_photo(2);
  per_photo[0] = {Grey(0, 0, 90.0f)};
  per_photo[1] = {Grey(0, 1, 150.0f)};
  const FaceCandidateTable table = GroupByFace(1, per_photo);
  TexturePatches patches;
  patches.patch_of_face = {0};
  patches.photo = {1};
  patches.faces = {{0}};
  const PatchConsensus consensus = FindPatchConsensus(table, patches);
  EXPECT_EQ(consensus.faces[0], 0u);
  EXPECT_EQ(consensus.offset[0], Eigen::Vector3f::Zero());
}

}  // namespace
}  // namespace reconar
