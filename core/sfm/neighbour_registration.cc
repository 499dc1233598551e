#include "core/sfm/neighbour_registration.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "core/sfm/image_registration.h"
#include "core/sfm/pair_pose.h"
#include "core/sfm/provisional_registration.h"
#include "core/sfm/two_view_check.h"

namespace reconar {
namespace {

// The registered neighbours of `image` with their pairs, largest pair first.
std::vector<std::pair<int, const MapperPair*>> RegisteredNeighbours(const MapperModel& model,
                                                                    const std::vector<MapperPair>& pairs, int image) {
  std::vector<std::pair<int, const MapperPair*>> out;
  for (const MapperPair& pair : pairs) {
    if (pair.planar) continue;
    const int a = pair.matches.image_a, b = pair.matches.image_b;
    if (a != image && b != image) continue;
    const int other = a == image ? b : a;
    if (model.rec.images[static_cast<size_t>(other)].registered) out.emplace_back(other, &pair);
  }
  std::stable_sort(out.begin(), out.end(), [](const auto& x, const auto& y) {
    return x.second->matches.matches.size() > y.second->matches.matches.size();
  });
  return out;
}

}  // namespace

std::vector<int> NeighbourRegistrationCandidates(const MapperModel& model, const std::vector<MapperPair>& pairs,
                                                 const std::vector<int>& tried_with) {
  std::vector<std::pair<size_t, int>> ranked;  // (largest pair to a registered image, image)
  std::vector<size_t> best(model.rec.images.size(), 0);
  for (const MapperPair& pair : pairs) {
    if (pair.planar) continue;
    const int a = pair.matches.image_a, b = pair.matches.image_b;
    const bool ra = model.rec.images[static_cast<size_t>(a)].registered;
    const bool rb = model.rec.images[static_cast<size_t>(b)].registered;
    if (ra == rb) continue;
    const int image = ra ? b : a;
    best[static_cast<size_t>(image)] = std::max(best[static_cast<size_t>(image)], pair.matches.matches.size());
  }
  for (size_t i = 0; i < best.size(); ++i) {
    if (best[i] == 0 || model.CountVisiblePoints(static_cast<int>(i)) <= tried_with[i]) continue;
    ranked.emplace_back(best[i], static_cast<int>(i));
  }
  std::stable_sort(ranked.begin(), ranked.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
  std::vector<int> out;
  for (const auto& r : ranked) out.push_back(r.second);
  return out;
}

bool RegisterImageFromNeighbour(MapperModel* model, const std::vector<MapperPair>& pairs, int image,
                                const MapperOptions& options) {
  std::string& failure = model->failure[static_cast<size_t>(image)];
  const SfmImage& img = model->rec.images[static_cast<size_t>(image)];
  if (options.registration_min_baseline_points <= 0) return false;
  if (model->CameraUsers(img.camera_id) < 3 && options.refine_focal) return false;
  // The image's 2D-3D correspondences.
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> world;
  std::vector<std::pair<int, int>> keypoint_point;
  const std::vector<int>& track_of = model->tracks.track_of[static_cast<size_t>(image)];
  for (size_t kp = 0; kp < track_of.size(); ++kp) {
    const int t = track_of[kp];
    const int point = t < 0 ? -1 : model->point_of_track[static_cast<size_t>(t)];
    if (point < 0) continue;
    pixels.push_back(img.keypoints[kp]);
    world.push_back(model->rec.points[static_cast<size_t>(point)].position);
    keypoint_point.emplace_back(static_cast<int>(kp), point);
  }
  if (static_cast<int>(pixels.size()) < options.registration_min_baseline_points) return false;
  const SfmCamera camera = GuessCamera(*model, image);
  const std::vector<TwoViewMatch> two_view = GatherTwoViewMatches(*model, image);
  std::string reasons;
  for (const auto& [neighbour, pair] : RegisteredNeighbours(*model, pairs, image)) {
    const std::string& neighbour_name = model->rec.images[static_cast<size_t>(neighbour)].name;
    const auto pair_pose = EstimatePairPose(*model, *pair, options);
    if (!pair_pose.ok() || pair_pose->num_inliers < options.registration_min_inliers) {
      reasons += "; with " + neighbour_name + ": " +
                 (pair_pose.ok() ? std::to_string(pair_pose->num_inliers) + " essential-matrix inliers (need " +
                                       std::to_string(options.registration_min_inliers) + ")"
                                 : pair_pose.status().message());
      continue;
    }
    const Rigid3 image_from_neighbour =
        pair->matches.image_a == neighbour ? pair_pose->b_from_a : pair_pose->b_from_a.Inverse();
    const Rigid3& neighbour_from_world = model->rec.images[static_cast<size_t>(neighbour)].cam_from_world;
    const Eigen::Matrix3d R = image_from_neighbour.rotation * neighbour_from_world.rotation;
    const Eigen::Vector3d offset = image_from_neighbour.rotation * neighbour_from_world.translation;
    const BaselineFit fit = FitBaselineLength(camera, R, offset, image_from_neighbour.translation, pixels, world,
                                              options.registration_max_error_px);
    const int agreeing = static_cast<int>(fit.inliers.size());
    if (agreeing < options.registration_min_baseline_points || 2 * agreeing < static_cast<int>(pixels.size())) {
      reasons += "; with " + neighbour_name + ": " + std::to_string(agreeing) + " of " + std::to_string(pixels.size()) +
                 " points agree on the baseline length (need " +
                 std::to_string(options.registration_min_baseline_points) + " and half)";
      continue;
    }
    std::vector<Eigen::Vector2d> agreeing_pixels;
    for (int i : fit.inliers) agreeing_pixels.push_back(pixels[static_cast<size_t>(i)]);
    const double spread = InlierSpread(agreeing_pixels, camera.width, camera.height);
    if (spread < options.registration_min_inlier_spread) {
      reasons += "; with " + neighbour_name + ": the " + std::to_string(agreeing) + " agreeing points span " +
                 std::to_string(static_cast<int>(100.0 * spread + 0.5)) + " % of the image";
      continue;
    }
    const Rigid3 cam_from_world{R, offset + fit.length * image_from_neighbour.translation};
    std::vector<TwoViewMatch> others;
    for (const TwoViewMatch& m : two_view) {
      if (m.image != neighbour) others.push_back(m);
    }
    const int consistent =
        CountEpipolarConsistent(*model, others, cam_from_world, camera.focal, options.registration_max_error_px);
    if (static_cast<int>(others.size()) >= options.registration_min_verified_inliers &&
        consistent < options.registration_min_two_view_fraction * static_cast<double>(others.size())) {
      reasons += "; with " + neighbour_name + ": only " + std::to_string(consistent) + " of " +
                 std::to_string(others.size()) + " matches to other images on their epipolar lines";
      continue;
    }
    std::vector<std::pair<int, int>> observations;
    for (int i : fit.inliers) observations.push_back(keypoint_point[static_cast<size_t>(i)]);
    AcceptRegistration(model, image, cam_from_world, observations);
    return true;
  }
  if (!reasons.empty()) {
    const std::string tag = "; from a neighbour's two-view geometry";
    failure = failure.substr(0, failure.find(tag)) + tag + reasons;
  }
  return false;
}

}  // namespace reconar
