#include "core/sfm/tracks.h"

#include <algorithm>
#include <iterator>
#include <numeric>

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
  // The sorted images of every set with more than one node, by root (a singleton's image is its own).
  std::vector<int> list_of_root(first_node.back(), -1);
  std::vector<std::vector<int>> image_lists;
  const auto image_of_node = [&](size_t n) {
    return static_cast<int>(std::upper_bound(first_node.begin(), first_node.end(), n) - first_node.begin()) - 1;
  };
  std::vector<int> merged;  // reused: the union of two image lists
  const auto union_if_consistent = [&](size_t a, size_t b) {
    const uint32_t root_a = sets.Find(static_cast<uint32_t>(a)), root_b = sets.Find(static_cast<uint32_t>(b));
    if (root_a == root_b) return true;
    const int single_a = image_of_node(root_a), single_b = image_of_node(root_b);
    const int list_a = list_of_root[root_a], list_b = list_of_root[root_b];
    const int* begin_a = list_a >= 0 ? image_lists[static_cast<size_t>(list_a)].data() : &single_a;
    const int* end_a = list_a >= 0 ? begin_a + image_lists[static_cast<size_t>(list_a)].size() : &single_a + 1;
    const int* begin_b = list_b >= 0 ? image_lists[static_cast<size_t>(list_b)].data() : &single_b;
    const int* end_b = list_b >= 0 ? begin_b + image_lists[static_cast<size_t>(list_b)].size() : &single_b + 1;
    merged.clear();
    std::set_union(begin_a, end_a, begin_b, end_b, std::back_inserter(merged));
    if (merged.size() != static_cast<size_t>((end_a - begin_a) + (end_b - begin_b))) return false;
    sets.Union(root_a, root_b);
    const uint32_t root = std::min(root_a, root_b), other = std::max(root_a, root_b);
    int list = list_of_root[root];
    if (list < 0) list = list_of_root[other];
    if (list < 0) {
      list = static_cast<int>(image_lists.size());
      image_lists.emplace_back();
    } else if (list_of_root[other] >= 0 && list_of_root[other] != list) {
      std::vector<int>().swap(image_lists[static_cast<size_t>(list_of_root[other])]);
    }
    image_lists[static_cast<size_t>(list)].swap(merged);
    list_of_root[root] = list;
    list_of_root[other] = -1;
    return true;
  };
  std::vector<size_t> order(pairs.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t x, size_t y) { return pairs[x].matches.size() > pairs[y].matches.size(); });
  TrackSet result;
  for (const size_t p : order) {
    const PairMatches& pair = pairs[p];
    for (const FeatureMatch& m : pair.matches) {
      const size_t a = node(pair.image_a, m.index_a), b = node(pair.image_b, m.index_b);
      if (!union_if_consistent(a, b)) {
        ++result.num_conflicting_matches;
        continue;
      }
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

  result.track_of.resize(num_keypoints.size());
  for (size_t i = 0; i < num_keypoints.size(); ++i) {
    result.track_of[i].assign(static_cast<size_t>(std::max(0, num_keypoints[i])), -1);
  }
  for (std::vector<TrackElement>& component : components) {
    if (component.size() < 2) continue;  // a keypoint matched to itself
    const int id = static_cast<int>(result.tracks.size());
    for (const TrackElement& e : component) {
      result.track_of[static_cast<size_t>(e.image_id)][static_cast<size_t>(e.keypoint_id)] = id;
    }
    result.tracks.push_back(std::move(component));
  }
  return result;
}

}  // namespace reconar
