#include "core/sfm/tracks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <utility>
#include <vector>

namespace reconar {
namespace {

PairMatches Pair(int a, int b, std::vector<std::pair<int, int>> matches) {
  PairMatches pair;
  pair.image_a = a;
  pair.image_b = b;
  for (const auto& [ia, ib] : matches) pair.matches.push_back({ia, ib});
  return pair;
}

// Every track sorted by image, with distinct images and length >= 2; track_of is its exact
// inverse (each element points back to its track, every other entry is -1).
void ExpectConsistent(const std::vector<int>& num_keypoints, const TrackSet& set) {
  ASSERT_EQ(set.track_of.size(), num_keypoints.size());
  for (size_t i = 0; i < num_keypoints.size(); ++i) {
    ASSERT_EQ(set.track_of[i].size(), static_cast<size_t>(num_keypoints[i])) << "image " << i;
  }
  size_t elements = 0;
  for (size_t t = 0; t < set.tracks.size(); ++t) {
    const std::vector<TrackElement>& track = set.tracks[t];
    EXPECT_GE(track.size(), 2u) << "track " << t;
    for (size_t e = 0; e < track.size(); ++e) {
      if (e > 0) {
        EXPECT_LT(track[e - 1].image_id, track[e].image_id) << "track " << t << " not sorted / repeated";
      }
      ASSERT_GE(track[e].image_id, 0);
      ASSERT_LT(track[e].image_id, static_cast<int>(num_keypoints.size()));
      ASSERT_GE(track[e].keypoint_id, 0);
      ASSERT_LT(track[e].keypoint_id, num_keypoints[static_cast<size_t>(track[e].image_id)]);
      EXPECT_EQ(set.track_of[static_cast<size_t>(track[e].image_id)][static_cast<size_t>(track[e].keypoint_id)],
                static_cast<int>(t));
    }
    elements += track.size();
  }
  size_t assigned = 0;
  for (const std::vector<int>& per_image : set.track_of) {
    for (int t : per_image) {
      EXPECT_GE(t, -1);
      EXPECT_LT(t, static_cast<int>(set.tracks.size()));
      assigned += t >= 0 ? 1 : 0;
    }
  }
  EXPECT_EQ(assigned, elements);
}

std::vector<std::pair<int, int>> Elements(const std::vector<TrackElement>& track) {
  std::vector<std::pair<int, int>> out;
  for (const TrackElement& e : track) out.emplace_back(e.image_id, e.keypoint_id);
  return out;
}

TEST(BuildTracksTest, EmptyInput) {
  const TrackSet none = BuildTracks({}, {});
  EXPECT_TRUE(none.tracks.empty());
  EXPECT_TRUE(none.track_of.empty());
  EXPECT_EQ(none.num_conflicting_matches, 0);

  // Images with keypoints but no pairs, and a pair without matches: no tracks, all -1.
  const std::vector<int> num_keypoints = {3, 0, 2};
  const TrackSet unmatched = BuildTracks(num_keypoints, {Pair(0, 2, {})});
  EXPECT_TRUE(unmatched.tracks.empty());
  EXPECT_EQ(unmatched.num_conflicting_matches, 0);
  ExpectConsistent(num_keypoints, unmatched);
  EXPECT_EQ(unmatched.track_of[0], std::vector<int>({-1, -1, -1}));
  EXPECT_TRUE(unmatched.track_of[1].empty());
  EXPECT_EQ(unmatched.track_of[2], std::vector<int>({-1, -1}));
}

TEST(BuildTracksTest, ChainAcrossFourImagesIsOneTrackSortedByImage) {
  // 3:1 - 0:2 - 2:0 - 1:4, given in an order that is neither by image nor along the chain, with
  // pairs whose image_a > image_b.
  const std::vector<int> num_keypoints = {3, 5, 2, 4};
  const std::vector<PairMatches> pairs = {
      Pair(2, 1, {{0, 4}}),
      Pair(3, 0, {{1, 2}}),
      Pair(0, 2, {{2, 0}}),
  };
  const TrackSet set = BuildTracks(num_keypoints, pairs);
  ExpectConsistent(num_keypoints, set);
  ASSERT_EQ(set.tracks.size(), 1u);
  EXPECT_EQ(set.num_conflicting_matches, 0);
  EXPECT_EQ(Elements(set.tracks[0]), (std::vector<std::pair<int, int>>{{0, 2}, {1, 4}, {2, 0}, {3, 1}}));
  // Unmatched keypoints stay -1.
  EXPECT_EQ(set.track_of[0], std::vector<int>({-1, -1, 0}));
  EXPECT_EQ(set.track_of[1], std::vector<int>({-1, -1, -1, -1, 0}));
  EXPECT_EQ(set.track_of[2], std::vector<int>({0, -1}));
  EXPECT_EQ(set.track_of[3], std::vector<int>({-1, 0, -1, -1}));
}

TEST(BuildTracksTest, SeveralTracksAndRedundantMatches) {
  // Track X: 0:0 1:0 2:0, matched in a closed loop (0-1, 1-2, 0-2) and with a duplicate match.
  // Track Y: 0:1 1:2 (two views only). Track Z: 1:1 2:2 3:0 via 1-2 and 2-3.
  const std::vector<int> num_keypoints = {2, 3, 3, 1};
  const std::vector<PairMatches> pairs = {
      Pair(0, 1, {{0, 0}, {1, 2}, {0, 0}}),
      Pair(1, 2, {{0, 0}, {1, 2}}),
      Pair(0, 2, {{0, 0}}),
      Pair(2, 3, {{2, 0}}),
  };
  const TrackSet set = BuildTracks(num_keypoints, pairs);
  ExpectConsistent(num_keypoints, set);
  EXPECT_EQ(set.num_conflicting_matches, 0);
  ASSERT_EQ(set.tracks.size(), 3u);
  std::set<std::vector<std::pair<int, int>>> got;
  for (const auto& track : set.tracks) got.insert(Elements(track));
  const std::set<std::vector<std::pair<int, int>>> expected = {
      {{0, 0}, {1, 0}, {2, 0}},
      {{0, 1}, {1, 2}},
      {{1, 1}, {2, 2}, {3, 0}},
  };
  EXPECT_EQ(got, expected);
  // Keypoints of one track share its index.
  EXPECT_EQ(set.track_of[0][0], set.track_of[1][0]);
  EXPECT_EQ(set.track_of[0][0], set.track_of[2][0]);
  EXPECT_EQ(set.track_of[1][1], set.track_of[3][0]);
  EXPECT_NE(set.track_of[0][0], set.track_of[0][1]);
}

TEST(BuildTracksTest, AMatchThatWouldJoinTwoKeypointsOfOneImageIsLeftOut) {
  // Pairs are joined strongest first: (1, 2) with 5 matches, (0, 1) with 2, (2, 0) with 1.
  // In (1, 2), 1:2 is matched to both 2:2 and 2:3 (one-to-many): the second is left out. In
  // (2, 0), the wrong match 2:1-0:2 would close the chain 0:1 1:1 2:1 back on image 0 at another
  // keypoint: left out, and the chain stays a track.
  const std::vector<int> num_keypoints = {3, 4, 5};
  const std::vector<PairMatches> pairs = {
      Pair(0, 1, {{0, 0}, {1, 1}}),
      Pair(1, 2, {{0, 0}, {1, 1}, {2, 2}, {2, 3}, {3, 4}}),
      Pair(2, 0, {{1, 2}}),
  };
  const TrackSet set = BuildTracks(num_keypoints, pairs);
  ExpectConsistent(num_keypoints, set);
  EXPECT_EQ(set.num_conflicting_matches, 2);
  std::set<std::vector<std::pair<int, int>>> got;
  for (const auto& track : set.tracks) got.insert(Elements(track));
  const std::set<std::vector<std::pair<int, int>>> expected = {
      {{0, 0}, {1, 0}, {2, 0}},
      {{0, 1}, {1, 1}, {2, 1}},
      {{1, 2}, {2, 2}},
      {{1, 3}, {2, 4}},
  };
  EXPECT_EQ(got, expected);
  // A keypoint whose only match was left out is in no track, like an unmatched one.
  EXPECT_EQ(set.track_of[0][2], -1);
  EXPECT_EQ(set.track_of[2][3], -1);
}

TEST(BuildTracksTest, TheStrongerPairsDecideWhichMatchIsLeftOut) {
  // (0, 1) with 3 matches and (1, 2) with 2 make the tracks 0:0 1:0 2:0 and 0:1 1:1 2:1; the one
  // wrong match 0:0-2:1 of the weak pair (0, 2) would join them. Taken in the input's order it
  // would come first and cost both true matches of (1, 2) instead.
  const std::vector<int> num_keypoints = {3, 3, 2};
  const std::vector<PairMatches> pairs = {
      Pair(0, 2, {{0, 1}}),
      Pair(0, 1, {{0, 0}, {1, 1}, {2, 2}}),
      Pair(1, 2, {{0, 0}, {1, 1}}),
  };
  const TrackSet set = BuildTracks(num_keypoints, pairs);
  ExpectConsistent(num_keypoints, set);
  EXPECT_EQ(set.num_conflicting_matches, 1);
  std::set<std::vector<std::pair<int, int>>> got;
  for (const auto& track : set.tracks) got.insert(Elements(track));
  const std::set<std::vector<std::pair<int, int>>> expected = {
      {{0, 0}, {1, 0}, {2, 0}},
      {{0, 1}, {1, 1}, {2, 1}},
      {{0, 2}, {1, 2}},
  };
  EXPECT_EQ(got, expected);
}

TEST(BuildTracksTest, ASelfPairMatchIsLeftOut) {
  // A pair of an image with itself linking two different keypoints would repeat the image.
  const std::vector<int> num_keypoints = {2, 1};
  const TrackSet set = BuildTracks(num_keypoints, {Pair(0, 0, {{0, 1}}), Pair(0, 1, {{1, 0}})});
  ExpectConsistent(num_keypoints, set);
  EXPECT_EQ(set.num_conflicting_matches, 1);
  ASSERT_EQ(set.tracks.size(), 1u);
  EXPECT_EQ(Elements(set.tracks[0]), (std::vector<std::pair<int, int>>{{0, 1}, {1, 0}}));
}

TEST(BuildTracksTest, LargeRandomChainsMatchTheConstruction) {
  // 200 ground-truth tracks over 6 images (each track visits a random subset of >= 2 images),
  // matched along a random spanning chain of its views: BuildTracks must recover exactly them.
  const int num_images = 6;
  std::vector<int> num_keypoints(num_images, 0);
  std::vector<std::vector<std::pair<int, int>>> truth;
  std::vector<std::vector<PairMatches>> by_pair(num_images, std::vector<PairMatches>(num_images));
  unsigned state = 12345u;
  const auto next = [&state]() {
    state = state * 1664525u + 1013904223u;
    return state >> 8;
  };
  for (int t = 0; t < 200; ++t) {
    std::vector<std::pair<int, int>> track;
    for (int i = 0; i < num_images; ++i) {
      if (next() % 2 == 0) track.emplace_back(i, num_keypoints[static_cast<size_t>(i)]++);
    }
    if (track.size() < 2) {
      // Undo: give the keypoints back so that every keypoint belongs to a truth track or none.
      for (const auto& e : track) --num_keypoints[static_cast<size_t>(e.first)];
      continue;
    }
    std::vector<std::pair<int, int>> chain = track;
    for (size_t k = chain.size(); k > 1; --k) std::swap(chain[k - 1], chain[next() % k]);
    for (size_t k = 1; k < chain.size(); ++k) {
      PairMatches& pair = by_pair[static_cast<size_t>(chain[k - 1].first)][static_cast<size_t>(chain[k].first)];
      pair.image_a = chain[k - 1].first;
      pair.image_b = chain[k].first;
      pair.matches.push_back({chain[k - 1].second, chain[k].second});
    }
    truth.push_back(track);
  }
  std::vector<PairMatches> pairs;
  for (auto& row : by_pair) {
    for (PairMatches& pair : row) {
      if (!pair.matches.empty()) pairs.push_back(std::move(pair));
    }
  }
  const TrackSet set = BuildTracks(num_keypoints, pairs);
  ExpectConsistent(num_keypoints, set);
  EXPECT_EQ(set.num_conflicting_matches, 0);
  std::set<std::vector<std::pair<int, int>>> got, expected(truth.begin(), truth.end());
  for (const auto& track : set.tracks) got.insert(Elements(track));
  EXPECT_EQ(got.size(), set.tracks.size());
  EXPECT_EQ(got, expected);
}

}  // namespace
}  // namespace reconar
