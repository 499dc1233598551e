#include "core/sfm/initial_pair.h"

#include <algorithm>
#include <cmath>

#include "core/sfm/mapper_adjustment.h"
#include "core/sfm/pair_pose.h"
#include "core/sfm/point_filter.h"
#include "core/sfm/track_triangulation.h"

namespace reconar {

Status InitializeFromBestPair(MapperModel* model, const std::vector<MapperImage>& images,
                              const std::vector<MapperPair>& pairs, const MapperOptions& options,
                              MapperReport* report) {
  std::vector<int> order;
  for (size_t p = 0; p < pairs.size(); ++p) {
    if (!pairs[p].planar) order.push_back(static_cast<int>(p));
  }
  std::stable_sort(order.begin(), order.end(), [&pairs](int a, int b) {
    return pairs[static_cast<size_t>(a)].matches.matches.size() > pairs[static_cast<size_t>(b)].matches.matches.size();
  });
  if (order.empty()) {
    return FailedPrecondition(
        "no image pair has enough verified matches with parallax to start a reconstruction "
        "(the photos may be unrelated, too few, or taken from one spot)");
  }
  std::string last_reason;
  const int tries = std::min(static_cast<int>(order.size()), options.init_max_pairs_tried);
  InitialPairBounds bounds{options.init_min_points, options.init_min_median_angle_deg};
  for (int round = 0;; ++round) {
    for (int k = 0; k < tries; ++k) {
      const MapperPair& pair = pairs[static_cast<size_t>(order[static_cast<size_t>(k)])];
      RECONAR_ASSIGN_OR_RETURN(last_reason, TryInitialPair(model, images, pair, bounds, options, report));
      if (last_reason.empty()) {
        report->initial_pair = images[static_cast<size_t>(pair.matches.image_a)].name + " + " +
                               images[static_cast<size_t>(pair.matches.image_b)].name;
        report->init_relaxations = round;
        return Status::Ok();
      }
    }
    const int next_points = std::max(options.init_min_points_floor, bounds.min_points / 2);
    const double next_angle = std::max(options.init_min_angle_floor_deg, bounds.min_median_angle_deg / 2.0);
    if (next_points == bounds.min_points && next_angle == bounds.min_median_angle_deg) break;
    bounds.min_points = next_points;
    bounds.min_median_angle_deg = next_angle;
  }
  return FailedPrecondition("no initial pair found among the " + std::to_string(tries) +
                            " best-matched pairs, even with the bounds relaxed to " +
                            std::to_string(bounds.min_points) + " points and " +
                            std::to_string(bounds.min_median_angle_deg) + " deg; last: " + last_reason);
}

Result<std::string> TryInitialPair(MapperModel* model, const std::vector<MapperImage>& images, const MapperPair& pair,
                                   const InitialPairBounds& bounds, const MapperOptions& options,
                                   MapperReport* report) {
  Reconstruction& rec = model->rec;
  const int a = pair.matches.image_a, b = pair.matches.image_b;
  const std::string pair_name = images[static_cast<size_t>(a)].name + " + " + images[static_cast<size_t>(b)].name;
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

std::string CheckInitialModel(const MapperModel& model, const std::string& pair_name, const InitialPairBounds& bounds) {
  constexpr double kDegree = M_PI / 180.0;
  std::vector<double> angles;
  for (size_t p = 0; p < model.rec.points.size(); ++p) {
    if (!model.rec.points[p].deleted) angles.push_back(model.MaxTriangulationAngle(model.rec.points[p]));
  }
  if (static_cast<int>(angles.size()) < bounds.min_points) {
    return pair_name + ": only " + std::to_string(angles.size()) + " points triangulated (need " +
           std::to_string(bounds.min_points) + ")";
  }
  std::nth_element(angles.begin(), angles.begin() + static_cast<std::ptrdiff_t>(angles.size() / 2), angles.end());
  const double median = angles[angles.size() / 2];
  if (median < bounds.min_median_angle_deg * kDegree) {
    return pair_name + ": median triangulation angle " + std::to_string(median / kDegree) + " deg is below " +
           std::to_string(bounds.min_median_angle_deg) + " deg";
  }
  return "";
}

}  // namespace reconar
