#include "core/sfm/mapper_adjustment.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include "core/math/rotation.h"
#include "core/optim/bundle_adjuster.h"
#include "core/optim/radial_camera_model.h"
#include "core/sfm/tag_observations.h"
#include "core/sfm/tag_squares.h"

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

// The square tags whose corners are all among the problem's points (tag_squares.h), each a frame
// block after the cameras with its corners anchored to it; their edge is the frame blocks' shared
// focal slot, in one intrinsics group after the cameras' (which `groups` gets when it had none).
void AddTagSquares(const Reconstruction& rec, const std::vector<MapperImage>& images, const std::vector<int>& point_ids,
                   const MapperOptions& options, RadialProblem* problem, std::vector<int>* groups) {
  if (!(options.tag_square_sigma > 0.0)) return;
  const TagSquares tags = FindTagSquares(rec, CornerKeypointsOfImages(images), options.square_tags);
  if (tags.squares.empty() || !(tags.edge > 0.0)) return;
  std::vector<int> index_of_point(rec.points.size(), -1);
  for (size_t j = 0; j < point_ids.size(); ++j) index_of_point[static_cast<size_t>(point_ids[j])] = static_cast<int>(j);
  const int num_cameras = problem->num_cameras();
  int group = 0;
  for (int g : *groups) group = std::max(group, g + 1);
  for (const TagSquare& square : tags.squares) {
    std::array<int, 4> points;
    bool all_in = true;
    for (size_t k = 0; k < 4; ++k) {
      points[k] = index_of_point[static_cast<size_t>(square.points[k])];
      all_in = all_in && points[k] >= 0;
    }
    if (!all_in) continue;
    const Rigid3 tag_from_world = square.world_from_tag.Inverse();
    const Eigen::Vector3d w = AngleAxisFromRotation(tag_from_world.rotation);
    const Eigen::Vector3d& t = tag_from_world.translation;
    const double block[12] = {w.x(), w.y(), w.z(), t.x(), t.y(), t.z(), tags.edge, 0.0, 0.0, 0.0, 0.0, 1.0};
    const int frame = problem->num_cameras();
    problem->cameras.insert(problem->cameras.end(), block, block + 12);
    for (size_t k = 0; k < 4; ++k) {
      PointAnchor anchor;
      anchor.frame = frame;
      anchor.point = points[k];
      anchor.local[0] = kTagCornerUnits[k][0] / 2.0;
      anchor.local[1] = kTagCornerUnits[k][1] / 2.0;
      anchor.weight = 1.0 / options.tag_square_sigma;
      problem->point_anchors.push_back(anchor);
    }
  }
  if (problem->num_cameras() == num_cameras) return;
  if (groups->empty()) groups->assign(static_cast<size_t>(num_cameras), -1);
  groups->resize(static_cast<size_t>(problem->num_cameras()), group);
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
  // The squares are a constraint on the model's shape at the scale of the room, which a local
  // adjustment (most cameras held) cannot correct; there a square's pull on newly triangulated
  // corners pushed their observations past the outlier bound and split tags (the room's even half).
  if (global) {
    AddTagSquares(rec, images, point_ids, options, &problem, &constancy.intrinsics_group);
    constancy.constant_cameras.resize(static_cast<size_t>(problem.num_cameras()), 0);
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

std::vector<double> CrossCheckTagSquares(const Reconstruction& rec, const std::vector<MapperImage>& images,
                                         const MapperOptions& options, MapperReport* report) {
  std::vector<double> errors;
  if (!(options.tag_square_sigma > 0.0)) return errors;
  const std::vector<TagCornerKeypoint> corner_keypoints = CornerKeypointsOfImages(images);
  const TagSquares all = FindTagSquares(rec, corner_keypoints, options.square_tags);
  if (all.squares.size() < 2) return errors;
  for (size_t fold = 0; fold < 2; ++fold) {
    MapperOptions held = options;
    held.square_tags.clear();
    for (size_t t = 0; t < all.squares.size(); ++t) {
      if (t % 2 != fold) held.square_tags.push_back(all.squares[t].tag_id);
    }
    MapperModel model;
    model.rec = rec;
    MapperAdjustment adjustment;
    adjustment.iterations = options.final_ba_iterations;
    adjustment.function_tolerance = options.final_ba_function_tolerance;
    if (!BundleAdjust(&model, images, model.RegisteredImages(), adjustment, held, report).ok()) continue;
    const TagSquares squares = FindTagSquares(model.rec, corner_keypoints, held.square_tags);
    if (!(squares.edge > 0.0)) continue;
    const auto position = [&model](int point) { return model.rec.points[static_cast<size_t>(point)].position; };
    for (size_t t = fold; t < all.squares.size(); t += 2) {
      const std::array<int, 4>& points = all.squares[t].points;
      for (int s = 0; s < 6; ++s) {
        const double length = (position(points[static_cast<size_t>(kTagSegments[s][1])]) -
                               position(points[static_cast<size_t>(kTagSegments[s][0])])).norm();
        errors.push_back(length / (s < 4 ? squares.edge : std::sqrt(2.0) * squares.edge) - 1.0);
      }
    }
  }
  return errors;
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
