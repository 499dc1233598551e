#include "core/features/pair_selection.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/base/prng.h"
#include "core/features/descriptor_distance.h"

namespace reconar {
namespace {

// Images of `places` places, image i showing place i % places: each place has its own random
// descriptors, each image a random 70 % of its place's, with noise of a few grey levels.
struct PlaceImages {
  std::vector<std::vector<uint8_t>> descriptors;  // per image
  std::vector<int> place;
};

PlaceImages MakePlaceImages(int num_images, int places, int per_place, uint64_t seed) {
  SplitMix64 rng(seed);
  std::vector<std::vector<uint8_t>> place_descriptors(static_cast<size_t>(places));
  for (std::vector<uint8_t>& place : place_descriptors) {
    for (int k = 0; k < per_place * kDescriptorSize; ++k) place.push_back(static_cast<uint8_t>(rng.UniformInt(256)));
  }
  PlaceImages images;
  for (int i = 0; i < num_images; ++i) {
    const std::vector<uint8_t>& place = place_descriptors[static_cast<size_t>(i % places)];
    std::vector<uint8_t> descriptors;
    for (int d = 0; d < per_place; ++d) {
      if (rng.Uniform01() > 0.7) continue;
      for (int c = 0; c < kDescriptorSize; ++c) {
        const double noisy = place[static_cast<size_t>(d * kDescriptorSize + c)] + rng.Uniform(-4.0, 4.0);
        descriptors.push_back(static_cast<uint8_t>(std::clamp(std::lround(noisy), 0l, 255l)));
      }
    }
    images.descriptors.push_back(std::move(descriptors));
    images.place.push_back(i % places);
  }
  return images;
}

std::vector<std::vector<int>> SelectAll(const PlaceImages& images, const PairSelectionOptions& options) {
  Result<PairSelector> selector = PairSelector::Create(options);
  EXPECT_TRUE(selector.ok()) << selector.status().ToString();
  std::vector<std::vector<int>> partners;
  for (const std::vector<uint8_t>& descriptors : images.descriptors) {
    Result<std::vector<int>> chosen =
        selector->Add(descriptors.data(), static_cast<int>(descriptors.size() / kDescriptorSize));
    EXPECT_TRUE(chosen.ok()) << chosen.status().ToString();
    partners.push_back(chosen.ok() ? *chosen : std::vector<int>{});
  }
  return partners;
}

PairSelectionOptions SmallRule() {
  PairSelectionOptions options;
  options.exhaustive_up_to = 8;
  options.sequential_window = 2;
  options.retrieved = 3;
  options.vocabulary.depth = 3;
  return options;
}

TEST(PairSelection, EveryPairUpToTheLimitThenWindowPlusRetrieval) {
  const PlaceImages images = MakePlaceImages(40, 6, 300, 11);
  const PairSelectionOptions options = SmallRule();
  const std::vector<std::vector<int>> partners = SelectAll(images, options);
  for (int i = 0; i < 40; ++i) {
    const std::vector<int>& mine = partners[static_cast<size_t>(i)];
    ASSERT_TRUE(std::is_sorted(mine.begin(), mine.end())) << "image " << i;
    ASSERT_TRUE(std::adjacent_find(mine.begin(), mine.end()) == mine.end()) << "image " << i;
    if (i < options.exhaustive_up_to) {
      EXPECT_EQ(static_cast<int>(mine.size()), i) << "image " << i;
      continue;
    }
    // The window, then `retrieved` images from before it: every earlier image of the same place
    // when there are at most that many, else only images of the same place.
    ASSERT_EQ(mine.size(), 5u) << "image " << i;
    EXPECT_EQ(mine[3], i - 2);
    EXPECT_EQ(mine[4], i - 1);
    std::vector<int> same_place, retrieved_same_place;
    for (int other = i - 6; other >= 0; other -= 6) same_place.push_back(other);
    for (int k = 0; k < 3; ++k) {
      const int other = mine[static_cast<size_t>(k)];
      EXPECT_LT(other, i - 2);
      if (images.place[static_cast<size_t>(other)] == images.place[static_cast<size_t>(i)]) {
        retrieved_same_place.push_back(other);
      }
    }
    EXPECT_EQ(retrieved_same_place.size(), std::min<size_t>(3, same_place.size())) << "image " << i;
  }
}

TEST(PairSelection, SameChoiceOnAnyNumberOfThreads) {
  const PlaceImages images = MakePlaceImages(30, 5, 200, 12);
  PairSelectionOptions one = SmallRule(), two = SmallRule();
  one.vocabulary.num_threads = 1;
  two.vocabulary.num_threads = 2;
  EXPECT_EQ(SelectAll(images, one), SelectAll(images, two));
}

TEST(PairSelection, ImagesWithoutDescriptorsRetrieveNothing) {
  PlaceImages images = MakePlaceImages(14, 3, 100, 13);
  for (int i : {0, 3, 9, 12}) images.descriptors[static_cast<size_t>(i)].clear();
  const std::vector<std::vector<int>> partners = SelectAll(images, SmallRule());
  EXPECT_EQ(partners[9], (std::vector<int>{7, 8}));  // only the window
  EXPECT_EQ(partners[12], (std::vector<int>{10, 11}));
  for (int other : partners[10]) EXPECT_NE(other, 0);  // nothing shared with an empty image
}

TEST(PairSelection, NoDescriptorsAnywhereLeavesTheWindow) {
  Result<PairSelector> selector = PairSelector::Create(SmallRule());
  ASSERT_TRUE(selector.ok());
  for (int i = 0; i < 10; ++i) {
    Result<std::vector<int>> chosen = selector->Add(nullptr, 0);
    ASSERT_TRUE(chosen.ok()) << chosen.status().ToString();
    if (i >= 8) {
      EXPECT_EQ(*chosen, (std::vector<int>{i - 2, i - 1}));
    }
  }
}

TEST(PairSelection, BadOptionsAndInputAreRefused) {
  PairSelectionOptions options;
  options.exhaustive_up_to = 1;
  EXPECT_EQ(PairSelector::Create(options).status().code(), StatusCode::kInvalidArgument);
  options = PairSelectionOptions{};
  options.retrieved = -1;
  EXPECT_EQ(PairSelector::Create(options).status().code(), StatusCode::kInvalidArgument);
  options = PairSelectionOptions{};
  options.vocabulary.branching = 1;
  EXPECT_EQ(PairSelector::Create(options).status().code(), StatusCode::kInvalidArgument);
  Result<PairSelector> selector = PairSelector::Create(PairSelectionOptions{});
  ASSERT_TRUE(selector.ok());
  EXPECT_EQ(selector->Add(nullptr, 5).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(selector->num_images(), 0);
}

TEST(PairSelection, DescribeNamesEverySetting) {
  PairSelectionOptions a, b;
  b.retrieved = a.retrieved + 1;
  EXPECT_NE(a.Describe(), b.Describe());
  b = a;
  b.vocabulary.seed = a.vocabulary.seed + 1;
  EXPECT_NE(a.Describe(), b.Describe());
}

}  // namespace
}  // namespace reconar
