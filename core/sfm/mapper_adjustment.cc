#include "core/sfm/mapper_adjustment.h"

#include <algorithm>
#include <chrono>

#include "core/math/rotation.h"
#include "core/optim/bundle_adjuster.h"
#include "core/optim/radial_camera_model.h"

namespace reconar {
namespace {

using Clock = std::chrono::steady_clock;

// The observation's weight: its keypoint weight when given, else from its detection scale
// (MapperOptions::weight_by_scale), else 1.
double ObservationWeight(const std::vector<MapperImage>& images, const TrackElement& e, const MapperOptions& options) {
  const std::vector<float>& weights = images[static_cast<size_t>(e.image_id)].keypoint_weights;
  if (!weights.empty() && weights[static_cast<size_t>(e.keypoint_id)] > 0.0f) {
    return weights[static_cast<size_t>(e.keypoint_id)];
  }
  const std::vector<float>& scales = images[static_cast<size_t>(e.image_id)].keypoint_scales;
  if (scales.empty()) return 1.0;
  return ScaleWeight(scales[static_cast<size_t>(e.keypoint_id)], options);
}

}  // namespace

void AppendCameraBlock(const SfmImage& image, const SfmCamera& camera, RadialProblem* problem) {
  const Eigen::Vector3d w = AngleAxisFromRotation(image.cam_from_world.rotation);
  const Eigen::Vector3d& t = image.cam_from_world.translation;
  const double block[12] = {w.x(),        w.y(),     w.z(),     t.x(),     t.y(),     t.z(),
                            camera.focal, camera.k1, camera.k2, camera.cx, camera.cy, camera.aspect};
  problem->cameras.insert(problem->cameras.end(), block, block + 12);
}

double ScaleWeight(double keypoint_scale, const MapperOptions& options) {
  if (!options.weight_by_scale) return 1.0;
  return keypoint_scale > options.base_scale_px ? options.base_scale_px / keypoint_scale : 1.0;
}

Result<double> BundleAdjust(MapperModel* model, const std::vector<MapperImage>& images,
                            const std::vector<int>& variable, const MapperAdjustment& adjustment,
                            const MapperOptions& options, MapperReport* report) {
  const auto start = Clock::now();
  Reconstruction& rec = model->rec;
  std::vector<int> slot_of_image(rec.images.size(), -1);
  std::vector<int> image_of_slot;
  std::vector<char> constant;
  for (int image : variable) {
    slot_of_image[static_cast<size_t>(image)] = static_cast<int>(image_of_slot.size());
    image_of_slot.push_back(image);
    constant.push_back(0);
  }
  const std::vector<int> point_ids = model->PointsSeenBy(variable);
  RadialProblem problem;
  problem.points.reserve(3 * point_ids.size());
  for (size_t j = 0; j < point_ids.size(); ++j) {
    const SfmPoint& point = rec.points[static_cast<size_t>(point_ids[j])];
    problem.points.insert(problem.points.end(), point.position.data(), point.position.data() + 3);
    for (const TrackElement& e : point.track) {
      int& slot = slot_of_image[static_cast<size_t>(e.image_id)];
      if (slot < 0) {
        slot = static_cast<int>(image_of_slot.size());
        image_of_slot.push_back(e.image_id);
        constant.push_back(1);
      }
      const Eigen::Vector2d& x =
          rec.images[static_cast<size_t>(e.image_id)].keypoints[static_cast<size_t>(e.keypoint_id)];
      problem.observations.push_back({slot, static_cast<int>(j), x.x(), x.y(), ObservationWeight(images, e, options)});
    }
  }
  for (int image : image_of_slot) {
    const SfmImage& img = rec.images[static_cast<size_t>(image)];
    AppendCameraBlock(img, rec.cameras[static_cast<size_t>(img.camera_id)], &problem);
  }
  BundleAdjustmentOptions solver;
  solver.max_iterations = adjustment.iterations;
  solver.function_tolerance = adjustment.function_tolerance;
  solver.loss.type = LossType::kCauchy;
  solver.loss.scale = options.ba_loss_scale_px;
  solver.num_threads = options.num_threads;
  // Dense or sparse by the reduced system's size and fill, shared intrinsics or not: measured on
  // this mapper's global adjustments, sparse took 0.2 of dense's time on a 400-photo corridor walk
  // (2406 unknowns, fill 0.12) but 1.1-1.5x round a 320-photo object, where most camera pairs
  // share points (fill 0.66-1); the crossover, fill 0.6 from 500 unknowns, is in bundle_adjuster.h.
  solver.linear_solver = BundleAdjustmentOptions::LinearSolver::kAuto;
  BundleAdjustmentConstancy constancy;
  constancy.constant_cameras = constant;
  const bool global = variable.size() == static_cast<size_t>(rec.NumRegisteredImages());
  // A shared camera is adjusted only when all its images are (global adjustment).
  const bool intrinsics = rec.NumRegisteredImages() >= 3 && (global || !model->CameraShared());
  if (model->CameraShared()) {
    for (int image : image_of_slot)
      constancy.intrinsics_group.push_back(rec.images[static_cast<size_t>(image)].camera_id);
  }
  const IntrinsicsChoice& free = adjustment.free;
  if (!options.refine_focal || !intrinsics) constancy.constant_camera_parameters.push_back(6);
  if (!free.distortion || !intrinsics) {
    constancy.constant_camera_parameters.push_back(7);
    constancy.constant_camera_parameters.push_back(8);
  }
  if (!free.principal_point) {
    constancy.constant_camera_parameters.push_back(9);
    constancy.constant_camera_parameters.push_back(10);
  }
  if (!free.aspect) constancy.constant_camera_parameters.push_back(11);
  const auto summary = SolveBundleAdjustment(solver, constancy, &problem);
  report->seconds_ba += std::chrono::duration<double>(Clock::now() - start).count();
  if (global) {
    ++report->num_global_ba;
  } else {
    ++report->num_local_ba;
  }
  const char* kind = global ? "global bundle adjustment" : "local bundle adjustment";
  if (!summary.ok()) return summary.status().WithContext(kind);
  if (summary->termination == BundleAdjustmentSummary::Termination::kNumericFailure) {
    return NumericFailure(std::string(kind) + " of " + std::to_string(variable.size()) +
                          " images ended in numeric failure (final cost " + std::to_string(summary->final_cost) +
                          "); the model was left as is");
  }
  for (size_t slot = 0; slot < image_of_slot.size(); ++slot) {
    if (constant[slot]) continue;
    SfmImage& img = rec.images[static_cast<size_t>(image_of_slot[slot])];
    SfmCamera& cam = rec.cameras[static_cast<size_t>(img.camera_id)];
    const double* block = problem.camera(static_cast<int>(slot));
    img.cam_from_world.rotation = RotationFromAngleAxis(Eigen::Vector3d(block[0], block[1], block[2]));
    img.cam_from_world.translation = Eigen::Vector3d(block[3], block[4], block[5]);
    static_cast<RadialCamera&>(cam) = RadialCameraOfBlock(block);
  }
  for (size_t j = 0; j < point_ids.size(); ++j) {
    rec.points[static_cast<size_t>(point_ids[j])].position = Eigen::Vector3d(problem.point(static_cast<int>(j)));
  }
  return summary->final_cost;
}

Status CountFailedAdjustment(const Status& status, MapperReport* report) {
  if (status.ok()) return status;
  if (status.code() == StatusCode::kInvalidArgument) return status;
  if (report->num_failed_ba == 0) report->first_ba_failure = status.message();
  ++report->num_failed_ba;
  return Status::Ok();
}

std::vector<int> LocalBundle(const MapperModel& model, int image, const MapperOptions& options) {
  const Reconstruction& rec = model.rec;
  std::vector<int> shared(rec.images.size(), 0);
  for (int id : rec.images[static_cast<size_t>(image)].point3d_ids) {
    if (id < 0) continue;
    for (const TrackElement& e : rec.points[static_cast<size_t>(id)].track) {
      if (e.image_id != image) ++shared[static_cast<size_t>(e.image_id)];
    }
  }
  std::vector<int> order;
  for (size_t i = 0; i < shared.size(); ++i) {
    if (shared[i] > 0) order.push_back(static_cast<int>(i));
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](int x, int y) { return shared[static_cast<size_t>(x)] > shared[static_cast<size_t>(y)]; });
  if (static_cast<int>(order.size()) > options.local_ba_images)
    order.resize(static_cast<size_t>(options.local_ba_images));
  order.insert(order.begin(), image);
  return order;
}

}  // namespace reconar
