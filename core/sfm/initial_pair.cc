#include "core/sfm/initial_pair.h"

#include <algorithm>
#include <cmath>

#include "core/base/median.h"
#include "core/sfm/mapper_adjustment.h"
#include "core/sfm/pair_pose.h"
#include "core/sfm/point_filter.h"
#include "core/sfm/track_triangulation.h"

namespace reconar {

namespace {

constexpr double kDegree = M_PI / 180.0;

// The triangulation angles (radians, sorted ascending) of a pair's inliers under a quick
// two-view reconstruction: the relative pose, then the angle between each inlier's two viewing
// rays. Empty when no pose was found.
std::vector<double> QuickTriangulationAngles(const MapperModel& model, const MapperPair& pair,
                                             const MapperOptions& options) {
  std::vector<double> angles;
  const auto pose = EstimatePairPose(model, pair, options, PairPoseSearch::kQuick);
  if (!pose.ok()) return angles;
  const Reconstruction& rec = model.rec;
  const SfmImage& ia = rec.images[static_cast<size_t>(pair.matches.image_a)];
  const SfmImage& ib = rec.images[static_cast<size_t>(pair.matches.image_b)];
  const SfmCamera& ca = rec.cameras[static_cast<size_t>(ia.camera_id)];
  const SfmCamera& cb = rec.cameras[static_cast<size_t>(ib.camera_id)];
  const Eigen::Matrix3d a_from_b = pose->b_from_a.rotation.transpose();
  for (size_t i = 0; i < pair.matches.matches.size(); ++i) {
    if (!pose->inlier[i]) continue;
    const FeatureMatch& m = pair.matches.matches[i];
    Eigen::Vector2d xa, xb;
    if (!ca.Undistort(ia.keypoints[static_cast<size_t>(m.index_a)], &xa) ||
        !cb.Undistort(ib.keypoints[static_cast<size_t>(m.index_b)], &xb))
      continue;
    const Eigen::Vector3d ray_a = xa.homogeneous().normalized();
    const Eigen::Vector3d ray_b = a_from_b * xb.homogeneous().normalized();
    angles.push_back(std::acos(std::clamp(ray_a.dot(ray_b), -1.0, 1.0)));
  }
  std::sort(angles.begin(), angles.end());
  return angles;
}

std::string PairName(const std::vector<MapperImage>& images, const MapperPair& pair) {
  return images[static_cast<size_t>(pair.matches.image_a)].name + " + " +
         images[static_cast<size_t>(pair.matches.image_b)].name;
}

std::string QuickReason(const std::vector<MapperImage>& images, const MapperPair& pair,
                        const std::vector<double>& angles) {
  if (angles.empty()) return PairName(images, pair) + ": no relative pose";
  return PairName(images, pair) + ": a quick two-view reconstruction gives " + std::to_string(angles.size()) +
         " inliers at a median triangulation angle of " + std::to_string(angles[angles.size() / 2] / kDegree) + " deg";
}

// Whether a quick reconstruction with these angles could meet `bounds`.
bool CouldMeet(const std::vector<double>& angles, const InitialPairBounds& bounds) {
  return static_cast<int>(angles.size()) >= bounds.min_points &&
         angles[angles.size() / 2] >= bounds.min_median_angle_deg * kDegree;
}

}  // namespace

Status InitializeFromBestPair(MapperModel* model, const std::vector<MapperImage>& images,
                              const std::vector<MapperPair>& pairs, const MapperOptions& options, MapperReport* report,
                              const std::set<std::pair<int, int>>& excluded, InitialPairOrder order_by,
                              InitialPairScores* scores) {
  InitialPairScores local_scores;
  InitialPairScores& quick = scores != nullptr ? *scores : local_scores;
  if (quick.scored.size() != pairs.size()) {
    quick.angles.assign(pairs.size(), {});
    quick.scored.assign(pairs.size(), 0);
  }
  std::vector<int> order;
  for (size_t p = 0; p < pairs.size(); ++p) {
    if (!pairs[p].planar && excluded.count({pairs[p].matches.image_a, pairs[p].matches.image_b}) == 0)
      order.push_back(static_cast<int>(p));
  }
  std::stable_sort(order.begin(), order.end(), [&pairs](int a, int b) {
    return pairs[static_cast<size_t>(a)].matches.matches.size() > pairs[static_cast<size_t>(b)].matches.matches.size();
  });
  if (order.empty()) {
    return FailedPrecondition(
        "no image pair has enough verified matches with parallax to start a reconstruction "
        "(the photos may be unrelated, too few, or taken from one spot)");
  }
  // Pairs are taken in match-count order, but only those whose quick two-view reconstruction could
  // meet the bounds are tried; they are scored in batches, as far down the list as needed, so that
  // a dense sequence, whose best-matched pairs are neighbours without baseline, reaches the wider
  // pairs further down. A model no third image can join is kept only as the last resort.
  const size_t max_scored = options.init_max_pairs_scored > 0
                                ? std::min(order.size(), static_cast<size_t>(options.init_max_pairs_scored))
                                : order.size();
  constexpr size_t kBatch = 32;
  size_t num_scored = 0;  // the first pairs of `order` that have their quick score
  auto angles_of = [&](size_t k) -> const std::vector<double>& { return quick.angles[static_cast<size_t>(order[k])]; };
  struct DeadEnd {
    int pair = -1;
    InitialPairBounds bounds;
    int round = 0;
  } dead_end;
  std::string last_reason;
  InitialPairBounds bounds{options.init_min_points, options.init_min_median_angle_deg};
  auto accept = [&](const MapperPair& pair, int round) {
    report->initial_pair = PairName(images, pair);
    report->initial_image_a = pair.matches.image_a;
    report->initial_image_b = pair.matches.image_b;
    report->init_relaxations = round;
    report->init_pairs_scored = static_cast<int>(num_scored);
  };
  std::string skipped;  // why the best-matched pair skipped in the last round could not meet the bounds
  auto score_up_to = [&](size_t end) {
    for (; num_scored < end; ++num_scored) {
      const size_t p = static_cast<size_t>(order[num_scored]);
      if (!quick.scored[p]) quick.angles[p] = QuickTriangulationAngles(*model, pairs[p], options);
      quick.scored[p] = 1;
    }
  };
  for (int round = 0;; ++round) {
    int tries = 0;
    skipped.clear();
    // In kGeometry order every pair is scored first, then taken by its well-triangulated inliers.
    std::vector<size_t> sequence;
    if (order_by == InitialPairOrder::kGeometry) {
      score_up_to(max_scored);
      std::vector<int> well(max_scored);
      for (size_t k = 0; k < max_scored; ++k) {
        const std::vector<double>& a = angles_of(k);
        well[k] =
            static_cast<int>(a.end() - std::lower_bound(a.begin(), a.end(), bounds.min_median_angle_deg * kDegree));
        sequence.push_back(k);
      }
      std::stable_sort(sequence.begin(), sequence.end(), [&well](size_t x, size_t y) { return well[x] > well[y]; });
    }
    for (size_t step = 0; step < max_scored && tries < options.init_max_pairs_tried; ++step) {
      const size_t k = sequence.empty() ? step : sequence[step];
      if (k == num_scored) score_up_to(std::min(max_scored, k + kBatch));
      if (!CouldMeet(angles_of(k), bounds)) {
        if (skipped.empty()) skipped = QuickReason(images, pairs[static_cast<size_t>(order[k])], angles_of(k));
        continue;
      }
      ++tries;
      const MapperPair& pair = pairs[static_cast<size_t>(order[k])];
      RECONAR_ASSIGN_OR_RETURN(last_reason, TryInitialPair(model, images, pair, bounds, options, report));
      if (!last_reason.empty()) continue;
      last_reason = CheckExtendable(*model, PairName(images, pair), options);
      if (last_reason.empty()) {
        accept(pair, round);
        return Status::Ok();
      }
      if (dead_end.pair < 0) dead_end = {order[k], bounds, round};
      model->Reset();
    }
    const int next_points = std::max(options.init_min_points_floor, bounds.min_points / 2);
    const double next_angle = std::max(options.init_min_angle_floor_deg, bounds.min_median_angle_deg / 2.0);
    if (next_points == bounds.min_points && next_angle == bounds.min_median_angle_deg) break;
    bounds.min_points = next_points;
    bounds.min_median_angle_deg = next_angle;
  }
  if (dead_end.pair >= 0) {
    const MapperPair& pair = pairs[static_cast<size_t>(dead_end.pair)];
    RECONAR_ASSIGN_OR_RETURN(last_reason, TryInitialPair(model, images, pair, dead_end.bounds, options, report));
    if (last_reason.empty()) {
      accept(pair, dead_end.round);
      return Status::Ok();
    }
  }
  if (last_reason.empty()) last_reason = skipped;
  return FailedPrecondition("no initial pair found among the " + std::to_string(num_scored) +
                            " best-matched pairs, even with the bounds relaxed to " +
                            std::to_string(bounds.min_points) + " points and " +
                            std::to_string(bounds.min_median_angle_deg) + " deg; last: " + last_reason);
}

Result<std::string> TryInitialPair(MapperModel* model, const std::vector<MapperImage>& images, const MapperPair& pair,
                                   const InitialPairBounds& bounds, const MapperOptions& options,
                                   MapperReport* report) {
  Reconstruction& rec = model->rec;
  const int a = pair.matches.image_a, b = pair.matches.image_b;
  const std::string pair_name = PairName(images, pair);
  const auto pose = EstimatePairPose(*model, pair, options);
  if (!pose.ok()) return pair_name + ": " + pose.status().message();

  SfmImage& ia = rec.images[static_cast<size_t>(a)];
  SfmImage& ib = rec.images[static_cast<size_t>(b)];
  ia.cam_from_world = Rigid3();
  ib.cam_from_world = pose->b_from_a;
  ia.registered = ib.registered = true;
  TriangulateImage(model, b, options);
  std::string reason = CheckInitialModel(*model, pair_name, bounds);
  if (reason.empty()) {
    MapperAdjustment adjustment;
    adjustment.iterations = options.global_ba_iterations;
    adjustment.free.distortion = options.refine_distortion;
    RECONAR_RETURN_IF_ERROR(CountFailedAdjustment(
        BundleAdjust(model, images, model->RegisteredImages(), adjustment, options, report).status(), report));
    FilterPoints(model, model->AllPoints(), options);
    reason = CheckInitialModel(*model, pair_name, bounds);
  }
  if (!reason.empty()) {
    model->Reset();
    return reason;
  }
  return std::string();
}

std::string CheckExtendable(const MapperModel& model, const std::string& pair_name, const MapperOptions& options) {
  const int needed = std::min(options.registration_min_inliers, options.registration_min_verified_inliers);
  int best = -1;
  for (size_t i = 0; i < model.rec.images.size(); ++i) {
    if (model.rec.images[i].registered) continue;
    best = std::max(best, model.CountVisiblePoints(static_cast<int>(i)));
    if (best >= needed) return "";
  }
  if (best < 0) return "";
  return pair_name + ": no other image sees " + std::to_string(needed) + " of its " +
         std::to_string(model.AllPoints().size()) + " points (at most " + std::to_string(best) + ")";
}

std::string CheckInitialModel(const MapperModel& model, const std::string& pair_name, const InitialPairBounds& bounds) {
  std::vector<double> angles;
  for (size_t p = 0; p < model.rec.points.size(); ++p) {
    if (!model.rec.points[p].deleted) angles.push_back(model.MaxTriangulationAngle(model.rec.points[p]));
  }
  if (static_cast<int>(angles.size()) < bounds.min_points) {
    return pair_name + ": only " + std::to_string(angles.size()) + " points triangulated (need " +
           std::to_string(bounds.min_points) + ")";
  }
  const double median = MedianInPlace(angles.data(), angles.size());
  if (median < bounds.min_median_angle_deg * kDegree) {
    return pair_name + ": median triangulation angle " + std::to_string(median / kDegree) + " deg is below " +
           std::to_string(bounds.min_median_angle_deg) + " deg";
  }
  return "";
}

}  // namespace reconar
