#pragma once
// TagTracker: AprilTags followed through a video. Per frame:
//  1. predict every followed tag's pose (constant velocity on the last two measurements, or the last
//     pose), project its square and take the bounding box plus a margin as its search region;
//  2. detect inside each region only (TagDetector::DetectInRegion, pixels not copied);
//  3. search the full frame instead when no tag is followed, when a region search missed its tag,
//     and every full_frame_interval frames (new tags, lost tags);
//  4. estimate each found tag's pose (tag_pose.h: IPPE + LM) and filter it: translation by an
//     alpha-beta (constant-velocity) filter, rotation by slerp toward the measurement.
//  5. optionally (SearchPredicted, after Track, same frame): search tags the caller predicts from
//     outside the tracker (a layout's tags placed by the frame's camera pose) where their predicted
//     square appears, so that a tag entering the view is found in that frame.
// Per-tag states: kTracking (measured this frame), kSearching (missed for fewer than
// lost_after_missed_frames consecutive frames: still predicted and region-searched), kLost (missed
// that many frames: only a full-frame or a predicted search finds it again, reported as
// `reacquired`). When max_tags tracks exist and a new id is found, the track lost the longest gives
// its place to the new id (a lost track keeps no state a re-acquisition uses); the id is dropped
// only when every track is still tracking or searching.
//
// Frames and pixels: see tag_pose.h and tag_detector.h (corners in the program's convention, the
// centre of the top-left pixel at (0, 0); cam_from_tag with the tag's z axis toward the viewer).
//
// Memory: every buffer (tracks, detection lists, the report's tag list) is sized at construction
// from max_tags; Track() makes no heap allocation in our code in steady state (proved by
// tests/tracker/tag_tracker_test.cc with a counting operator new). libapriltag itself calls C
// malloc/free inside every detection (working images, clusters, quads); that is not ours to avoid.
#include <chrono>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/base/image.h"
#include "core/base/status.h"
#include "core/math/camera_intrinsics.h"
#include "core/math/rigid3.h"
#include "tracker/tag_detector.h"
#include "tracker/tag_pose.h"

namespace reconar {

struct TagTrackerOptions {
  // Used for full-frame searches. Region searches use the same options except quad_decimate.
  TagDetectorOptions detector;
  // quad_decimate inside a predicted region: the largest factor, up to region_max_quad_decimate,
  // that keeps the predicted tag's shortest edge at least region_min_decimated_edge_px decimated
  // pixels long (3 px per module of a tag36h11 border: quads stay well above libapriltag's minimum
  // size), and never below the full-frame decimation. Edges are refined at full resolution
  // (detector.refine_edges), so the corners keep their accuracy while quad finding on a near tag
  // costs a fraction.
  float region_max_quad_decimate = 4.0f;
  double region_min_decimated_edge_px = 24.0;
  CameraIntrinsics intrinsics;  // valid() required
  double tag_size = 0.0;        // edge of the black square in metres (> 0), all tags
  int max_tags = 16;            // tags followed at once; further ids are counted as dropped

  enum class Prediction {
    kLastPose,          // the region is the last measured square
    kConstantVelocity,  // last pose moved by the motion between the last two measurements
  };
  Prediction prediction = Prediction::kConstantVelocity;
  // Margin added on every side of the bounding box of the predicted and the last detected square:
  // region_margin times the box's larger side plus region_margin_px. 0.25 covers the tag's white
  // border (1/8 of the black square for tag36h11) plus an error of the prediction of 1/8 of the
  // tag's size per frame.
  double region_margin = 0.25;
  int region_margin_px = 8;
  // SearchPredicted: tags whose predicted square has an edge shorter than this (pixels) are not
  // searched (too small to decode: tag36h11 has 10 modules across, white border included).
  double predicted_min_edge_px = 10.0;
  int lost_after_missed_frames = 5;
  // A full-frame search every this many frames even when every region search succeeds (0 = never),
  // so that new tags and lost ones are found (30: within a second at 30 fps).
  int full_frame_interval = 30;
  // Filter gains in (0, 1]: 1 follows the measurement exactly.
  double translation_alpha = 0.6;  // position correction
  double translation_beta = 0.2;   // velocity correction
  double rotation_alpha = 0.6;     // slerp fraction toward the measured rotation
  PlanarPoseOptions pose;

  Status Check() const;
};

enum class TagTrackState { kTracking, kSearching, kLost };
const char* TagTrackStateName(TagTrackState state);

struct TrackedTag {
  int id = -1;
  TagTrackState state = TagTrackState::kSearching;
  bool measured = false;    // detected (and its pose estimated) in this frame
  bool reacquired = false;  // measured in this frame after having been kLost
  bool found_in_region = false;      // in a region search (its own or, found_by_prediction, a predicted one)
  bool found_by_prediction = false;  // found by SearchPredicted in this frame
  int missed_frames = 0;    // consecutive frames without a measurement
  TagDetection detection;   // this frame's detection (valid when measured)
  TagPose pose;             // this frame's raw pose estimate (valid when measured)
  Rigid3 cam_from_tag;      // = pose.cam_from_tag when measured, else the last measurement
  Rigid3 smoothed_cam_from_tag;  // the filtered pose (predicted forward when not measured)
};

struct TagTrackerFrameReport {
  enum class Search {
    kRegions,              // only the predicted regions were searched
    kFullFrame,            // only the full frame (nothing followed, or periodic)
    kRegionsThenFullFrame  // a region search missed its tag and the full frame was searched too
  };
  int64_t frame_index = -1;
  Search search = Search::kFullFrame;
  int regions_searched = 0;
  int detections = 0;      // raw detections over all searches
  int tags_dropped = 0;    // ids not followed because max_tags were already followed
  int predicted_searched = 0;  // SearchPredicted: predicted tags searched in their region
  int predicted_found = 0;     // SearchPredicted: tags measured by those searches
  double detect_ms = 0.0;  // inside libapriltag
  double pose_ms = 0.0;
  double total_ms = 0.0;
  std::vector<TrackedTag> tags;  // every followed tag (any state); capacity max_tags, reserved once
};

const char* SearchName(TagTrackerFrameReport::Search search);

// A tag the caller expects in the current frame at cam_from_tag (e.g. a layout's tag placed by the
// camera pose of the frame: cam_from_world * world_from_tag), for TagTracker::SearchPredicted.
struct PredictedTag {
  int id = -1;
  Rigid3 cam_from_tag;
};

class TagTracker {
 public:
  // InvalidArgument for bad options; errors of TagDetector::Create.
  static Result<std::unique_ptr<TagTracker>> Create(const TagTrackerOptions& options);
  ~TagTracker();

  // Processes the next frame (same size as the previous ones; a size change restarts the tracks).
  // *report is overwritten; keep one report object across frames so its storage is reused.
  Status Track(ImageView<const uint8_t> image, TagTrackerFrameReport* report);

  // After Track() on the same frame (same image, same report): searches every predicted tag not
  // measured in this frame where its square appears. A tag is skipped when a corner is behind the
  // camera or projects through the fold of the distortion, its printed side faces away, its
  // predicted square does not lie in the frame (up to the region margin) or has an edge shorter
  // than predicted_min_edge_px. The region is the one of a followed tag (the predicted square's
  // box plus the margin, SquareRegion) and its quad_decimate the region rule of the options, from
  // 1 up (no full-frame search has shown that the tag is found at the full-frame decimation); it is
  // not searched when this frame's full-frame search used that decimation or a finer one (it
  // already looked there). Detections of predicted ids found there are measured and followed like any other (a new id
  // starts a track; a lost one counts as reacquired). Updates *report: its tags, detections,
  // timings and predicted_searched / predicted_found. Nothing is searched when count is 0.
  // InvalidArgument when the image is not the one of the last Track (size) or count < 0.
  Status SearchPredicted(ImageView<const uint8_t> image, const PredictedTag* tags, int count,
                         TagTrackerFrameReport* report);

  const TagTrackerOptions& options() const { return options_; }

 private:
  struct FollowedTag;
  explicit TagTracker(const TagTrackerOptions& options);
  FollowedTag* FindTrack(int id);
  // The search box of a followed tag and its predicted square's shortest edge in pixels.
  bool PredictRegion(FollowedTag& track, int width, int height, int region[4], double* shortest_edge_px) const;
  // The search box of a tag at cam_from_tag: the box of its projected square (and of `last_corners`,
  // its last detected square, when not null) plus the margin, clipped to the frame. False when a
  // corner is not in front of the camera or the clipped box is too small to hold a tag. With
  // in_view: also false when a corner's projection is folded back by the distortion (it lies beyond
  // the camera's RadialCamera::FoldRadiusSquared), and *in_view tells whether the unclipped box lies
  // in the frame grown by the margin.
  bool SquareRegion(const Rigid3& cam_from_tag, const Eigen::Vector2d* last_corners, int width, int height,
                    int region[4], double* shortest_edge_px, bool* in_view) const;
  // quad_decimate of a region search for a tag of that shortest edge, never below min_decimate.
  float RegionDecimate(double shortest_edge_px, float min_decimate) const;
  // Detects inside region with region_detector_ into scratch_ (time and count into *report).
  Status DetectRegion(ImageView<const uint8_t> image, const int region[4], float decimate,
                      TagTrackerFrameReport* report);
  void Measure(FollowedTag& track, const TagDetection& detection, bool in_region, double* pose_ms);
  // Follows a detection of an id without a track: a new track, or the place of the track lost the
  // longest when max_tags tracks exist (else counted in tags_dropped). Nothing when its pose fails.
  FollowedTag* StartTrack(const TagDetection& detection, bool in_region, TagTrackerFrameReport* report);
  void FillReport(TagTrackerFrameReport* report) const;

  TagTrackerOptions options_;
  std::unique_ptr<TagDetector> full_detector_;
  std::unique_ptr<TagDetector> region_detector_;
  std::vector<FollowedTag> tracks_;
  TagDetectionList scratch_;
  int64_t frame_index_ = -1;
  int width_ = 0;
  int height_ = 0;
};

}  // namespace reconar
