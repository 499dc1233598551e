#include "core/sfm/intrinsics_selection.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace reconar {
namespace {

// The adjustable part of a model: cameras, poses and point positions.
struct Snapshot {
  std::vector<SfmCamera> cameras;
  std::vector<Rigid3> poses;
  std::vector<Eigen::Vector3d> points;
};

Snapshot Save(const Reconstruction& rec) {
  Snapshot snapshot{rec.cameras, {}, {}};
  for (const SfmImage& image : rec.images) snapshot.poses.push_back(image.cam_from_world);
  for (const SfmPoint& point : rec.points) snapshot.points.push_back(point.position);
  return snapshot;
}

void Restore(const Snapshot& snapshot, Reconstruction* rec) {
  rec->cameras = snapshot.cameras;
  for (size_t i = 0; i < rec->images.size(); ++i) rec->images[i].cam_from_world = snapshot.poses[i];
  for (size_t p = 0; p < rec->points.size(); ++p) rec->points[p].position = snapshot.points[p];
}

// A principal point beyond this fraction of the image's size from its centre is no camera's: with a
// long lens on part of a ring, a shift of the principal point trades against a common tilt of the
// cameras (dinoSparseRing's first seven views put it 570 px below a 480 px image, 10 degrees off).
constexpr double kMaxPrincipalPointOffset = 0.25;
// Radial coefficients beyond this are bogus (COLMAP's max_extra_param): with a long lens, k1 and k2
// barely move the image and trade against the focal (templeSparseRing: k2 = 2.8 and the focal 4.5 %
// long; dinoSparseRing: k2 = 338).
constexpr double kMaxRadialCoefficient = 1.0;

// The candidate's cameras are plausible in what it refines (the principal point only when it is
// the data's choice: MapperOptions::PrincipalPoint::kAuto).
bool PlausibleCameras(const Reconstruction& rec, const IntrinsicsChoice& choice, bool principal_point_optional) {
  for (const SfmCamera& camera : rec.cameras) {
    if (choice.principal_point && principal_point_optional &&
        (std::fabs(camera.cx - 0.5 * (camera.width - 1)) > kMaxPrincipalPointOffset * camera.width ||
         std::fabs(camera.cy - 0.5 * (camera.height - 1)) > kMaxPrincipalPointOffset * camera.height))
      return false;
    if (choice.distortion &&
        (std::fabs(camera.k1) > kMaxRadialCoefficient || std::fabs(camera.k2) > kMaxRadialCoefficient))
      return false;
  }
  return true;
}

}  // namespace

Result<IntrinsicsChoice> SelectIntrinsicsModel(MapperModel* model, const std::vector<MapperImage>& images,
                                               const MapperOptions& options, MapperReport* report) {
  using PP = MapperOptions::PrincipalPoint;
  const Snapshot start = Save(model->rec);
  // The candidate's final cost (infinity when its adjustment failed numerically) and its state.
  const auto adjust = [&](const IntrinsicsChoice& choice, Snapshot* result) -> Result<double> {
    Restore(start, &model->rec);
    if (!choice.distortion) {
      for (SfmCamera& camera : model->rec.cameras) camera.k1 = camera.k2 = 0.0;
    }
    MapperAdjustment adjustment;
    adjustment.iterations = options.final_ba_iterations;
    adjustment.function_tolerance = options.final_ba_function_tolerance;
    adjustment.free = choice;
    const Result<double> cost = BundleAdjust(model, images, model->RegisteredImages(), adjustment, options, report);
    RECONAR_RETURN_IF_ERROR(CountFailedAdjustment(cost.status(), report));
    *result = Save(model->rec);
    const bool plausible = PlausibleCameras(model->rec, choice, options.principal_point == PP::kAuto);
    return cost.ok() && plausible ? cost.value() : std::numeric_limits<double>::infinity();
  };
  IntrinsicsChoice richest;
  richest.principal_point = options.principal_point != PP::kFixed;
  richest.distortion = options.refine_distortion;
  richest.aspect = options.refine_aspect;
  IntrinsicsChoice chosen;
  chosen.principal_point = options.principal_point == PP::kRefine;
  Snapshot chosen_state;
  double chosen_cost = 0.0;
  RECONAR_ASSIGN_OR_RETURN(chosen_cost, adjust(chosen, &chosen_state));
  const bool optional_pp = options.principal_point == PP::kAuto;
  if (optional_pp || richest.distortion || richest.aspect) {
    Snapshot richest_state;
    double richest_cost = 0.0;
    RECONAR_ASSIGN_OR_RETURN(richest_cost, adjust(richest, &richest_state));
    double residuals = 0.0;
    for (const SfmPoint& point : model->rec.points) {
      residuals += point.deleted ? 0.0 : 2.0 * static_cast<double>(point.track.size());
    }
    // The noise level from the richest model, or from the plainest when the richest is refused.
    const double reference_cost = std::isfinite(richest_cost) ? richest_cost : chosen_cost;
    const double s2 = std::max(2.0 * reference_cost / std::max(residuals, 1.0), 1e-12);
    const double cameras = static_cast<double>(model->rec.cameras.size());
    const auto bic = [&](const IntrinsicsChoice& c, double cost) {
      const double parameters = cameras * (2.0 * c.principal_point + 2.0 * c.distortion + 1.0 * c.aspect);
      return 2.0 * cost / s2 + parameters * std::log(std::max(residuals, 2.0));
    };
    double chosen_bic = bic(chosen, chosen_cost);
    // Forward selection: add the group that lowers the BIC most, while one does.
    while (true) {
      IntrinsicsChoice best_choice;
      Snapshot best_state;
      double best_cost = 0.0, best_bic = chosen_bic;
      bool improved = false;
      for (int group = 0; group < 3; ++group) {
        IntrinsicsChoice c = chosen;
        if (group == 0) {
          if (!optional_pp || c.principal_point) continue;
          c.principal_point = true;
        } else if (group == 1) {
          if (!richest.distortion || c.distortion) continue;
          c.distortion = true;
        } else {
          if (!richest.aspect || c.aspect) continue;
          c.aspect = true;
        }
        Snapshot state;
        double cost = 0.0;
        if (c == richest) {  // adjusted already, from the same start
          state = richest_state;
          cost = richest_cost;
        } else {
          RECONAR_ASSIGN_OR_RETURN(cost, adjust(c, &state));
        }
        const double b = bic(c, cost);
        if (std::isfinite(cost) && b < best_bic) {
          best_choice = c;
          best_state = std::move(state);
          best_cost = cost;
          best_bic = b;
          improved = true;
        }
      }
      if (!improved) break;
      chosen = best_choice;
      chosen_state = std::move(best_state);
      chosen_cost = best_cost;
      chosen_bic = best_bic;
    }
  }
  Restore(chosen_state, &model->rec);
  report->principal_point_refined = chosen.principal_point;
  report->distortion_refined = chosen.distortion;
  report->aspect_refined = chosen.aspect;
  return chosen;
}

}  // namespace reconar
