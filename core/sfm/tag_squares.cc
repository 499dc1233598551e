#include "core/sfm/tag_squares.h"

#include <algorithm>
#include <map>
#include <utility>

#include "core/math/sim3.h"
#include "core/sfm/tag_observations.h"

namespace reconar {

std::array<Eigen::Vector3d, 4> TagSquareCorners(double edge) {
  std::array<Eigen::Vector3d, 4> corners;
  for (int k = 0; k < 4; ++k) {
    corners[static_cast<size_t>(k)] = Eigen::Vector3d(kTagCornerUnits[k][0], kTagCornerUnits[k][1], 0.0) * edge / 2.0;
  }
  return corners;
}

std::vector<TagCornerPoints> FindTagCornerPoints(const Reconstruction& rec,
                                                 const std::vector<TagCornerKeypoint>& corner_keypoints) {
  std::map<std::pair<int, int>, std::map<int, int>> votes;  // (tag, corner) -> point id -> keypoints
  std::map<int, TagCornerPoints> tags;
  for (const TagCornerKeypoint& c : corner_keypoints) {
    if (c.image_id < 0 || static_cast<size_t>(c.image_id) >= rec.images.size()) continue;
    const SfmImage& image = rec.images[static_cast<size_t>(c.image_id)];
    if (!image.registered || c.keypoint_id < 0 || static_cast<size_t>(c.keypoint_id) >= image.point3d_ids.size()) continue;
    tags[c.tag_id].tag_id = c.tag_id;
    const int point = image.point3d_ids[static_cast<size_t>(c.keypoint_id)];
    if (point >= 0 && !rec.points[static_cast<size_t>(point)].deleted) ++votes[{c.tag_id, c.corner}][point];
  }
  for (const auto& [key, count] : votes) {
    const auto best = std::max_element(count.begin(), count.end(),
                                       [](const auto& x, const auto& y) { return x.second < y.second; });
    tags[key.first].points[static_cast<size_t>(key.second)] = best->first;
  }
  std::vector<TagCornerPoints> result;
  result.reserve(tags.size());
  for (const auto& entry : tags) result.push_back(entry.second);
  return result;
}

std::vector<TagCornerKeypoint> CornerKeypointsOfImages(const std::vector<MapperImage>& images) {
  std::vector<TagCornerKeypoint> corners;
  for (size_t i = 0; i < images.size(); ++i) {
    for (const MapperTag& tag : images[i].tags) {
      for (int k = 0; k < 4; ++k) {
        const int keypoint = tag.first_keypoint + k;
        corners.push_back({static_cast<int>(i), keypoint, tag.tag_id, k,
                           images[i].keypoints[static_cast<size_t>(keypoint)]});
      }
    }
  }
  return corners;
}

TagSquares FindTagSquares(const Reconstruction& rec, const std::vector<TagCornerKeypoint>& corner_keypoints,
                          const std::vector<int>& square_tags) {
  TagSquares result;
  std::vector<TagCornerPoints> tags;
  for (const TagCornerPoints& tag : FindTagCornerPoints(rec, corner_keypoints)) {
    if (!square_tags.empty() && std::find(square_tags.begin(), square_tags.end(), tag.tag_id) == square_tags.end()) {
      continue;
    }
    std::array<int, 4> points = tag.points;
    std::sort(points.begin(), points.end());
    if (points[0] < 0 || std::adjacent_find(points.begin(), points.end()) != points.end()) continue;
    tags.push_back(tag);
  }
  if (tags.empty()) return result;
  const auto position = [&rec](int point) { return rec.points[static_cast<size_t>(point)].position; };
  for (const TagCornerPoints& tag : tags) {
    for (size_t k = 0; k < 4; ++k) result.edge += (position(tag.points[(k + 1) % 4]) - position(tag.points[k])).norm();
  }
  result.edge /= 4.0 * static_cast<double>(tags.size());
  const std::array<Eigen::Vector3d, 4> ideal = TagSquareCorners(result.edge);
  const std::vector<Eigen::Vector3d> from(ideal.begin(), ideal.end());
  for (const TagCornerPoints& tag : tags) {
    std::vector<Eigen::Vector3d> to;
    for (int point : tag.points) to.push_back(position(point));
    const Result<Sim3> fit = AlignSimilarity(from, to, 1.0);
    if (!fit.ok()) continue;
    result.squares.push_back({tag.tag_id, tag.points, Rigid3{fit->rotation, fit->translation}});
  }
  return result;
}

}  // namespace reconar
