#include "core/sfm/image_registration.h"

#include <string>

#include "core/geometry/absolute_pose.h"
#include "core/sfm/provisional_registration.h"
#include "core/sfm/tag_image_registration.h"
#include "core/sfm/two_view_check.h"

namespace reconar {

SfmCamera GuessCamera(const MapperModel& model, int image) {
  const Reconstruction& rec = model.rec;
  const int camera_id = rec.images[static_cast<size_t>(image)].camera_id;
  SfmCamera camera = rec.cameras[static_cast<size_t>(camera_id)];
  if (model.CameraUsers(camera_id) > 0 || model.camera_from_exif[static_cast<size_t>(camera_id)]) return camera;
  double focal_sum = 0.0, k1_sum = 0.0, k2_sum = 0.0;
  int n = 0;
  for (size_t i = 0; i < rec.images.size(); ++i) {
    const int other_id = rec.images[i].camera_id;
    const SfmCamera& other = rec.cameras[static_cast<size_t>(other_id)];
    if (!rec.images[i].registered || other.width != camera.width || other.height != camera.height) continue;
    if (model.camera_from_exif[static_cast<size_t>(other_id)]) continue;
    focal_sum += other.focal;
    k1_sum += other.k1;
    k2_sum += other.k2;
    ++n;
  }
  if (n > 0) {
    camera.focal = focal_sum / n;
    camera.k1 = k1_sum / n;
    camera.k2 = k2_sum / n;
  }
  return camera;
}

void AcceptRegistration(MapperModel* model, int image, const Rigid3& cam_from_world,
                        const std::vector<std::pair<int, int>>& observations) {
  SfmImage& img = model->rec.images[static_cast<size_t>(image)];
  img.cam_from_world.rotation = cam_from_world.rotation;
  img.cam_from_world.translation = cam_from_world.translation;
  img.registered = true;
  for (const auto& [kp, point] : observations) model->AddObservation(point, image, kp);
  model->failure[static_cast<size_t>(image)].clear();
}

namespace {

// Empty when the pose has registration_min_inliers inliers, or fewer but verified as
// provisional_registration.h says; otherwise why it is refused.
std::string VerifyFewInliers(const MapperModel& model, int image, const std::vector<Eigen::Vector2d>& pixels,
                             const AbsolutePoseResult& pose, double focal, const MapperOptions& options) {
  if (pose.num_inliers >= options.registration_min_inliers) return "";
  WeakPose weak;
  weak.cam_from_world = pose.cam_from_world;
  weak.focal = focal;
  weak.num_correspondences = static_cast<int>(pixels.size());
  for (int index : pose.inliers) weak.inlier_pixels.push_back(pixels[static_cast<size_t>(index)]);
  const std::string refused = CheckWeakPose(model, image, WeakEvidence::kFewInliers, weak, options);
  if (refused.empty()) return "";
  return "the best pose has " + std::to_string(pose.num_inliers) + " inliers (" +
         std::to_string(options.registration_min_inliers) + " register without further checks), and " + refused;
}

// Of the pose and its alternative (AbsolutePoseResult::alternatives: the planar flip of a room's
// walls or a facade fits nearly as many points), the one that explains more of the image: its
// 2D-3D inliers plus its matches to registered images on tracks without a point that lie on their
// epipolar lines under it. The wrong one of two such poses leaves most of those matches off.
void TakeTheBetterExplainedPose(const MapperModel& model, int image, double focal, const MapperOptions& options,
                                AbsolutePoseResult* pose) {
  if (pose->alternatives.empty()) return;
  AlternativePose& other = pose->alternatives[0];
  if (other.inliers.size() + pose->inliers.size() == 0) return;
  const std::vector<TwoViewMatch> two_view = GatherTwoViewMatches(model, image);
  const auto explained = [&](const Rigid3& cam_from_world, size_t inliers) {
    return static_cast<int>(inliers) +
           CountEpipolarConsistent(model, two_view, cam_from_world, focal, options.registration_max_error_px);
  };
  if (explained(other.cam_from_world, other.inliers.size()) <=
      explained(pose->cam_from_world, pose->inliers.size()))
    return;
  std::swap(pose->cam_from_world, other.cam_from_world);
  std::swap(pose->inliers, other.inliers);
  pose->num_inliers = static_cast<int>(pose->inliers.size());
  if (pose->num_inliers < options.registration_min_verified_inliers) {
    pose->outcome = AbsolutePoseResult::Outcome::kTooFewInliers;
    pose->reason = "of two poses the one that explains more has " + std::to_string(pose->num_inliers) +
                   " inliers, need " + std::to_string(options.registration_min_verified_inliers);
  }
}

}  // namespace

bool RegisterImage(MapperModel* model, const std::vector<MapperImage>& images, int image, const MapperOptions& options,
                   bool* focal_changed, int* num_inliers) {
  *focal_changed = false;
  if (num_inliers != nullptr) *num_inliers = 0;
  Reconstruction& rec = model->rec;
  SfmImage& img = rec.images[static_cast<size_t>(image)];
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> world;
  std::vector<int> keypoint_of;
  const std::vector<int>& track_of = model->tracks.track_of[static_cast<size_t>(image)];
  for (size_t kp = 0; kp < track_of.size(); ++kp) {
    const int t = track_of[kp];
    if (t < 0 || model->point_of_track[static_cast<size_t>(t)] < 0) continue;
    pixels.push_back(img.keypoints[kp]);
    world.push_back(rec.points[static_cast<size_t>(model->point_of_track[static_cast<size_t>(t)])].position);
    keypoint_of.push_back(static_cast<int>(kp));
  }
  SfmCamera camera = GuessCamera(*model, image);
  const RadialCamera& pose_camera = camera;  // with its aspect ratio
  // Until three images confirm a camera's focal, the model is shaped by a prior the data has not
  // checked: register with the focal free, under a looser bound, falling back to the DLT for an
  // unknown focal; a global adjustment with the focal free follows (the caller's).
  const int camera_id = img.camera_id;
  const bool exif = images[static_cast<size_t>(image)].focal_from_exif;
  const bool focal_confirmed = model->CameraUsers(camera_id) >= 3 || !options.refine_focal;
  AbsolutePoseOptions pose_options;
  pose_options.max_error_px = options.registration_max_error_px * (focal_confirmed ? 1.0 : 2.0);
  pose_options.min_inliers = options.registration_min_verified_inliers;
  pose_options.refine_focal = !focal_confirmed;
  pose_options.second_pose_from_outliers = focal_confirmed;  // weighed by TakeTheBetterExplainedPose
  auto result = EstimateAbsolutePose(pixels, world, pose_camera, pose_options);
  if (result.ok() && !result->success() && !focal_confirmed) {
    result = EstimateAbsolutePoseUnknownFocal(pixels, world, pose_camera, pose_options);
  }
  if (result.ok() && result->success()) {
    TakeTheBetterExplainedPose(*model, image, result->focal > 0.0 ? result->focal : camera.focal, options, &*result);
  }
  std::string verification;
  if (result.ok() && result->success()) {
    verification = VerifyFewInliers(*model, image, pixels, *result,
                                    result->focal > 0.0 ? result->focal : camera.focal, options);
  }
  if (!result.ok() || !result->success() || !verification.empty()) {
    std::string reason = "pose from " + std::to_string(pixels.size()) + " 2D-3D correspondences failed: " +
                         (!verification.empty() ? verification
                          : result.ok()         ? result->reason
                                                : result.status().message());
    if (!images[static_cast<size_t>(image)].tags.empty()) {
      std::string tag_reason;
      if (RegisterImageByTags(model, images, image, options, &tag_reason)) return true;
      reason += "; " + tag_reason;
    }
    model->failure[static_cast<size_t>(image)] = std::move(reason);
    return false;
  }
  if (!focal_confirmed && result->focal > 0.0) {
    // Paper eq. 5: the EXIF focal is kept when it lies within 0.7-1.4 of the data's estimate.
    double focal = result->focal;
    const double prior = images[static_cast<size_t>(image)].focal_prior;
    if (exif && prior > options.focal_prior_min_ratio * focal && prior < options.focal_prior_max_ratio * focal) {
      focal = prior;
    }
    camera.focal = focal;
    rec.cameras[static_cast<size_t>(camera_id)] = camera;
    *focal_changed = true;
  }
  std::vector<std::pair<int, int>> observations;
  observations.reserve(result->inliers.size());
  for (int index : result->inliers) {
    const int kp = keypoint_of[static_cast<size_t>(index)];
    const int t = track_of[static_cast<size_t>(kp)];
    observations.emplace_back(kp, model->point_of_track[static_cast<size_t>(t)]);
  }
  AcceptRegistration(model, image, result->cam_from_world, observations);
  if (num_inliers != nullptr) *num_inliers = result->num_inliers;
  return true;
}

}  // namespace reconar
