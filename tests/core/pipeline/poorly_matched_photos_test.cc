// Which photos the match stage extracts again (PhotosToExtractAgain), on the verified partners and
// feature counts the default extraction gave real photo sets: dinoSparseRing (a plaster figure on
// black velvet, 16 views), templeSparseRing (16 views, every one with at least two partners), both
// in one folder, and a textured set with one unrelated photo.
#include <gtest/gtest.h>

#include <vector>

#include "core/pipeline/match_stage.h"

namespace reconar {
namespace {

using Reason = ReextractionReason;

// `reconar sfm` with the default extraction (Lowe's 0.04, first octave -1), views 1-16.
const std::vector<int> kDinoPartners = {2, 3, 2, 1, 0, 0, 1, 3, 3, 3, 3, 1, 0, 0, 0, 2};
const std::vector<int> kDinoFeatures = {146, 163, 173, 149, 111, 125, 194, 210, 215, 231, 214, 191, 124, 88, 102, 136};
const std::vector<int> kTemplePartners = {3, 3, 2, 3, 2, 3, 3, 3, 3, 4, 3, 2, 3, 2, 2, 3};
const std::vector<int> kTempleFeatures = {838, 825, 824, 691, 887, 956, 792, 913, 973, 985, 855, 1048, 1088, 896, 990, 1027};

TEST(PoorlyMatchedPhotosTest, AWellMatchedSetKeepsItsFeatures) {
  for (const Reason reason : PhotosToExtractAgain(kTemplePartners, kTempleFeatures, 2)) EXPECT_EQ(reason, Reason::kNone);
}

// The median view has 1.5 partners: every view is extracted again.
TEST(PoorlyMatchedPhotosTest, ASetWhoseMedianPhotoMatchesPoorlyIsExtractedAgainWhole) {
  for (const Reason reason : PhotosToExtractAgain(kDinoPartners, kDinoFeatures, 2))
    EXPECT_EQ(reason, Reason::kTheSetMatchesPoorly);
}

// Mixed, the dino's poorly matched views (under the set's median count) mark as texture-poor every
// view with no more features than the richest of them (194): 12 dino views, no temple view.
TEST(PoorlyMatchedPhotosTest, TexturePoorPhotosAmongTexturedOnesAreFoundByTheirPoorlyMatchedLikes) {
  std::vector<int> partners = kTemplePartners, features = kTempleFeatures;
  partners.insert(partners.end(), kDinoPartners.begin(), kDinoPartners.end());
  features.insert(features.end(), kDinoFeatures.begin(), kDinoFeatures.end());
  const std::vector<Reason> reasons = PhotosToExtractAgain(partners, features, 2);
  for (size_t i = 0; i < 16; ++i) EXPECT_EQ(reasons[i], Reason::kNone) << "temple view " << i + 1;
  int again = 0;
  for (size_t i = 16; i < 32; ++i) {
    const Reason expected = kDinoPartners[i - 16] < 2 ? Reason::kPoorlyMatched
                            : kDinoFeatures[i - 16] <= 194 ? Reason::kAsTexturePoor
                                                           : Reason::kNone;
    EXPECT_EQ(reasons[i], expected) << "dino view " << i - 15;
    again += reasons[i] != Reason::kNone;
  }
  EXPECT_EQ(again, 12);
}

// An unrelated photo with as many features as the others matches nothing: it alone is extracted
// again (the rest of the set would gain nothing from it).
TEST(PoorlyMatchedPhotosTest, AnUnrelatedPhotoIsExtractedAgainAlone) {
  std::vector<int> partners = kTemplePartners, features = kTempleFeatures;
  partners.push_back(0);
  features.push_back(1500);
  const std::vector<Reason> reasons = PhotosToExtractAgain(partners, features, 2);
  for (size_t i = 0; i < 16; ++i) EXPECT_EQ(reasons[i], Reason::kNone);
  EXPECT_EQ(reasons[16], Reason::kPoorlyMatched);
  EXPECT_NE(ReextractionReasonText(reasons[16], 0, 2).find("need 2"), std::string::npos);
}

TEST(PoorlyMatchedPhotosTest, OffWithNoPartnersAsked) {
  for (const Reason reason : PhotosToExtractAgain(kDinoPartners, kDinoFeatures, 0)) EXPECT_EQ(reason, Reason::kNone);
}

}  // namespace
}  // namespace reconar
