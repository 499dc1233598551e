#include "core/sfm/provisional_registration.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "core/sfm/point_filter.h"
#include "core/sfm/two_view_check.h"

namespace reconar {

double InlierSpread(const std::vector<Eigen::Vector2d>& pixels, int width, int height) {
  if (pixels.size() < 3 || std::min(width, height) <= 0) return 0.0;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : pixels) mean += p;
  mean /= static_cast<double>(pixels.size());
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector2d& p : pixels) covariance += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(covariance);
  double extent_product = 1.0;
  std::vector<double> along(pixels.size());
  for (int axis = 0; axis < 2; ++axis) {
    for (size_t i = 0; i < pixels.size(); ++i) along[i] = solver.eigenvectors().col(axis).dot(pixels[i] - mean);
    std::sort(along.begin(), along.end());
    const size_t last = along.size() - 1;
    extent_product *= along[last - last / 10] - along[last / 10];
  }
  return std::sqrt(extent_product) / std::min(width, height);
}

std::string CheckWeakPose(const MapperModel& model, int image, WeakEvidence evidence, const WeakPose& pose,
                          const MapperOptions& options, bool check_two_view) {
  const int inliers = static_cast<int>(pose.inlier_pixels.size());
  const int needed = evidence == WeakEvidence::kFewInliers ? options.registration_min_verified_inliers
                                                           : options.registration_min_baseline_points;
  const std::string of = std::to_string(inliers) + " of " + std::to_string(pose.num_correspondences) + " points";
  if (inliers < needed) return of + " fit the pose (need " + std::to_string(needed) + ")";
  if (2 * inliers < pose.num_correspondences) return "only " + of + " fit the pose (need half)";
  const SfmCamera& camera = model.rec.cameras[static_cast<size_t>(model.rec.images[static_cast<size_t>(image)].camera_id)];
  const double spread = InlierSpread(pose.inlier_pixels, camera.width, camera.height);
  if (spread < options.registration_min_inlier_spread) {
    return "the " + std::to_string(inliers) + " points that fit the pose span " +
           std::to_string(static_cast<int>(100.0 * spread + 0.5)) + " % of the image (need " +
           std::to_string(static_cast<int>(100.0 * options.registration_min_inlier_spread + 0.5)) + " %)";
  }
  if (!check_two_view) return "";
  const std::vector<TwoViewMatch> two_view = GatherTwoViewMatches(model, image);
  if (static_cast<int>(two_view.size()) < options.registration_min_verified_inliers) return "";
  const int consistent =
      CountEpipolarConsistent(model, two_view, pose.cam_from_world, pose.focal, options.registration_max_error_px);
  if (consistent < options.registration_min_two_view_fraction * static_cast<double>(two_view.size())) {
    return "only " + std::to_string(consistent) + " of its " + std::to_string(two_view.size()) +
           " two-view matches to registered images lie on their epipolar lines";
  }
  return "";
}

std::string ReviewProvisionalImage(const MapperModel& model, const ProvisionalImage& provisional,
                                   const MapperOptions& options) {
  const int image = provisional.image;
  const SfmImage& img = model.rec.images[static_cast<size_t>(image)];
  const SfmCamera& camera = model.rec.cameras[static_cast<size_t>(img.camera_id)];
  const double max_error2 = options.registration_max_error_px * options.registration_max_error_px;
  WeakPose pose;
  pose.cam_from_world = img.cam_from_world;
  pose.focal = camera.focal;
  const std::vector<int>& track_of = model.tracks.track_of[static_cast<size_t>(image)];
  for (size_t kp = 0; kp < track_of.size(); ++kp) {
    const int t = track_of[kp];
    const int point_id = t < 0 ? -1 : model.point_of_track[static_cast<size_t>(t)];
    if (point_id < 0) continue;
    const SfmPoint& point = model.rec.points[static_cast<size_t>(point_id)];
    int others = 0;
    for (const TrackElement& e : point.track) others += e.image_id != image ? 1 : 0;
    if (others < 2) continue;
    ++pose.num_correspondences;
    if (model.SquaredError(point.position, image, static_cast<int>(kp)) <= max_error2)
      pose.inlier_pixels.push_back(img.keypoints[kp]);
  }
  return CheckWeakPose(model, image, provisional.evidence, pose, options, false);
}

void DeregisterImage(MapperModel* model, int image, const MapperOptions& options) {
  SfmImage& img = model->rec.images[static_cast<size_t>(image)];
  std::vector<int> touched;
  for (int& point_id : img.point3d_ids) {
    if (point_id < 0) continue;
    std::vector<TrackElement>& track = model->rec.points[static_cast<size_t>(point_id)].track;
    track.erase(std::remove_if(track.begin(), track.end(),
                               [image](const TrackElement& e) { return e.image_id == image; }),
                track.end());
    touched.push_back(point_id);
    point_id = -1;
  }
  img.registered = false;
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  FilterPoints(model, touched, options);
}

}  // namespace reconar
