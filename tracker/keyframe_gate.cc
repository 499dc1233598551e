#include "tracker/keyframe_gate.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "core/base/median.h"
#include "core/base/prng.h"
#include "core/geometry/homography_four_point.h"
#include "core/geometry/triangulation.h"

namespace reconar {
namespace {

constexpr int kHighlightLevel = 251;
constexpr int kPyramidLevels = 3;
constexpr float kMaxForwardBackwardPx = 1.0f;  // analysis pixels
constexpr double kHomographyInlierPx = 1.0;    // analysis pixels
constexpr int kHomographyIterations = 64;

}  // namespace

const char* GateVerdictName(GateVerdict verdict) {
  switch (verdict) {
    case GateVerdict::kKeyframe:
      return "keyframe";
    case GateVerdict::kBlurred:
      return "blurred";
    case GateVerdict::kBadExposure:
      return "bad exposure";
    case GateVerdict::kTooClose:
      return "too close to the last keyframe";
    case GateVerdict::kLost:
      return "lost";
  }
  return "?";
}

Status KeyframeGateOptions::Check() const {
  if (analysis_width < 64) return InvalidArgument("KeyframeGateOptions: analysis_width < 64");
  if (!(sharpness_ratio > 0.0 && sharpness_ratio <= 1.0))
    return InvalidArgument("KeyframeGateOptions: sharpness_ratio must be in (0, 1]");
  if (sharpness_window < 1 || sharpness_window > 64)
    return InvalidArgument("KeyframeGateOptions: sharpness_window must be in [1, 64]");
  if (min_history < 1 || min_history > sharpness_window)
    return InvalidArgument("KeyframeGateOptions: min_history must be in [1, sharpness_window]");
  if (!(max_highlight_fraction > 0.0 && max_highlight_fraction <= 1.0))
    return InvalidArgument("KeyframeGateOptions: max_highlight_fraction must be in (0, 1]");
  if (!(min_bright_level >= 0.0 && max_dark_level <= 255.0))
    return InvalidArgument("KeyframeGateOptions: need min_bright_level >= 0 and max_dark_level <= 255");
  if (!(keyframe_parallax > 0.0)) return InvalidArgument("KeyframeGateOptions: keyframe_parallax <= 0");
  if (!(keyframe_angle_deg > 0.0 && keyframe_angle_deg < 90.0))
    return InvalidArgument("KeyframeGateOptions: keyframe_angle_deg must be in (0, 90)");
  if (!(lost_overlap >= 0.0 && keyframe_overlap > lost_overlap && keyframe_overlap <= 1.0))
    return InvalidArgument("KeyframeGateOptions: need 0 <= lost_overlap < keyframe_overlap <= 1");
  if (!(max_frame_motion > 0.0)) return InvalidArgument("KeyframeGateOptions: max_frame_motion <= 0");
  if (grid_columns < 2 || grid_rows < 2 || grid_columns * grid_rows > 256)
    return InvalidArgument("KeyframeGateOptions: the grid needs 2 x 2 to 256 cells");
  if (lost_frames_to_restart < 1) return InvalidArgument("KeyframeGateOptions: lost_frames_to_restart < 1");
  return Status::Ok();
}

KeyframeGate::KeyframeGate(const KeyframeGateOptions& options) : options_(options) {
  flow_options_.window_radius = 5;
  flow_options_.num_levels = kPyramidLevels;
}

// Box filter by factor_: the factor_ input rows of an output row summed into column_sums_ (a loop
// the compiler vectorises), then each run of factor_ sums added.
void KeyframeGate::Downscale(ImageView<const uint8_t> gray) {
  const int f = factor_;
  const int area = f * f;
  const int used_width = small_.width() * f;
  uint32_t* sums = column_sums_.data();
  for (int y = 0; y < small_.height(); ++y) {
    const uint8_t* first = gray.row(y * f);
    for (int x = 0; x < used_width; ++x) sums[x] = first[x];
    for (int dy = 1; dy < f; ++dy) {
      const uint8_t* in = gray.row(y * f + dy);
      for (int x = 0; x < used_width; ++x) sums[x] += in[x];
    }
    uint8_t* out = small_.row(y);
    for (int x = 0; x < small_.width(); ++x) {
      uint32_t sum = 0;
      for (int dx = 0; dx < f; ++dx) sum += sums[x * f + dx];
      out[x] = static_cast<uint8_t>((sum + static_cast<uint32_t>(area / 2)) / static_cast<uint32_t>(area));
    }
  }
}

// Exposure on the analysis image; sharpness on the frame itself, at every other pixel of every
// other row (the box filter would take away the finest detail that blur removes first).
void KeyframeGate::MeasureImage(ImageView<const uint8_t> gray, GateFrameReport* report) const {
  const int w = small_.width(), h = small_.height();
  std::array<int, 256> histogram{};
  long long level_sum = 0;
  for (int y = 0; y < h; ++y) {
    const uint8_t* row = small_.row(y);
    for (int x = 0; x < w; ++x) {
      level_sum += row[x];
      ++histogram[row[x]];
    }
  }
  const long long pixels = static_cast<long long>(w) * h;
  report->mean_level = static_cast<double>(level_sum) / static_cast<double>(pixels);
  long long below = 0, highlights = 0;
  int dark = -1, bright = -1;
  for (int level = 0; level < 256; ++level) {
    below += histogram[static_cast<size_t>(level)];
    if (dark < 0 && 20 * below > pixels) dark = level;
    if (bright < 0 && 20 * below >= 19 * pixels) bright = level;
    if (level >= kHighlightLevel) highlights += histogram[static_cast<size_t>(level)];
  }
  report->dark_level = dark;
  report->bright_level = bright;
  report->highlight_fraction = static_cast<double>(highlights) / static_cast<double>(pixels);
  long long laplacian_sum = 0, laplacian_squares = 0, count = 0;
  for (int y = 1; y + 1 < gray.height; y += 2) {
    const uint8_t* up = gray.row(y - 1);
    const uint8_t* row = gray.row(y);
    const uint8_t* down = gray.row(y + 1);
    for (int x = 1; x + 1 < gray.width; x += 2) {
      const int laplacian = up[x] + down[x] + row[x - 1] + row[x + 1] - 4 * row[x];
      laplacian_sum += laplacian;
      laplacian_squares += laplacian * laplacian;
      ++count;
    }
  }
  const double mean = count > 0 ? static_cast<double>(laplacian_sum) / count : 0.0;
  report->sharpness = count > 0 ? static_cast<double>(laplacian_squares) / count - mean * mean : 0.0;
}

double KeyframeGate::SharpnessReference() const {
  if (history_count_ < options_.min_history) return sharpness_max_;
  std::array<double, 64> sorted = sharpness_history_;
  return MedianInPlace(sorted.data(), static_cast<size_t>(history_count_));
}

void KeyframeGate::RememberSharpness(double sharpness) {
  sharpness_history_[static_cast<size_t>(history_next_)] = sharpness;
  history_next_ = (history_next_ + 1) % options_.sharpness_window;
  history_count_ = std::min(history_count_ + 1, options_.sharpness_window);
  sharpness_max_ = std::max(sharpness_max_, sharpness);
}

double KeyframeGate::TriangulationAngleDeg(const GateMapPose& map_pose) {
  const Eigen::Vector3d centre = CameraCenterInWorld(map_pose.cam_from_world);
  const int count = std::min(map_pose.num_points, kMaxAnglePoints);
  for (int i = 0; i < count; ++i)
    angles_[static_cast<size_t>(i)] = TriangulationAngle(keyframe_centre_, centre, map_pose.points[i]);
  return MedianInPlace(angles_.data(), static_cast<size_t>(count)) * 180.0 / M_PI;
}

void KeyframeGate::MoveKeyframeToMap(int map_version, const Sim3& new_from_old) {
  if (keyframe_map_version_ == 0) return;
  keyframe_centre_ = new_from_old.Apply(keyframe_centre_);
  keyframe_map_version_ = map_version;
}

// Corners of the newest frame: per grid cell the pixel with the largest smaller eigenvalue of the
// 3x3 structure tensor (Shi & Tomasi, "Good Features to Track", CVPR 1994), when it is textured
// enough for the flow.
void KeyframeGate::TakeKeyframe(const GateMapPose* map_pose) {
  keyframe_map_version_ = map_pose != nullptr ? map_pose->map_version : 0;
  if (keyframe_map_version_ > 0) keyframe_centre_ = CameraCenterInWorld(map_pose->cam_from_world);
  const int w = small_.width(), h = small_.height();
  const int margin = flow_options_.window_radius + 2;
  num_corners_ = 0;
  for (int gy = 0; gy < options_.grid_rows; ++gy) {
    for (int gx = 0; gx < options_.grid_columns; ++gx) {
      const int x0 = std::max(margin, gx * w / options_.grid_columns);
      const int x1 = std::min(w - margin, (gx + 1) * w / options_.grid_columns);
      const int y0 = std::max(margin, gy * h / options_.grid_rows);
      const int y1 = std::min(h - margin, (gy + 1) * h / options_.grid_rows);
      float best = static_cast<float>(flow_options_.min_eigenvalue) * 4.0f;
      int best_x = -1, best_y = -1;
      for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
          double gxx = 0.0, gyy = 0.0, gxy = 0.0;
          for (int dy = -1; dy <= 1; ++dy) {
            const uint8_t* row = small_.row(y + dy);
            const uint8_t* up = small_.row(y + dy - 1);
            const uint8_t* down = small_.row(y + dy + 1);
            for (int dx = -1; dx <= 1; ++dx) {
              const double ix = 0.5 * (row[x + dx + 1] - row[x + dx - 1]);
              const double iy = 0.5 * (down[x + dx] - up[x + dx]);
              gxx += ix * ix, gyy += iy * iy, gxy += ix * iy;
            }
          }
          gxx /= 9.0, gyy /= 9.0, gxy /= 9.0;
          const float smaller =
              static_cast<float>(0.5 * (gxx + gyy) - std::sqrt(0.25 * (gxx - gyy) * (gxx - gyy) + gxy * gxy));
          if (smaller > best) best = smaller, best_x = x, best_y = y;
        }
      }
      if (best_x < 0) continue;
      const Eigen::Vector2f corner(static_cast<float>(best_x), static_cast<float>(best_y));
      keyframe_corners_[static_cast<size_t>(num_corners_)] = corner;
      corners_[static_cast<size_t>(num_corners_)] = corner;
      alive_[static_cast<size_t>(num_corners_)] = true;
      ++num_corners_;
    }
  }
  keyframe_pyramid_ = pyramids_[newest_];
  have_keyframe_ = true;
  ++keyframes_;
  lost_frames_ = 0;
}

// The median distance (analysis pixels) of the followed corners from where the homography that
// explains most of them puts them (RANSAC over 4-point samples, seeded: deterministic; refitted on
// its inliers). 0 with fewer than 8 corners: too few to tell.
double KeyframeGate::Parallax(int count) {
  if (count < 8) return 0.0;
  SplitMix64 rng(0x6b6579ull);
  std::array<Eigen::Matrix3d, HomographyFourPoint::kMaxModels> models;
  Eigen::Matrix3d best = Eigen::Matrix3d::Identity();
  int best_inliers = -1;
  const double inlier_squared = kHomographyInlierPx * kHomographyInlierPx;
  for (int iteration = 0; iteration < kHomographyIterations; ++iteration) {
    std::array<Correspondence, 4> sample;
    std::array<int, 4> picked = {-1, -1, -1, -1};
    for (int s = 0; s < 4; ++s) {
      int index;
      do {
        index = static_cast<int>(rng.UniformInt(static_cast<uint32_t>(count)));
      } while (std::find(picked.begin(), picked.begin() + s, index) != picked.begin() + s);
      picked[static_cast<size_t>(s)] = index;
      sample[static_cast<size_t>(s)] = pairs_[static_cast<size_t>(index)];
    }
    if (HomographyFourPoint::Estimate(sample.data(), 4, &models) == 0) continue;
    HomographyFourPoint::Residuals(pairs_.data(), count, models[0], residuals_.data());
    int inliers = 0;
    for (int i = 0; i < count; ++i) inliers += residuals_[static_cast<size_t>(i)] <= inlier_squared;
    if (inliers > best_inliers) best_inliers = inliers, best = models[0];
  }
  if (best_inliers < 0) return 0.0;
  HomographyFourPoint::Residuals(pairs_.data(), count, best, residuals_.data());
  int inliers = 0;
  for (int i = 0; i < count; ++i) {
    if (residuals_[static_cast<size_t>(i)] <= inlier_squared)
      inlier_pairs_[static_cast<size_t>(inliers++)] = pairs_[static_cast<size_t>(i)];
  }
  if (inliers >= 4 && HomographyFourPoint::Estimate(inlier_pairs_.data(), inliers, &models) > 0) best = models[0];
  HomographyFourPoint::Residuals(pairs_.data(), count, best, residuals_.data());
  for (int i = 0; i < count; ++i) residuals_[static_cast<size_t>(i)] = std::sqrt(residuals_[static_cast<size_t>(i)]);
  return MedianInPlace(residuals_.data(), static_cast<size_t>(count));
}

// flow_ for the `count` points at `from` (in `previous`) into `next`; a result whose flow back does
// not return within kMaxForwardBackwardPx is marked lost (kLargeError).
Status KeyframeGate::ConsistentFlow(const ImagePyramid& previous, const ImagePyramid& next, const Eigen::Vector2f* from,
                                    int count) {
  RECONAR_RETURN_IF_ERROR(TrackPoints(previous, next, flow_options_, from, nullptr, count, flow_.data()));
  for (int i = 0; i < count; ++i) forward_[static_cast<size_t>(i)] = flow_[static_cast<size_t>(i)].point;
  RECONAR_RETURN_IF_ERROR(
      TrackPoints(next, previous, flow_options_, forward_.data(), from, count, backward_flow_.data()));
  for (int i = 0; i < count; ++i) {
    const size_t k = static_cast<size_t>(i);
    if (flow_[k].status != FlowStatus::kTracked) continue;
    if (backward_flow_[k].status != FlowStatus::kTracked ||
        (backward_flow_[k].point - from[i]).norm() > kMaxForwardBackwardPx)
      flow_[k].status = FlowStatus::kLargeError;
  }
  return Status::Ok();
}

// Follows the keyframe's corners from the previous frame into the newest one. In a frame the gate
// accepts after rejected ones, the corners lost since the last accepted frame are looked for again
// from there: a blurred or dark frame loses corners the next sharp frame can still show.
Status KeyframeGate::FollowCorners(bool accepted, GateFrameReport* report) {
  const ImagePyramid& next = pyramids_[newest_];
  RECONAR_RETURN_IF_ERROR(ConsistentFlow(pyramids_[previous_], next, corners_.data(), num_corners_));
  int alive = 0, moved = 0;
  for (int i = 0; i < num_corners_; ++i) {
    const size_t k = static_cast<size_t>(i);
    if (!alive_[k]) continue;
    if (flow_[k].status != FlowStatus::kTracked) {
      alive_[k] = false;
      continue;
    }
    scratch_[static_cast<size_t>(moved++)] = (flow_[k].point - corners_[k]).norm();
    corners_[k] = flow_[k].point;
    ++alive;
  }
  if (accepted && frames_since_accepted_ > 0) {
    int retried = 0;
    for (int i = 0; i < num_corners_; ++i) {
      const size_t k = static_cast<size_t>(i);
      if (alive_[k] || !accepted_alive_[k]) continue;
      retry_index_[static_cast<size_t>(retried)] = i;
      retry_from_[static_cast<size_t>(retried++)] = accepted_corners_[k];
    }
    if (retried > 0) RECONAR_RETURN_IF_ERROR(ConsistentFlow(pyramids_[accepted_], next, retry_from_.data(), retried));
    const float intervals = static_cast<float>(frames_since_accepted_ + 1);
    for (int r = 0; r < retried; ++r) {
      const FlowResult& found = flow_[static_cast<size_t>(r)];
      if (found.status != FlowStatus::kTracked) continue;
      const size_t k = static_cast<size_t>(retry_index_[static_cast<size_t>(r)]);
      scratch_[static_cast<size_t>(moved++)] = (found.point - accepted_corners_[k]).norm() / intervals;
      corners_[k] = found.point;
      alive_[k] = true;
      ++alive;
    }
  }
  // Lost: the view may have come back to the keyframe's, so look for its corners from there.
  if (alive < options_.lost_overlap * num_corners_) {
    RECONAR_RETURN_IF_ERROR(ConsistentFlow(keyframe_pyramid_, next, keyframe_corners_.data(), num_corners_));
    int found = 0;
    for (int i = 0; i < num_corners_; ++i) found += flow_[static_cast<size_t>(i)].status == FlowStatus::kTracked;
    if (found > alive) {
      alive = moved = 0;
      report->recovered = true;
      for (int i = 0; i < num_corners_; ++i) {
        const size_t k = static_cast<size_t>(i);
        alive_[k] = flow_[k].status == FlowStatus::kTracked;
        if (alive_[k]) corners_[k] = flow_[k].point, ++alive;
      }
    }
  }
  int paired = 0;
  for (int i = 0; i < num_corners_; ++i) {
    const size_t k = static_cast<size_t>(i);
    if (alive_[k])
      pairs_[static_cast<size_t>(paired++)] = {keyframe_corners_[k].cast<double>(), corners_[k].cast<double>()};
  }
  const float width = static_cast<float>(small_.width());
  report->corners = num_corners_;
  report->overlap = num_corners_ > 0 ? static_cast<double>(alive) / num_corners_ : 0.0;
  report->frame_motion = moved > 0 ? MedianInPlace(scratch_.data(), static_cast<size_t>(moved)) / width : 0.0;
  for (int i = 0; i < alive; ++i) {
    const Correspondence& pair = pairs_[static_cast<size_t>(i)];
    scratch_[static_cast<size_t>(i)] = static_cast<float>((pair.x2 - pair.x1).norm());
  }
  report->motion = alive > 0 ? MedianInPlace(scratch_.data(), static_cast<size_t>(alive)) / width : 0.0;
  report->parallax = Parallax(alive) / width;
  return Status::Ok();
}

Status KeyframeGate::Process(ImageView<const uint8_t> gray, GateFrameReport* report, const GateMapPose* map_pose) {
  *report = GateFrameReport();
  if (gray.data == nullptr || gray.width <= 0 || gray.height <= 0)
    return InvalidArgument("keyframe gate: an empty frame");
  if (frame_width_ == 0) {
    RECONAR_RETURN_IF_ERROR(options_.Check());
    frame_width_ = gray.width, frame_height_ = gray.height;
    factor_ = std::max(1, (gray.width + options_.analysis_width - 1) / options_.analysis_width);
    small_ = Image<uint8_t>(gray.width / factor_, gray.height / factor_);
    column_sums_.assign(static_cast<size_t>(gray.width), 0);
    if (small_.width() < 32 || small_.height() < 32)
      return InvalidArgument("keyframe gate: frames under 32 pixels after downscaling");
  } else if (gray.width != frame_width_ || gray.height != frame_height_) {
    return InvalidArgument("keyframe gate: a frame of " + std::to_string(gray.width) + "x" +
                           std::to_string(gray.height) + " after frames of " + std::to_string(frame_width_) + "x" +
                           std::to_string(frame_height_));
  }
  Downscale(gray);
  // The newest frame's pyramid in a slot neither the previous nor the last accepted frame holds,
  // taken in turn so that all three are sized within the first three frames.
  previous_ = newest_;
  do {
    newest_ = (newest_ + 1) % kPyramids;
  } while (newest_ == previous_ || newest_ == accepted_);
  RECONAR_RETURN_IF_ERROR(pyramids_[newest_].Build(small_.view(), kPyramidLevels));
  MeasureImage(gray, report);
  const bool too_dark = report->bright_level < options_.min_bright_level;
  const bool too_bright = report->dark_level > options_.max_dark_level;
  const bool exposed = !too_dark && !too_bright && report->highlight_fraction <= options_.max_highlight_fraction;
  report->sharpness_threshold = options_.sharpness_ratio * SharpnessReference();
  if (exposed) RememberSharpness(report->sharpness);
  const bool accepted = exposed && report->sharpness >= report->sharpness_threshold;

  if (have_keyframe_) RECONAR_RETURN_IF_ERROR(FollowCorners(accepted, report));
  if (!options_.use_map_poses) map_pose = nullptr;
  if (have_keyframe_ && map_pose != nullptr && map_pose->map_version > 0 &&
      map_pose->map_version == keyframe_map_version_ && map_pose->num_points >= kMinAnglePoints) {
    report->triangulation_angle_deg = TriangulationAngleDeg(*map_pose);
  }
  const bool enough_baseline = report->triangulation_angle_deg >= 0.0
                                   ? report->triangulation_angle_deg >= options_.keyframe_angle_deg
                                   : report->parallax >= options_.keyframe_parallax;
  const bool fast = report->frame_motion > options_.max_frame_motion;
  if (!exposed) {
    report->verdict = GateVerdict::kBadExposure;
    report->advice = too_dark ? GateAdvice::kTooDark : too_bright ? GateAdvice::kTooBright : GateAdvice::kHarshLight;
  } else if (!accepted) {
    report->verdict = GateVerdict::kBlurred;
    report->advice = fast ? GateAdvice::kTooFast : GateAdvice::kBlurred;
  } else if (!have_keyframe_) {
    report->verdict = GateVerdict::kKeyframe;
    report->advice = GateAdvice::kMoveSideways;
  } else if (report->overlap < options_.lost_overlap) {
    report->verdict = GateVerdict::kLost;
    report->advice = GateAdvice::kLost;
    if (++lost_frames_ >= options_.lost_frames_to_restart) {
      report->verdict = GateVerdict::kKeyframe;
      report->restarted = true;
      report->advice = GateAdvice::kRestarted;
    }
  } else if (enough_baseline || report->overlap < options_.keyframe_overlap) {
    report->verdict = GateVerdict::kKeyframe;
    report->advice = fast ? GateAdvice::kTooFast : GateAdvice::kMoveSideways;
  } else {
    report->verdict = GateVerdict::kTooClose;
    report->advice = fast ? GateAdvice::kTooFast : GateAdvice::kMoveSideways;
  }
  if (report->verdict == GateVerdict::kKeyframe) TakeKeyframe(map_pose);
  if (report->verdict != GateVerdict::kLost) lost_frames_ = 0;
  if (accepted) {
    accepted_ = newest_;
    accepted_corners_ = corners_;
    accepted_alive_ = alive_;
    frames_since_accepted_ = 0;
  } else {
    ++frames_since_accepted_;
  }
  return Status::Ok();
}

}  // namespace reconar
