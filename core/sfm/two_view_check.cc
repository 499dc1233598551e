#include "core/sfm/two_view_check.h"

namespace reconar {

std::vector<TwoViewMatch> GatherTwoViewMatches(const MapperModel& model, int image,
                                               const std::vector<char>* skip_keypoint) {
  std::vector<TwoViewMatch> matches;
  const SfmImage& img = model.rec.images[static_cast<size_t>(image)];
  const SfmCamera& camera = model.rec.cameras[static_cast<size_t>(img.camera_id)];
  const std::vector<int>& track_of = model.tracks.track_of[static_cast<size_t>(image)];
  for (size_t kp = 0; kp < track_of.size() && kp < img.keypoints.size(); ++kp) {
    const int t = track_of[kp];
    if (t < 0 || model.point_of_track[static_cast<size_t>(t)] >= 0) continue;
    if (skip_keypoint != nullptr && kp < skip_keypoint->size() && (*skip_keypoint)[kp]) continue;
    Eigen::Vector2d here;
    if (!camera.Undistort(img.keypoints[kp], &here)) continue;
    for (const TrackElement& e : model.tracks.tracks[static_cast<size_t>(t)]) {
      const SfmImage& other = model.rec.images[static_cast<size_t>(e.image_id)];
      if (e.image_id == image || !other.registered) continue;
      if (matches.size() >= kMaxTwoViewMatches) return matches;
      Eigen::Vector2d there;
      if (model.rec.cameras[static_cast<size_t>(other.camera_id)].Undistort(
              other.keypoints[static_cast<size_t>(e.keypoint_id)], &there))
        matches.push_back({here, there, e.image_id});
    }
  }
  return matches;
}

int CountEpipolarConsistent(const MapperModel& model, const std::vector<TwoViewMatch>& matches,
                            const Rigid3& cam_from_world, double focal, double bound_px) {
  const double bound = bound_px * bound_px / (focal * focal);
  int consistent = 0;
  for (const TwoViewMatch& m : matches) {
    // Sampson distance under E = [t]x R of here_from_there.
    const Rigid3& there_pose = model.rec.images[static_cast<size_t>(m.image)].cam_from_world;
    const Eigen::Matrix3d R = cam_from_world.rotation * there_pose.rotation.transpose();
    const Eigen::Vector3d t = cam_from_world.translation - R * there_pose.translation;
    Eigen::Matrix3d tx;
    tx << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
    const Eigen::Matrix3d E = tx * R;
    const Eigen::Vector3d x1 = m.there.homogeneous(), x2 = m.here.homogeneous();
    const Eigen::Vector3d Ex1 = E * x1, Etx2 = E.transpose() * x2;
    const double denominator = Ex1.head<2>().squaredNorm() + Etx2.head<2>().squaredNorm();
    const double numerator = x2.dot(Ex1);
    if (!(denominator > 0.0) || numerator * numerator <= bound * denominator) ++consistent;
  }
  return consistent;
}

}  // namespace reconar
