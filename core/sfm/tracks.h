#pragma once
// Feature tracks: the connected components of the graph whose nodes are (image, keypoint) and
// whose edges are verified matches, found by union-find (Snavely, Seitz & Szeliski, "Photo
// Tourism", SIGGRAPH 2006, sec. 4.1). A component that holds two keypoints of one image is
// inconsistent (some match in it is wrong) and is dropped, as Bundler does.
#include <vector>

#include "core/features/matcher.h"
#include "core/sfm/reconstruction.h"

namespace reconar {

struct PairMatches {
  int image_a = -1;
  int image_b = -1;
  std::vector<FeatureMatch> matches;  // index_a into image_a's keypoints, index_b into image_b's
};

struct TrackSet {
  std::vector<std::vector<TrackElement>> tracks;  // each sorted by image, length >= 2
  std::vector<std::vector<int>> track_of;         // [image][keypoint] -> track index or -1
  int num_inconsistent = 0;                       // components dropped for a repeated image
};

// num_keypoints[i] is the keypoint count of image i; matches index into those.
TrackSet BuildTracks(const std::vector<int>& num_keypoints, const std::vector<PairMatches>& pairs);

}  // namespace reconar
