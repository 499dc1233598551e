#include "core/sfm/mapper_model.h"

#include <algorithm>

#include "core/sfm/mapper.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace reconar {

void MapperModel::SetTracks(TrackSet track_set) {
  tracks = std::move(track_set);
  point_of_track.assign(tracks.tracks.size(), -1);
  track_of_point.clear();
}

double MapperModel::MaxSquaredError(int image, int kp, const MapperOptions& options) const {
  double bound = options.max_reprojection_error_px;
  if (static_cast<size_t>(image) < tag_corner_bounds.size()) {
    const std::vector<TagCornerBound>& corners = tag_corner_bounds[static_cast<size_t>(image)];
    const auto it = std::lower_bound(corners.begin(), corners.end(), TagCornerBound{kp, 0.0});
    if (it != corners.end() && it->keypoint == kp) bound = std::max(bound, it->bound_px);
  }
  return bound * bound;
}

double MapperModel::SquaredError(const Eigen::Vector3d& position, int image, int kp) const {
  const SfmImage& img = rec.images[static_cast<size_t>(image)];
  const Eigen::Vector3d cam = img.cam_from_world * position;
  if (!(cam.z() > 0.0)) return std::numeric_limits<double>::infinity();
  const Eigen::Vector2d predicted = rec.cameras[static_cast<size_t>(img.camera_id)].Project(cam);
  return (predicted - img.keypoints[static_cast<size_t>(kp)]).squaredNorm();
}

double MapperModel::MaxTriangulationAngle(const SfmPoint& point) const {
  const size_t n = std::min<size_t>(point.track.size(), 30);
  double best_cos = 1.0;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d ri =
        (rec.images[static_cast<size_t>(point.track[i].image_id)].Center() - point.position).normalized();
    for (size_t j = i + 1; j < n; ++j) {
      const Eigen::Vector3d rj =
          (rec.images[static_cast<size_t>(point.track[j].image_id)].Center() - point.position).normalized();
      best_cos = std::min(best_cos, ri.dot(rj));
    }
  }
  return std::acos(std::clamp(best_cos, -1.0, 1.0));
}

void MapperModel::AddObservation(int point_id, int image, int kp) {
  SfmPoint& point = rec.points[static_cast<size_t>(point_id)];
  point.track.push_back({image, kp});
  rec.images[static_cast<size_t>(image)].point3d_ids[static_cast<size_t>(kp)] = point_id;
}

void MapperModel::DeletePoint(int point_id) {
  SfmPoint& point = rec.points[static_cast<size_t>(point_id)];
  for (const TrackElement& e : point.track) {
    rec.images[static_cast<size_t>(e.image_id)].point3d_ids[static_cast<size_t>(e.keypoint_id)] = -1;
  }
  point.track.clear();
  point.deleted = true;
  point_of_track[static_cast<size_t>(track_of_point[static_cast<size_t>(point_id)])] = -1;
}

int MapperModel::CountVisiblePoints(int image) const {
  int count = 0;
  const std::vector<int>& track_of = tracks.track_of[static_cast<size_t>(image)];
  for (int t : track_of) count += (t >= 0 && point_of_track[static_cast<size_t>(t)] >= 0) ? 1 : 0;
  return count;
}

int MapperModel::CameraUsers(int camera) const {
  int n = 0;
  for (const SfmImage& image : rec.images) n += (image.registered && image.camera_id == camera) ? 1 : 0;
  return n;
}

bool MapperModel::CameraShared() const { return rec.cameras.size() < rec.images.size(); }

std::vector<int> MapperModel::AllPoints() const {
  std::vector<int> ids;
  for (size_t p = 0; p < rec.points.size(); ++p) {
    if (!rec.points[p].deleted) ids.push_back(static_cast<int>(p));
  }
  return ids;
}

std::vector<int> MapperModel::PointsSeenBy(const std::vector<int>& images) const {
  std::vector<char> seen(rec.points.size(), 0);
  for (int image : images) {
    for (int id : rec.images[static_cast<size_t>(image)].point3d_ids) {
      if (id >= 0) seen[static_cast<size_t>(id)] = 1;
    }
  }
  std::vector<int> ids;
  for (size_t p = 0; p < seen.size(); ++p) {
    if (seen[p]) ids.push_back(static_cast<int>(p));
  }
  return ids;
}

std::vector<int> MapperModel::RegisteredImages() const {
  std::vector<int> ids;
  for (size_t i = 0; i < rec.images.size(); ++i) {
    if (rec.images[i].registered) ids.push_back(static_cast<int>(i));
  }
  return ids;
}

void MapperModel::Reset() {
  for (SfmImage& image : rec.images) {
    image.registered = false;
    std::fill(image.point3d_ids.begin(), image.point3d_ids.end(), -1);
  }
  for (size_t c = 0; c < rec.cameras.size(); ++c) {
    rec.cameras[c].focal = camera_prior[c];
    rec.cameras[c].k1 = rec.cameras[c].k2 = 0.0;
  }
  rec.points.clear();
  track_of_point.clear();
  std::fill(point_of_track.begin(), point_of_track.end(), -1);
}

}  // namespace reconar
