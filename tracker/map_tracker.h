#pragma once
// MapTracker: the pose of every video frame against a localisation map (core/sfm/localization_map.h),
// by frame-to-frame tracking of map points between relocalisations (core/sfm/localizer.h).
//
// Per frame while tracking (the steady state):
//  1. predict the pose: the prior when the caller gives one (the tags' pose), else constant
//     velocity on the last two poses (the last pose when only one is known), re-orthonormalised;
//  2. guided matching: every followed map point is tracked from its pixel in the previous frame
//     by pyramidal Lucas-Kanade (core/features/optical_flow.h), the search seeded at the point's
//     projection under the predicted pose, so the window only has to absorb the prediction's error;
//     the result is then refined at full resolution against the point's template, the window kept
//     from the frame where the point was first found (AlignFlowTemplate), and the point is dropped
//     when the two disagree by more than max_anchor_shift_px: chained flow cannot slide;
//  3. pose: robust LM refinement (core/geometry/absolute_pose.h, Cauchy loss) of the predicted pose
//     on all tracked points, the inliers (error < max_error_px) kept, a second refinement (Huber) on
//     them alone; the pose counts when it has min_inliers inliers that are min_inlier_ratio of the
//     tracked points. A failed gate tries P3P LO-RANSAC on the same correspondences before giving up
//     (a frame on that path may allocate);
//  4. new points: when fewer than replenish_fraction of max_tracked_points are followed, the map
//     points the posed camera should see (in front of it, inside the frame, seen by the map's
//     keyframes from within max_view_angle_deg of this view direction) are projected with the
//     frame's pose and followed from their projection on, at most one per grid_cell_px cell, their
//     template taken there (a flat window is not followed). Their first measurement is the next
//     frame's flow: a projection landing on the wrong texture (an occluded point, a point the pose
//     puts a pixel off) is dropped by the flow's texture and error checks or the pose's inlier gate;
//  5. re-anchoring: every reanchor_interval posed frames the frame is relocalised instead, so the
//     followed points are SIFT matches again (points seeded from projections carry the seeding
//     pose's error; without this it accumulates over generations of seeds).
// Why this design: descriptor matching in every frame needs SIFT in every frame (~30 ms for a
// 640x480 frame, and allocation), and the map holds no keyframe images to take patches from. Flow
// is cheap (13x13 windows, four levels: ~1.5 ms for 300 points), accurate to a few hundredths of a
// pixel, and follows the slow appearance change of a video; the map's 3D points and the periodic
// SIFT re-anchoring keep the pose on the map.
// Limits: between re-anchorings the pose can drift by the error of the frames that seeded the
// followed points (measured on a real video: ~1 cm / 1 deg at the 95th percentile, 2.7 cm / 2.2 deg
// at worst, against 1.2 cm / 0.7 deg for relocalising every frame); texture-poor views give too few
// windows with texture in two directions (the frame is lost, not misposed); on repeated structure a
// poor prediction can let flow lock onto the next repetition: the inlier gate rejects it when few
// points do, the relocalisation's ratio test when the whole view repeats.
//
// States: kTracking (this frame or the last one had a pose), kRelocalising (the last pose is fewer
// than lost_after_frames frames old: every frame is relocalised), kLost (older: relocalisation every
// lost_relocalise_interval frames). A frame without followed points or whose tracking fails is
// relocalised in the same frame (SIFT on the frame, Localizer::Localize with the known camera),
// unless a prior is given: tracking then restarts from the prior's projection of the map (no pose
// for that frame, found = false, from_prior = true).
//
// Memory: every per-frame buffer (followed points, their templates, flow results, correspondences,
// the report's inlier lists) has capacity max_tracked_points, reserved at Create; the image
// pyramids, the seeding grid and the relocalisation buffers are sized by the first frame of a size.
// Tracked frames make no heap allocation after that (tests/tracker/map_tracker_allocation_test.cc
// counts every frame); relocalisation frames (also the re-anchoring ones) and the RANSAC fallback do.
// Not thread-safe: one tracker per video.
#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "core/base/image.h"
#include "core/base/status.h"
#include "core/features/optical_flow.h"
#include "core/features/sift/sift.h"
#include "core/math/camera_intrinsics.h"
#include "core/math/rigid3.h"
#include "core/sfm/localization_map.h"
#include "core/sfm/localizer.h"

namespace reconar {

enum class MapTrackingState { kTracking, kRelocalising, kLost };
const char* MapTrackingStateName(MapTrackingState state);  // "tracking", "relocalising", "lost"

struct MapTrackerOptions {
  CameraIntrinsics intrinsics;   // of the video frames (valid() required); scaled to the frame size
  LocalizerOptions localizer;    // relocalisation
  SiftOptions sift;              // for relocalisation frames (its arena is sized for the frame)
  int max_tracked_points = 300;  // capacity of every per-frame buffer
  int lost_after_frames = 10;    // consecutive frames without a pose before kRelocalising becomes kLost

  OpticalFlowOptions flow;           // window radius, pyramid levels, texture and error checks
  double max_error_px = 3.0;         // inlier threshold of the tracked pose
  int min_inliers = 20;              // a tracked pose needs this many inliers
  double min_inlier_ratio = 0.5;     // ... that are at least this share of the tracked points
  double loss_scale_px = 2.0;        // Cauchy scale of the first refinement
  // While kLost, relocalise every this many frames (1: every frame). Lost is when the user needs a
  // pose most, and a relocalisation at 640x480 costs ~40 ms; a larger interval saves power.
  int lost_relocalise_interval = 1;
  double replenish_fraction = 0.8;   // seed new points when fewer than this share of the capacity are followed
  int grid_cell_px = 16;             // at most one followed point per cell of this size
  double max_view_angle_deg = 60.0;  // seed a point only when seen from within this angle of its keyframes
  int border_px = 8;                 // seed a point only this far inside the frame
  // Each followed point keeps the window of the frame where it was first found (its template);
  // every frame, the flow's result is refined against it (level 0) and the point is dropped when
  // the two differ by more than max_anchor_shift_px or the template no longer matches. Without
  // this, a window can slide along an edge or a blurred frame a little further every frame.
  bool anchor_to_first_sighting = true;
  double max_anchor_shift_px = 2.0;
  // Every this many frames tracked since the last relocalisation, the frame is relocalised instead
  // (tracking is the fallback when that fails): the followed points become SIFT matches again, so
  // points seeded from projections cannot carry a pose error on for long (0: never). Such a frame
  // costs a relocalisation (SIFT + Localize, ~40 ms at 640x480) and allocates. Measured on the
  // recorded AR video (tests/tools/map_tracker_video_test.cc), worst error over 93 frames: 8.5 cm /
  // 6.7 deg without re-anchoring, 4.8 cm / 4.0 deg every 30 frames, 2.7 cm / 2.2 deg every 10.
  int reanchor_interval = 10;

  // InvalidArgument naming the first offending field.
  Status Check() const;
};

struct MapTrackerFrameReport {
  int64_t frame_index = -1;
  MapTrackingState state = MapTrackingState::kLost;
  bool found = false;        // cam_from_world valid for this frame
  bool relocalised = false;  // this frame's pose came from relocalisation (not frame-to-frame)
  Rigid3 cam_from_world;
  int inliers = 0;
  double rms_reprojection_px = 0.0;
  double track_ms = 0.0;
  // The inliers of this frame's pose: pixel (frame pixels, centre of the top-left pixel at (0,0)) and
  // its map point in the world frame. Capacity reserved once (max_tracked_points).
  std::vector<Eigen::Vector2d> inlier_pixels;
  std::vector<Eigen::Vector3d> inlier_world_points;

  // Details.
  int tracked_points = 0;  // map points the flow followed into this frame
  int seeded_points = 0;   // new map points projected into this frame to follow from here
  bool relocalisation_tried = false;
  bool ransac_fallback = false;  // the tracked pose came from P3P RANSAC, not the prediction
  bool from_prior = false;       // tracking (re)started from the prior's projection this frame
  double relocalise_ms = 0.0;    // SIFT + Localize, when tried
};

class MapTracker {
 public:
  // Borrows the map (must outlive the tracker). InvalidArgument for bad options or a map without
  // points; errors of Localizer::Create.
  static Result<std::unique_ptr<MapTracker>> Create(const LocalizationMap* map, const MapTrackerOptions& options);
  // The same with the map's localizer built already (its search index is most of Create's cost, so
  // a caller that builds it elsewhere, as the live model's worker does, takes up a map at once).
  // The map is the localizer's; options.localizer is replaced by the localizer's own options.
  static Result<std::unique_ptr<MapTracker>> Create(std::shared_ptr<const Localizer> localizer,
                                                    const MapTrackerOptions& options);
  ~MapTracker();

  // The next frame. prior_cam_from_world: this frame's pose from another source (the tags) when
  // known, used instead of the motion prediction (and to (re)start tracking without a
  // relocalisation); may be nullptr. *report is overwritten; keep one report object across frames
  // so its storage is reused. A frame of another size than the previous one restarts tracking.
  // InvalidArgument for an empty frame or intrinsics of another aspect ratio; errors of SIFT.
  Status Track(ImageView<const uint8_t> gray, const Rigid3* prior_cam_from_world, MapTrackerFrameReport* report);

  MapTrackingState state() const { return state_; }
  const MapTrackerOptions& options() const { return options_; }

 private:
  MapTracker(const MapTrackerOptions& options, std::shared_ptr<const Localizer> localizer);
  Status StartFrameSize(int width, int height);
  // Flow + pose from the prediction; true when the pose passes the gate.
  bool TrackFrame(const Rigid3& predicted, MapTrackerFrameReport* report);
  // Refines *pose on correspondences [0, count); returns the inliers, compacted to the front.
  int RefineAndGate(int count, Rigid3* pose, double* rms);
  Status Relocalise(ImageView<const uint8_t> gray, MapTrackerFrameReport* report);
  // Follows the visible map points not yet followed, projected with cam_from_world.
  int Seed(const Rigid3& cam_from_world);
  // A new followed point with its template from this frame; false when there is no free slot or
  // its window is flat.
  bool AddTrack(int32_t point, const Eigen::Vector2f& pixel);
  // The template slots not used by the followed points.
  void RebuildFreeSlots();
  float* TemplateOf(int32_t slot) { return templates_.data() + static_cast<size_t>(slot) * template_floats_; }

  const LocalizationMap* map_ = nullptr;  // the localizer's
  MapTrackerOptions options_;
  std::shared_ptr<const Localizer> localizer_;
  std::vector<Eigen::Vector3f> view_direction_;  // per map point: unit mean direction toward its keyframes
  std::vector<int32_t> seed_order_;              // map points in a fixed shuffled order
  std::vector<int64_t> followed_in_frame_;       // per map point: the frame it was last followed in

  // Frame size state.
  int width_ = 0, height_ = 0;
  RadialCamera camera_;
  QueryCamera query_camera_;
  std::unique_ptr<SiftExtractor> sift_;
  Image<float> sift_image_;
  ImagePyramid pyramids_[2];
  int current_ = 0;  // pyramids_[current_] is this frame's
  bool have_previous_frame_ = false;
  int grid_columns_ = 0, grid_rows_ = 0;
  std::vector<uint8_t> grid_;

  // Followed points (capacity max_tracked_points): map point and pixel in the previous frame.
  int num_tracks_ = 0;
  std::vector<int32_t> track_point_;
  std::vector<Eigen::Vector2f> track_pixel_;
  std::vector<int32_t> track_slot_;  // its template in templates_
  // Templates (FlowTemplateFloats floats each) in max_tracked_points slots, and the free ones.
  int template_floats_ = 0;
  std::vector<float> templates_;
  std::vector<int32_t> free_slots_;
  int num_free_ = 0;
  std::vector<uint8_t> slot_used_;
  std::vector<int32_t> corr_slot_;
  // Per-frame scratch of the same capacity.
  std::vector<Eigen::Vector2f> guesses_;
  std::vector<FlowResult> flow_;
  std::vector<Eigen::Vector2d> pixels_;
  std::vector<Eigen::Vector3d> world_;
  std::vector<int32_t> corr_point_;
  std::vector<int> indices_;

  // Motion model and state.
  MapTrackingState state_ = MapTrackingState::kRelocalising;
  int64_t frame_index_ = -1;
  int frames_without_pose_ = 0;
  int frames_since_relocalisation_try_ = 0;
  int frames_since_relocalisation_ = 0;  // frames posed since the last relocalised one
  bool have_last_pose_ = false, have_previous_pose_ = false;
  Rigid3 last_pose_, previous_pose_;
};

}  // namespace reconar
