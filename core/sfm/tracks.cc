#include "core/sfm/tracks.h"

#include <algorithm>

#include "core/base/union_find.h"

namespace reconar {

TrackSet BuildTracks(const std::vector<int>& num_keypoints, const std::vector<PairMatches>& pairs) {
  std::vector<size_t> first_node(num_keypoints.size() + 1, 0);
  for (size_t i = 0; i < num_keypoints.size(); ++i) {
    first_node[i + 1] = first_node[i] + static_cast<size_t>(std::max(0, num_keypoints[i]));
  }
  const auto node = [&](int image, int keypoint) {
    return first_node[static_cast<size_t>(image)] + static_cast<size_t>(keypoint);
  };
  UnionFind sets(first_node.back());
  std::vector<char> matched(first_node.back(), 0);
  for (const PairMatches& pair : pairs) {
    for (const FeatureMatch& m : pair.matches) {
      const size_t a = node(pair.image_a, m.index_a), b = node(pair.image_b, m.index_b);
      sets.Union(static_cast<uint32_t>(a), static_cast<uint32_t>(b));
      matched[a] = matched[b] = 1;
    }
  }

  // Group matched nodes by root; nodes are visited in (image, keypoint) order, so every
  // component's elements come out sorted by image.
  std::vector<int> component_of_root(first_node.back(), -1);
  std::vector<std::vector<TrackElement>> components;
  for (size_t image = 0; image < num_keypoints.size(); ++image) {
    for (int k = 0; k < num_keypoints[image]; ++k) {
      const size_t n = node(static_cast<int>(image), k);
      if (!matched[n]) continue;
      const size_t root = sets.Find(static_cast<uint32_t>(n));
      if (component_of_root[root] < 0) {
        component_of_root[root] = static_cast<int>(components.size());
        components.emplace_back();
      }
      components[static_cast<size_t>(component_of_root[root])].push_back(
          {static_cast<int>(image), k});
    }
  }

  TrackSet result;
  result.track_of.resize(num_keypoints.size());
  for (size_t i = 0; i < num_keypoints.size(); ++i) {
    result.track_of[i].assign(static_cast<size_t>(std::max(0, num_keypoints[i])), -1);
  }
  for (std::vector<TrackElement>& component : components) {
    bool repeated = false;
    for (size_t e = 1; e < component.size(); ++e) {
      repeated |= component[e].image_id == component[e - 1].image_id;
    }
    if (repeated) {
      ++result.num_inconsistent;
      continue;
    }
    const int id = static_cast<int>(result.tracks.size());
    for (const TrackElement& e : component) {
      result.track_of[static_cast<size_t>(e.image_id)][static_cast<size_t>(e.keypoint_id)] = id;
    }
    result.tracks.push_back(std::move(component));
  }
  return result;
}

}  // namespace reconar
