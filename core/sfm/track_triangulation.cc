#include "core/sfm/track_triangulation.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/geometry/triangulation.h"

namespace reconar {
namespace {

constexpr double kDegree = M_PI / 180.0;

// TriangulateMultiView (core/geometry/triangulation.h) of the undistorted keypoints. False when
// the views do not determine a point or a keypoint cannot be undistorted.
bool Triangulate(const MapperModel& model, const std::vector<TrackElement>& views, Eigen::Vector3d* position) {
  std::vector<TriangulationView> observations(views.size());
  for (size_t v = 0; v < views.size(); ++v) {
    const SfmImage& img = model.rec.images[static_cast<size_t>(views[v].image_id)];
    const SfmCamera& cam = model.rec.cameras[static_cast<size_t>(img.camera_id)];
    TriangulationView& view = observations[v];
    if (!cam.Undistort(img.keypoints[static_cast<size_t>(views[v].keypoint_id)], &view.normalised)) return false;
    view.cam_from_world = Rigid3{img.cam_from_world.rotation, img.cam_from_world.translation};
    view.focal = cam.focal;
  }
  return TriangulateMultiView(observations, position);
}

}  // namespace

bool TriangulateTrack(MapperModel* model, int track, const MapperOptions& options) {
  std::vector<TrackElement> views;
  for (const TrackElement& e : model->tracks.tracks[static_cast<size_t>(track)]) {
    if (model->rec.images[static_cast<size_t>(e.image_id)].registered) views.push_back(e);
  }
  if (views.size() < 2) return false;
  const double max_error2 = options.max_reprojection_error_px * options.max_reprojection_error_px;
  const auto inliers_of = [&](const Eigen::Vector3d& x) {
    std::vector<TrackElement> inliers;
    for (const TrackElement& e : views) {
      if (model->SquaredError(x, e.image_id, e.keypoint_id) <= max_error2) inliers.push_back(e);
    }
    return inliers;
  };
  Eigen::Vector3d x;
  std::vector<TrackElement> inliers;
  if (Triangulate(*model, views, &x)) inliers = inliers_of(x);
  if (inliers.size() < views.size()) {
    const size_t n = std::min<size_t>(views.size(), 12);
    for (size_t i = 0; i < n; ++i) {
      for (size_t j = i + 1; j < n; ++j) {
        Eigen::Vector3d y;
        if (!Triangulate(*model, {views[i], views[j]}, &y)) continue;
        std::vector<TrackElement> candidate = inliers_of(y);
        if (candidate.size() > inliers.size()) inliers.swap(candidate);
      }
    }
    if (inliers.size() < 2 || !Triangulate(*model, inliers, &x)) return false;
    inliers = inliers_of(x);
  }
  if (inliers.size() < 2) return false;
  SfmPoint point;
  point.position = x;
  point.track = inliers;
  if (model->MaxTriangulationAngle(point) < options.min_triangulation_angle_deg * kDegree) return false;
  const int id = static_cast<int>(model->rec.points.size());
  model->rec.points.push_back(SfmPoint{x, {0, 0, 0}, 0.0, {}, false});
  model->track_of_point.push_back(track);
  model->point_of_track[static_cast<size_t>(track)] = id;
  for (const TrackElement& e : inliers) model->AddObservation(id, e.image_id, e.keypoint_id);
  return true;
}

void TriangulateImage(MapperModel* model, int image, const MapperOptions& options) {
  SfmImage& img = model->rec.images[static_cast<size_t>(image)];
  const std::vector<int>& track_of = model->tracks.track_of[static_cast<size_t>(image)];
  for (size_t kp = 0; kp < track_of.size(); ++kp) {
    const int t = track_of[kp];
    if (t < 0 || img.point3d_ids[kp] >= 0) continue;
    const int point_id = model->point_of_track[static_cast<size_t>(t)];
    if (point_id < 0) {
      TriangulateTrack(model, t, options);
    } else if (model->SquaredError(model->rec.points[static_cast<size_t>(point_id)].position, image,
                                   static_cast<int>(kp)) <= model->MaxSquaredError(image, static_cast<int>(kp), options)) {
      model->AddObservation(point_id, image, static_cast<int>(kp));
    }
  }
}

void RetriangulateAll(MapperModel* model, const MapperOptions& options) {
  for (size_t t = 0; t < model->tracks.tracks.size(); ++t) {
    if (model->point_of_track[t] < 0) TriangulateTrack(model, static_cast<int>(t), options);
  }
  for (size_t p = 0; p < model->rec.points.size(); ++p) {
    if (model->rec.points[p].deleted) continue;
    const int t = model->track_of_point[p];
    for (const TrackElement& e : model->tracks.tracks[static_cast<size_t>(t)]) {
      const SfmImage& img = model->rec.images[static_cast<size_t>(e.image_id)];
      if (!img.registered || img.point3d_ids[static_cast<size_t>(e.keypoint_id)] >= 0) continue;
      if (model->SquaredError(model->rec.points[p].position, e.image_id, e.keypoint_id) <=
          model->MaxSquaredError(e.image_id, e.keypoint_id, options)) {
        model->AddObservation(static_cast<int>(p), e.image_id, e.keypoint_id);
      }
    }
  }
}

}  // namespace reconar
