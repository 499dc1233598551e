#include "core/sfm/model_merge.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <utility>

#include "core/base/prng.h"
#include "core/sfm/mapper_model.h"
#include "core/sfm/pair_pose.h"

namespace reconar {
namespace {

struct SharedPoint {
  int to_point = -1;
  int from_point = -1;
};

// Point ids of `model` per (image, keypoint) are in SfmImage::point3d_ids; -1 when the image is
// not registered or the keypoint has no live point.
int PointAt(const Reconstruction& model, int image, int keypoint) {
  const SfmImage& img = model.images[static_cast<size_t>(image)];
  if (!img.registered || keypoint < 0 || static_cast<size_t>(keypoint) >= img.point3d_ids.size()) return -1;
  const int id = img.point3d_ids[static_cast<size_t>(keypoint)];
  if (id < 0 || model.points[static_cast<size_t>(id)].deleted || model.points[static_cast<size_t>(id)].track.size() < 2)
    return -1;
  return id;
}

std::vector<SharedPoint> SharedPoints(const Reconstruction& to, const Reconstruction& from,
                                      const std::vector<MapperPair>& pairs) {
  std::set<std::pair<int, int>> shared;
  const auto add = [&](int to_image, int to_kp, int from_image, int from_kp) {
    const int a = PointAt(to, to_image, to_kp);
    const int b = PointAt(from, from_image, from_kp);
    if (a >= 0 && b >= 0) shared.insert({a, b});
  };
  for (const MapperPair& pair : pairs) {
    const PairMatches& m = pair.matches;
    for (const FeatureMatch& f : m.matches) {
      add(m.image_a, f.index_a, m.image_b, f.index_b);
      add(m.image_b, f.index_b, m.image_a, f.index_a);
    }
  }
  const size_t num_images = std::min(to.images.size(), from.images.size());
  for (size_t i = 0; i < num_images; ++i) {
    if (!to.images[i].registered || !from.images[i].registered) continue;
    for (size_t k = 0; k < to.images[i].point3d_ids.size(); ++k)
      add(static_cast<int>(i), static_cast<int>(k), static_cast<int>(i), static_cast<int>(k));
  }
  std::vector<SharedPoint> out;
  out.reserve(shared.size());
  for (const auto& [a, b] : shared) out.push_back({a, b});
  return out;
}

// `position` (in `model`'s frame) reprojects within the bound in every view of `point`.
bool ReprojectsInViews(const Reconstruction& model, const SfmPoint& point, const Eigen::Vector3d& position,
                       double max_squared_error) {
  for (const TrackElement& e : point.track) {
    const SfmImage& image = model.images[static_cast<size_t>(e.image_id)];
    const Eigen::Vector3d cam = image.cam_from_world * position;
    if (!(cam.z() > 0.0)) return false;
    const Eigen::Vector2d predicted = model.cameras[static_cast<size_t>(image.camera_id)].Project(cam);
    if ((predicted - image.keypoints[static_cast<size_t>(e.keypoint_id)]).squaredNorm() > max_squared_error)
      return false;
  }
  return true;
}

std::string FormatPixels(double px) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f px", px);
  return text;
}

Sim3 Inverse(const Sim3& a_from_b) {
  Sim3 b_from_a;
  b_from_a.scale = 1.0 / a_from_b.scale;
  b_from_a.rotation = a_from_b.rotation.transpose();
  b_from_a.translation = -b_from_a.scale * (b_from_a.rotation * a_from_b.translation);
  return b_from_a;
}

std::vector<int> Inliers(const Reconstruction& to, const Reconstruction& from, const std::vector<SharedPoint>& shared,
                         const Sim3& to_from_from, double max_squared_error) {
  const Sim3 from_from_to = Inverse(to_from_from);
  std::vector<int> inliers;
  for (size_t s = 0; s < shared.size(); ++s) {
    const SfmPoint& a = to.points[static_cast<size_t>(shared[s].to_point)];
    const SfmPoint& b = from.points[static_cast<size_t>(shared[s].from_point)];
    if (ReprojectsInViews(to, a, to_from_from.Apply(b.position), max_squared_error) &&
        ReprojectsInViews(from, b, from_from_to.Apply(a.position), max_squared_error))
      inliers.push_back(static_cast<int>(s));
  }
  return inliers;
}

Result<Sim3> Fit(const Reconstruction& to, const Reconstruction& from, const std::vector<SharedPoint>& shared,
                 const std::vector<int>& subset) {
  std::vector<Eigen::Vector3d> from_points, to_points;
  for (const int s : subset) {
    from_points.push_back(from.points[static_cast<size_t>(shared[static_cast<size_t>(s)].from_point)].position);
    to_points.push_back(to.points[static_cast<size_t>(shared[static_cast<size_t>(s)].to_point)].position);
  }
  return AlignSimilarity(from_points, to_points);
}

}  // namespace

Result<ModelAlignment> AlignModels(const Reconstruction& to, const Reconstruction& from,
                                   const std::vector<MapperPair>& pairs, const ModelMergeOptions& options) {
  const std::vector<SharedPoint> shared = SharedPoints(to, from, pairs);
  const int n = static_cast<int>(shared.size());
  const int needed = std::max(options.min_inliers, static_cast<int>(std::ceil(options.min_inlier_ratio * n)));
  if (n < std::max(3, needed)) {
    return FailedPrecondition("the models share " + std::to_string(n) + (n == 1 ? " point" : " points") + ", need " +
                              std::to_string(std::max(3, options.min_inliers)));
  }
  const double max_squared_error = options.max_error_px * options.max_error_px;
  // Every triple when there are few; else max_iterations seeded draws (deterministic).
  std::vector<std::array<int, 3>> samples;
  const long long num_triples = static_cast<long long>(n) * (n - 1) * (n - 2) / 6;
  if (num_triples <= options.max_iterations) {
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j)
        for (int k = j + 1; k < n; ++k) samples.push_back({i, j, k});
  } else {
    SplitMix64 rng(0x6d6f64656c73ull);
    while (static_cast<int>(samples.size()) < options.max_iterations) {
      std::array<int, 3> sample;
      for (int& index : sample) index = static_cast<int>(rng.UniformInt(static_cast<uint32_t>(n)));
      if (sample[0] != sample[1] && sample[0] != sample[2] && sample[1] != sample[2]) samples.push_back(sample);
    }
  }
  ModelAlignment alignment;
  alignment.num_shared_points = n;
  std::vector<int> best;
  for (const std::array<int, 3>& sample : samples) {
    const Result<Sim3> candidate = Fit(to, from, shared, {sample[0], sample[1], sample[2]});
    if (!candidate.ok() || !(candidate->scale > 0.0)) continue;
    std::vector<int> inliers = Inliers(to, from, shared, *candidate, max_squared_error);
    if (inliers.size() <= best.size()) continue;
    best = std::move(inliers);
    alignment.to_from_from = *candidate;
    alignment.num_inliers = static_cast<int>(best.size());
  }
  // Refit on the inliers while that keeps or adds to them.
  for (int round = 0; round < 3 && best.size() >= 3; ++round) {
    const Result<Sim3> refit = Fit(to, from, shared, best);
    if (!refit.ok() || !(refit->scale > 0.0)) break;
    std::vector<int> inliers = Inliers(to, from, shared, *refit, max_squared_error);
    if (inliers.size() < best.size()) break;
    alignment.to_from_from = *refit;
    alignment.num_inliers = static_cast<int>(inliers.size());
    if (inliers == best) break;
    best = std::move(inliers);
  }
  if (alignment.num_inliers < needed) {
    return FailedPrecondition("no similarity explains enough shared points: " + std::to_string(alignment.num_inliers) +
                              " of " + std::to_string(n) + " within " + FormatPixels(options.max_error_px) + ", need " +
                              std::to_string(needed));
  }
  return alignment;
}

namespace {

// The keypoints of `image` matched in `pair` (as its side of the pair) whose point `model` holds,
// with the other image's keypoint of each match.
struct PairPoints {
  std::vector<Eigen::Vector3d> world;      // the points, in `model`'s frame
  std::vector<Eigen::Vector2d> there;      // the other image's keypoints (pixels)
};
PairPoints PointsInPair(const Reconstruction& model, const Reconstruction& other, const MapperPair& pair, int image) {
  PairPoints out;
  const bool image_is_a = pair.matches.image_a == image;
  const SfmImage& there = other.images[static_cast<size_t>(image_is_a ? pair.matches.image_b : pair.matches.image_a)];
  for (const FeatureMatch& m : pair.matches.matches) {
    const int point = PointAt(model, image, image_is_a ? m.index_a : m.index_b);
    if (point < 0) continue;
    out.world.push_back(model.points[static_cast<size_t>(point)].position);
    out.there.push_back(there.keypoints[static_cast<size_t>(image_is_a ? m.index_b : m.index_a)]);
  }
  return out;
}

}  // namespace

Result<ModelAlignment> AlignModelsByTwoViewGeometry(const Reconstruction& to, const Reconstruction& from,
                                                    const std::vector<MapperPair>& pairs, const MapperOptions& options,
                                                    int min_points) {
  // `to` with `from`'s cameras where `to` has not refined them: the pair's intrinsics.
  MapperModel model;
  model.rec = to;
  std::vector<bool> used(to.cameras.size(), false);
  for (const SfmImage& image : to.images) {
    if (image.registered) used[static_cast<size_t>(image.camera_id)] = true;
  }
  for (size_t c = 0; c < used.size() && c < from.cameras.size(); ++c) {
    if (!used[c]) model.rec.cameras[c] = from.cameras[c];
  }
  ModelAlignment best;
  int best_support = -1, pairs_tried = 0;
  std::string counts;
  for (const MapperPair& pair : pairs) {
    const int a = pair.matches.image_a, b = pair.matches.image_b;
    int i = -1, j = -1;  // i in `to`, j in `from`
    if (to.images[static_cast<size_t>(a)].registered && from.images[static_cast<size_t>(b)].registered) i = a, j = b;
    if (to.images[static_cast<size_t>(b)].registered && from.images[static_cast<size_t>(a)].registered) i = b, j = a;
    if (i < 0) continue;
    ++pairs_tried;
    const Result<PairPose> pose = EstimatePairPose(model, pair, options);
    if (!pose.ok() || pose->num_inliers < options.registration_min_inliers) continue;
    // cam_j_from_cam_i = {R_ji, length * t_ji}, t_ji of unit length.
    const Rigid3 j_from_i = a == i ? pose->b_from_a : pose->b_from_a.Inverse();
    const Eigen::Matrix3d& R_ji = j_from_i.rotation;
    const Eigen::Vector3d t_ji = j_from_i.translation.normalized();
    const Rigid3& i_from_to = to.images[static_cast<size_t>(i)].cam_from_world;
    const Rigid3& j_from_from = from.images[static_cast<size_t>(j)].cam_from_world;
    const SfmCamera& camera_i = model.rec.cameras[static_cast<size_t>(to.images[static_cast<size_t>(i)].camera_id)];
    const SfmCamera& camera_j = model.rec.cameras[static_cast<size_t>(from.images[static_cast<size_t>(j)].camera_id)];
    // The baseline's length in `to`'s units: `to`'s points seen by i, on j's rays.
    const PairPoints to_points = PointsInPair(to, from, pair, i);
    const BaselineFit length =
        FitBaselineLength(camera_j, R_ji * i_from_to.rotation, R_ji * i_from_to.translation, t_ji, to_points.there,
                          to_points.world, options.registration_max_error_px);
    // The same length in `from`'s units: `from`'s points, in j's frame, on i's rays. From i,
    // a point at Y in j's frame is at R_ji^T (Y - length_from * t_ji).
    PairPoints from_points = PointsInPair(from, to, pair, j);
    for (Eigen::Vector3d& point : from_points.world) point = j_from_from * point;
    const BaselineFit length_from = FitBaselineLength(camera_i, R_ji.transpose(), Eigen::Vector3d::Zero(),
                                                      -(R_ji.transpose() * t_ji), from_points.there,
                                                      from_points.world, options.registration_max_error_px);
    const int support = static_cast<int>(std::min(length.inliers.size(), length_from.inliers.size()));
    if (support > best_support) {
      counts = std::to_string(length.inliers.size()) + " of " + std::to_string(to_points.world.size()) + " and " +
               std::to_string(length_from.inliers.size()) + " of " + std::to_string(from_points.world.size());
    }
    if (support <= best_support || support < min_points || !(length.length > 0.0) || !(length_from.length > 0.0))
      continue;
    best_support = support;
    // X_to = (j_from_to)^-1 (scale * (j_from_from X_from)), j_from_to = {R_ji R_i, R_ji t_i + length t_ji}.
    const double scale = length.length / length_from.length;
    const Eigen::Matrix3d to_from_j = (R_ji * i_from_to.rotation).transpose();
    best.to_from_from.scale = scale;
    best.to_from_from.rotation = to_from_j * j_from_from.rotation;
    best.to_from_from.translation =
        to_from_j * (scale * j_from_from.translation - R_ji * i_from_to.translation - length.length * t_ji);
    best.num_shared_points = static_cast<int>(to_points.world.size() + from_points.world.size());
    best.num_inliers = static_cast<int>(length.inliers.size() + length_from.inliers.size());
    best.pair_to_image = i;
    best.pair_from_image = j;
  }
  if (best.pair_to_image < 0) {
    return FailedPrecondition(
        pairs_tried == 0 ? "no verified pair joins the models"
                         : "no verified pair between the models fixes the baseline from both (" +
                               std::to_string(min_points) + " points each)" +
                               (counts.empty() ? std::string() : "; at best " + counts + " points agree"));
  }
  return best;
}

Reconstruction CombineRegisteredImages(const Reconstruction& to, const Reconstruction& from, const Sim3& to_from_from) {
  Reconstruction combined = to;
  combined.points.clear();
  for (SfmImage& image : combined.images) std::fill(image.point3d_ids.begin(), image.point3d_ids.end(), -1);
  std::vector<bool> camera_used(combined.cameras.size(), false);
  for (const SfmImage& image : to.images) {
    if (image.registered) camera_used[static_cast<size_t>(image.camera_id)] = true;
  }
  // A camera of `from` scaled by s about the world: X_cam' = s X_cam, which projects the same.
  const Eigen::Matrix3d rotation_t = to_from_from.rotation.transpose();
  for (size_t i = 0; i < combined.images.size() && i < from.images.size(); ++i) {
    const SfmImage& source = from.images[i];
    SfmImage& target = combined.images[i];
    if (target.registered || !source.registered) continue;
    target.registered = true;
    target.cam_from_world.rotation = source.cam_from_world.rotation * rotation_t;
    target.cam_from_world.translation = to_from_from.scale * source.cam_from_world.translation -
                                        target.cam_from_world.rotation * to_from_from.translation;
    const size_t camera = static_cast<size_t>(source.camera_id);
    if (camera < camera_used.size() && camera < from.cameras.size() && !camera_used[camera])
      combined.cameras[camera] = from.cameras[camera];
  }
  return combined;
}

}  // namespace reconar
