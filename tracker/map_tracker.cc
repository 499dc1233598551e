#include "tracker/map_tracker.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <string>
#include <utility>

#include "core/base/elapsed.h"
#include "core/base/prng.h"
#include "core/geometry/absolute_pose.h"
#include "core/io/gray.h"
#include "core/math/rotation.h"

namespace reconar {
namespace {

using Clock = std::chrono::steady_clock;

// The pixel of a world point, false when it is not in front of the camera.
bool ProjectPoint(const RadialCamera& camera, const Rigid3& cam_from_world, const Eigen::Vector3d& world,
                  Eigen::Vector2d* pixel) {
  const Eigen::Vector3d x = cam_from_world * world;
  if (!(x.z() > 1e-9)) return false;
  *pixel = camera.Project(x);
  return pixel->allFinite();
}

}  // namespace

const char* MapTrackingStateName(MapTrackingState state) {
  switch (state) {
    case MapTrackingState::kTracking:
      return "tracking";
    case MapTrackingState::kRelocalising:
      return "relocalising";
    case MapTrackingState::kLost:
      return "lost";
  }
  return "unknown";
}

Status MapTrackerOptions::Check() const {
  if (!intrinsics.valid()) return InvalidArgument("MapTrackerOptions.intrinsics must be valid (fx, fy > 0)");
  if (!intrinsics.Camera().IsValid()) return InvalidArgument("MapTrackerOptions.intrinsics must be finite");
  RECONAR_RETURN_IF_ERROR(localizer.Check());
  RECONAR_RETURN_IF_ERROR(sift.Check());
  RECONAR_RETURN_IF_ERROR(flow.Check());
  if (max_tracked_points < 4) return InvalidArgument("MapTrackerOptions.max_tracked_points must be >= 4");
  if (lost_after_frames < 1) return InvalidArgument("MapTrackerOptions.lost_after_frames must be >= 1");
  if (!(max_error_px > 0.0)) return InvalidArgument("MapTrackerOptions.max_error_px must be > 0");
  if (min_inliers < 4) return InvalidArgument("MapTrackerOptions.min_inliers must be >= 4");
  if (min_inliers > max_tracked_points) {
    return InvalidArgument("MapTrackerOptions.min_inliers must not exceed max_tracked_points");
  }
  if (!(min_inlier_ratio >= 0.0 && min_inlier_ratio <= 1.0)) {
    return InvalidArgument("MapTrackerOptions.min_inlier_ratio must be in [0, 1]");
  }
  if (!(loss_scale_px > 0.0)) return InvalidArgument("MapTrackerOptions.loss_scale_px must be > 0");
  if (lost_relocalise_interval < 1) return InvalidArgument("MapTrackerOptions.lost_relocalise_interval must be >= 1");
  if (!(replenish_fraction > 0.0 && replenish_fraction <= 1.0)) {
    return InvalidArgument("MapTrackerOptions.replenish_fraction must be in (0, 1]");
  }
  if (grid_cell_px < 1) return InvalidArgument("MapTrackerOptions.grid_cell_px must be >= 1");
  if (!(max_view_angle_deg > 0.0 && max_view_angle_deg <= 180.0)) {
    return InvalidArgument("MapTrackerOptions.max_view_angle_deg must be in (0, 180]");
  }
  if (border_px < 0) return InvalidArgument("MapTrackerOptions.border_px must be >= 0");
  if (!(max_anchor_shift_px > 0.0)) return InvalidArgument("MapTrackerOptions.max_anchor_shift_px must be > 0");
  if (reanchor_interval < 0) return InvalidArgument("MapTrackerOptions.reanchor_interval must be >= 0");
  return Status::Ok();
}

MapTracker::MapTracker(const MapTrackerOptions& options, std::shared_ptr<const Localizer> localizer)
    : options_(options), localizer_(std::move(localizer)) {
  map_ = &localizer_->map();
  options_.localizer = localizer_->options();
}

MapTracker::~MapTracker() = default;

Result<std::unique_ptr<MapTracker>> MapTracker::Create(const LocalizationMap* map, const MapTrackerOptions& options) {
  if (map == nullptr) return InvalidArgument("MapTracker: no map");
  RECONAR_RETURN_IF_ERROR(options.Check());
  if (map->num_points() == 0) return InvalidArgument("MapTracker: the map has no point");
  RECONAR_ASSIGN_OR_RETURN(Localizer localizer, Localizer::Create(map, options.localizer));
  return Create(std::make_shared<const Localizer>(std::move(localizer)), options);
}

Result<std::unique_ptr<MapTracker>> MapTracker::Create(std::shared_ptr<const Localizer> localizer,
                                                       const MapTrackerOptions& options) {
  if (localizer == nullptr) return InvalidArgument("MapTracker: no localizer");
  RECONAR_RETURN_IF_ERROR(options.Check());
  const LocalizationMap* map = &localizer->map();
  if (map->num_points() == 0) return InvalidArgument("MapTracker: the map has no point");
  std::unique_ptr<MapTracker> tracker(new MapTracker(options, std::move(localizer)));
  const size_t num_points = map->points.size();
  // Mean viewing direction of each point: toward the keyframes that observed it.
  std::vector<Eigen::Vector3d> sum(num_points, Eigen::Vector3d::Zero());
  for (const MapKeyframe& keyframe : map->keyframes) {
    const Eigen::Vector3d centre = CameraCenterInWorld(keyframe.cam_from_world);
    for (const int32_t id : keyframe.point_ids) {
      if (id < 0 || static_cast<size_t>(id) >= num_points) continue;
      const Eigen::Vector3d ray = centre - map->points[static_cast<size_t>(id)];
      const double norm = ray.norm();
      if (norm > 0.0 && std::isfinite(norm)) sum[static_cast<size_t>(id)] += ray / norm;
    }
  }
  tracker->view_direction_.resize(num_points);
  for (size_t i = 0; i < num_points; ++i) {
    const double norm = sum[i].norm();
    tracker->view_direction_[i] = norm > 0.0 ? Eigen::Vector3f((sum[i] / norm).cast<float>()) : Eigen::Vector3f::Zero();
  }
  tracker->seed_order_.resize(num_points);
  std::iota(tracker->seed_order_.begin(), tracker->seed_order_.end(), 0);
  SplitMix64 random(0x6d61707472616b31ull);
  for (size_t i = num_points; i > 1; --i) {
    std::swap(tracker->seed_order_[i - 1], tracker->seed_order_[random.UniformInt(static_cast<uint32_t>(i))]);
  }
  tracker->followed_in_frame_.assign(num_points, -1);
  const size_t capacity = static_cast<size_t>(options.max_tracked_points);
  tracker->track_point_.resize(capacity);
  tracker->track_pixel_.resize(capacity);
  tracker->track_slot_.resize(capacity);
  tracker->corr_slot_.resize(capacity);
  tracker->free_slots_.resize(capacity);
  tracker->slot_used_.resize(capacity);
  tracker->template_floats_ = FlowTemplateFloats(options.flow.window_radius);
  tracker->templates_.resize(capacity * static_cast<size_t>(tracker->template_floats_));
  tracker->RebuildFreeSlots();
  tracker->guesses_.resize(capacity);
  tracker->flow_.resize(capacity);
  tracker->pixels_.resize(capacity);
  tracker->world_.resize(capacity);
  tracker->corr_point_.resize(capacity);
  tracker->indices_.resize(capacity);
  return tracker;
}

Status MapTracker::StartFrameSize(int width, int height) {
  CameraIntrinsics intrinsics = options_.intrinsics;
  if (intrinsics.width <= 0 || intrinsics.height <= 0) {
    intrinsics.width = width;
    intrinsics.height = height;
  }
  RECONAR_ASSIGN_OR_RETURN(const CameraIntrinsics scaled, ScaleIntrinsicsToFrame(intrinsics, width, height));
  camera_ = scaled.Camera();
  query_camera_ = QueryCamera();
  query_camera_.width = width;
  query_camera_.height = height;
  query_camera_.known = camera_;
  query_camera_.source = "intrinsics";
  SiftOptions sift = options_.sift;
  sift.arena_bytes = SiftExtractor::RequiredArenaBytes(width, height, sift);
  sift_ = std::make_unique<SiftExtractor>(sift);
  sift_image_ = Image<float>(width, height);
  grid_columns_ = (width + options_.grid_cell_px - 1) / options_.grid_cell_px;
  grid_rows_ = (height + options_.grid_cell_px - 1) / options_.grid_cell_px;
  grid_.assign(static_cast<size_t>(grid_columns_) * static_cast<size_t>(grid_rows_), 0);
  width_ = width;
  height_ = height;
  have_previous_frame_ = false;
  num_tracks_ = 0;
  have_last_pose_ = have_previous_pose_ = false;
  return Status::Ok();
}

int MapTracker::RefineAndGate(int count, Rigid3* pose, double* rms) {
  PoseRefinementOptions refinement;
  refinement.loss = LossType::kCauchy;
  refinement.loss_scale_px = options_.loss_scale_px;
  RadialCamera camera = camera_;
  Eigen::Matrix3d R = pose->rotation;
  Eigen::Vector3d t = pose->translation;
  for (int i = 0; i < count; ++i) indices_[static_cast<size_t>(i)] = i;
  NormalLmSummary summary =
      RefineAbsolutePoseInPlace(pixels_.data(), world_.data(), indices_.data(), count, refinement, &camera, &R, &t);
  if (summary.termination == LmTermination::kNumericFailure) return 0;
  const double max_squared = options_.max_error_px * options_.max_error_px;
  int inliers = 0;
  for (int i = 0; i < count; ++i) {
    if (SquaredPixelError(camera_, R, t, world_[static_cast<size_t>(i)], pixels_[static_cast<size_t>(i)]) <
        max_squared) {
      indices_[static_cast<size_t>(inliers++)] = i;
    }
  }
  if (inliers < 4) return 0;
  refinement.loss = LossType::kHuber;
  refinement.loss_scale_px = 1.0;
  summary =
      RefineAbsolutePoseInPlace(pixels_.data(), world_.data(), indices_.data(), inliers, refinement, &camera, &R, &t);
  if (summary.termination == LmTermination::kNumericFailure) return 0;
  // Compact the inliers of the final pose to the front.
  int kept = 0;
  double sum = 0.0;
  for (int i = 0; i < count; ++i) {
    const size_t s = static_cast<size_t>(i);
    const double squared = SquaredPixelError(camera_, R, t, world_[s], pixels_[s]);
    if (!(squared < max_squared)) continue;
    sum += squared;
    const size_t d = static_cast<size_t>(kept++);
    pixels_[d] = pixels_[s];
    world_[d] = world_[s];
    corr_point_[d] = corr_point_[s];
    corr_slot_[d] = corr_slot_[s];
  }
  pose->rotation = R;
  pose->translation = t;
  *rms = kept > 0 ? std::sqrt(sum / kept) : 0.0;
  return kept;
}

bool MapTracker::TrackFrame(const Rigid3& predicted, MapTrackerFrameReport* report) {
  const int n = num_tracks_;
  for (int i = 0; i < n; ++i) {
    const size_t s = static_cast<size_t>(i);
    Eigen::Vector2d pixel;
    guesses_[s] = ProjectPoint(camera_, predicted, map_->points[static_cast<size_t>(track_point_[s])], &pixel)
                      ? pixel.cast<float>()
                      : track_pixel_[s];
  }
  const ImagePyramid& previous = pyramids_[1 - current_];
  const ImagePyramid& next = pyramids_[current_];
  if (!TrackPoints(previous, next, options_.flow, track_pixel_.data(), guesses_.data(), n, flow_.data()).ok()) {
    return false;
  }
  // The flow's result is refined against the point's template from its first sighting (no drift),
  // and kept only when both agree.
  const double max_shift2 = options_.max_anchor_shift_px * options_.max_anchor_shift_px;
  for (int i = 0; i < n; ++i) {
    const size_t s = static_cast<size_t>(i);
    if (flow_[s].status != FlowStatus::kTracked || !options_.anchor_to_first_sighting) continue;
    const FlowResult anchored = AlignFlowTemplate(next, TemplateOf(track_slot_[s]), flow_[s].point, options_.flow);
    if (anchored.status != FlowStatus::kTracked || (anchored.point - flow_[s].point).squaredNorm() > max_shift2) {
      flow_[s].status = FlowStatus::kLargeError;
    } else {
      flow_[s].point = anchored.point;
    }
  }
  const auto collect = [&]() {
    int count = 0;
    for (int i = 0; i < n; ++i) {
      const size_t s = static_cast<size_t>(i);
      if (flow_[s].status != FlowStatus::kTracked) continue;
      const size_t d = static_cast<size_t>(count++);
      pixels_[d] = flow_[s].point.cast<double>();
      world_[d] = map_->points[static_cast<size_t>(track_point_[s])];
      corr_point_[d] = track_point_[s];
      corr_slot_[d] = track_slot_[s];
    }
    return count;
  };
  int count = collect();
  report->tracked_points = count;
  const int needed = std::max(options_.min_inliers, 4);
  if (count < needed) return false;
  Rigid3 pose = predicted;
  double rms = 0.0;
  int inliers = RefineAndGate(count, &pose, &rms);
  const auto passes = [&](int k) { return k >= needed && k >= options_.min_inlier_ratio * count; };
  if (!passes(inliers)) {
    // The prediction was too far off for the local refinement: P3P LO-RANSAC on the same
    // correspondences (allocates; off the steady state).
    const std::vector<Eigen::Vector2d> pixels(pixels_.begin(), pixels_.begin() + count);
    const std::vector<Eigen::Vector3d> world(world_.begin(), world_.begin() + count);
    AbsolutePoseOptions ransac = options_.localizer.pose;
    ransac.min_inliers = needed;
    ransac.max_error_px = options_.max_error_px;
    const Result<AbsolutePoseResult> estimate = EstimateAbsolutePose(pixels, world, camera_, ransac);
    if (!estimate.ok() || !estimate->success()) return false;
    // The correspondences were compacted by RefineAndGate: restore them from the flow.
    count = collect();
    pose = estimate->cam_from_world;
    inliers = RefineAndGate(count, &pose, &rms);
    report->ransac_fallback = true;
    if (!passes(inliers)) return false;
  }
  // The inliers are the followed points from now on.
  for (int i = 0; i < inliers; ++i) {
    const size_t s = static_cast<size_t>(i);
    track_point_[s] = corr_point_[s];
    track_pixel_[s] = pixels_[s].cast<float>();
    track_slot_[s] = corr_slot_[s];
  }
  num_tracks_ = inliers;
  RebuildFreeSlots();
  report->cam_from_world = pose;
  report->inliers = inliers;
  report->rms_reprojection_px = rms;
  return true;
}

Status MapTracker::Relocalise(ImageView<const uint8_t> gray, MapTrackerFrameReport* report) {
  const auto start = Clock::now();
  report->relocalisation_tried = true;
  Gray8ToFloat(gray, sift_image_.view());
  RECONAR_ASSIGN_OR_RETURN(const SiftFeatures features, sift_->Extract(sift_image_.view()));
  RECONAR_ASSIGN_OR_RETURN(const LocalizationResult result, localizer_->Localize(features, query_camera_));
  report->relocalise_ms = 1000.0 * SecondsSince(start);
  if (!result.registered) return Status::Ok();
  // The inliers (within max_error_px, up to the capacity, in the localizer's order: by map point
  // id) are the frame's; each is followed from its keypoint unless its window is flat.
  const double max_squared = options_.max_error_px * options_.max_error_px;
  int count = 0;
  double sum = 0.0;
  num_tracks_ = 0;  // the followed points are replaced by the relocalisation's
  RebuildFreeSlots();
  for (size_t i = 0; i < result.inlier_points.size() && count < options_.max_tracked_points; ++i) {
    const SiftKeypoint& keypoint = features.keypoints[static_cast<size_t>(result.inlier_keypoints[i])];
    const int32_t point = result.inlier_points[i];
    if (followed_in_frame_[static_cast<size_t>(point)] == frame_index_) continue;
    const Eigen::Vector2d pixel(keypoint.x, keypoint.y);
    const Eigen::Vector3d& world = map_->points[static_cast<size_t>(point)];
    const double squared =
        SquaredPixelError(camera_, result.cam_from_world.rotation, result.cam_from_world.translation, world, pixel);
    if (!(squared < max_squared)) continue;
    AddTrack(point, pixel.cast<float>());  // not followed when its window is flat; still an inlier
    sum += squared;
    const size_t d = static_cast<size_t>(count++);
    pixels_[d] = pixel;
    world_[d] = world;
    followed_in_frame_[static_cast<size_t>(point)] = frame_index_;
  }
  report->found = true;
  report->relocalised = true;
  report->cam_from_world = result.cam_from_world;
  report->inliers = count;
  report->rms_reprojection_px = count > 0 ? std::sqrt(sum / count) : 0.0;
  return Status::Ok();
}

void MapTracker::RebuildFreeSlots() {
  std::fill(slot_used_.begin(), slot_used_.end(), 0);
  for (int i = 0; i < num_tracks_; ++i) slot_used_[static_cast<size_t>(track_slot_[static_cast<size_t>(i)])] = 1;
  num_free_ = 0;
  for (size_t slot = slot_used_.size(); slot-- > 0;) {
    if (!slot_used_[slot]) free_slots_[static_cast<size_t>(num_free_++)] = static_cast<int32_t>(slot);
  }
}

bool MapTracker::AddTrack(int32_t point, const Eigen::Vector2f& pixel) {
  if (num_free_ == 0 || num_tracks_ >= options_.max_tracked_points) return false;
  const int32_t slot = free_slots_[static_cast<size_t>(num_free_ - 1)];
  if (!MakeFlowTemplate(pyramids_[current_], pixel, options_.flow, TemplateOf(slot))) return false;
  --num_free_;
  const size_t d = static_cast<size_t>(num_tracks_++);
  track_point_[d] = point;
  track_pixel_[d] = pixel;
  track_slot_[d] = slot;
  return true;
}

int MapTracker::Seed(const Rigid3& cam_from_world) {
  RebuildFreeSlots();
  std::fill(grid_.begin(), grid_.end(), 0);
  const int cell = options_.grid_cell_px;
  const auto cell_of = [&](const Eigen::Vector2f& p) {
    const int cx = std::clamp(static_cast<int>(p.x()) / cell, 0, grid_columns_ - 1);
    const int cy = std::clamp(static_cast<int>(p.y()) / cell, 0, grid_rows_ - 1);
    return static_cast<size_t>(cy) * static_cast<size_t>(grid_columns_) + static_cast<size_t>(cx);
  };
  for (int i = 0; i < num_tracks_; ++i) {
    const size_t s = static_cast<size_t>(i);
    grid_[cell_of(track_pixel_[s])] = 1;
    followed_in_frame_[static_cast<size_t>(track_point_[s])] = frame_index_;
  }
  const Eigen::Vector3f centre = CameraCenterInWorld(cam_from_world).cast<float>();
  const float min_cos = static_cast<float>(std::cos(options_.max_view_angle_deg * M_PI / 180.0));
  const double border = options_.border_px;
  const double max_x = width_ - 1 - border, max_y = height_ - 1 - border;
  int seeded = 0;
  for (const int32_t point : seed_order_) {
    if (num_tracks_ >= options_.max_tracked_points) break;
    const size_t p = static_cast<size_t>(point);
    if (followed_in_frame_[p] == frame_index_) continue;
    const Eigen::Vector3d& world = map_->points[p];
    Eigen::Vector2d pixel;
    if (!ProjectPoint(camera_, cam_from_world, world, &pixel)) continue;
    if (!(pixel.x() >= border && pixel.y() >= border && pixel.x() <= max_x && pixel.y() <= max_y)) continue;
    const Eigen::Vector3f ray = (centre - world.cast<float>()).normalized();
    if (!(ray.dot(view_direction_[p]) >= min_cos)) continue;
    const Eigen::Vector2f at = pixel.cast<float>();
    const size_t c = cell_of(at);
    if (grid_[c] || !AddTrack(point, at)) continue;
    grid_[c] = 1;
    followed_in_frame_[p] = frame_index_;
    ++seeded;
  }
  return seeded;
}

Status MapTracker::Track(ImageView<const uint8_t> gray, const Rigid3* prior_cam_from_world,
                         MapTrackerFrameReport* report) {
  const auto start = Clock::now();
  if (gray.empty()) return InvalidArgument("MapTracker: empty frame");
  if (report == nullptr) return InvalidArgument("MapTracker: no report");
  ++frame_index_;
  report->frame_index = frame_index_;
  report->found = report->relocalised = false;
  report->cam_from_world = Rigid3();
  report->inliers = 0;
  report->rms_reprojection_px = 0.0;
  report->inlier_pixels.clear();
  report->inlier_world_points.clear();
  report->inlier_pixels.reserve(static_cast<size_t>(options_.max_tracked_points));
  report->inlier_world_points.reserve(static_cast<size_t>(options_.max_tracked_points));
  report->tracked_points = report->seeded_points = 0;
  report->relocalisation_tried = report->ransac_fallback = report->from_prior = false;
  report->relocalise_ms = 0.0;

  if (gray.width != width_ || gray.height != height_) RECONAR_RETURN_IF_ERROR(StartFrameSize(gray.width, gray.height));
  current_ = 1 - current_;
  RECONAR_RETURN_IF_ERROR(pyramids_[current_].Build(gray, options_.flow.num_levels));

  // 1-3: prediction, flow, pose.
  std::optional<Rigid3> predicted;
  if (prior_cam_from_world != nullptr) {
    predicted = *prior_cam_from_world;
  } else if (have_last_pose_ && have_previous_pose_) {
    predicted = (last_pose_ * previous_pose_.Inverse()) * last_pose_;
  } else if (have_last_pose_) {
    predicted = last_pose_;
  }
  // The refinement only multiplies rotations onto the start: rounding in the products of the
  // motion model (or a prior that is not quite orthonormal) must not accumulate.
  if (predicted) predicted->rotation = NearestRotation(predicted->rotation);
  bool found = false;
  const bool can_track = num_tracks_ > 0 && have_previous_frame_ && predicted;
  if (can_track && options_.reanchor_interval > 0 && prior_cam_from_world == nullptr &&
      frames_since_relocalisation_ >= options_.reanchor_interval) {
    // Re-anchoring: the followed points are replaced by the relocalisation's SIFT matches; tracking
    // stays the fallback when it fails.
    RECONAR_RETURN_IF_ERROR(Relocalise(gray, report));
    found = report->found;
    if (!found) frames_since_relocalisation_ = 0;  // next try after another interval
  }
  if (!found && can_track) found = TrackFrame(*predicted, report);
  if (found) {
    report->found = true;
  } else {
    num_tracks_ = 0;
    if (prior_cam_from_world != nullptr) {
      // Restart from the prior: the map points it shows are followed from here (no pose yet).
      report->from_prior = true;
    } else {
      const bool due = state_ != MapTrackingState::kLost ||
                       frames_since_relocalisation_try_ + 1 >= options_.lost_relocalise_interval;
      if (due) {
        frames_since_relocalisation_try_ = 0;
        RECONAR_RETURN_IF_ERROR(Relocalise(gray, report));
      } else {
        ++frames_since_relocalisation_try_;
      }
    }
  }

  // 4: the pose's inliers, the motion model, new points.
  if (report->found) {
    for (int i = 0; i < report->inliers; ++i) {
      report->inlier_pixels.push_back(pixels_[static_cast<size_t>(i)]);
      report->inlier_world_points.push_back(world_[static_cast<size_t>(i)]);
    }
    frames_since_relocalisation_ = report->relocalised ? 0 : frames_since_relocalisation_ + 1;
    previous_pose_ = last_pose_;
    have_previous_pose_ = have_last_pose_;
    last_pose_ = report->cam_from_world;
    have_last_pose_ = true;
    frames_without_pose_ = 0;
    state_ = MapTrackingState::kTracking;
  } else {
    ++frames_without_pose_;
    have_previous_pose_ = false;
    if (report->from_prior) {
      last_pose_ = *prior_cam_from_world;
      have_last_pose_ = true;
    } else {
      have_last_pose_ = false;
    }
    state_ =
        frames_without_pose_ >= options_.lost_after_frames ? MapTrackingState::kLost : MapTrackingState::kRelocalising;
  }
  if (have_last_pose_ && num_tracks_ < static_cast<int>(options_.replenish_fraction * options_.max_tracked_points)) {
    report->seeded_points = Seed(last_pose_);
  }
  have_previous_frame_ = true;
  report->state = state_;
  report->track_ms = 1000.0 * SecondsSince(start);
  return Status::Ok();
}

}  // namespace reconar
