#pragma once
// The capture's keyframe gate (issue 18): at video rate, which frames of a live camera serve the
// reconstruction, and what the person holding it should do next. Each frame is looked at on a copy
// box-filtered down to at most KeyframeGateOptions::analysis_width pixels wide, and for sharpness
// on the frame itself:
//  - sharpness: the variance of the frame's 4-neighbour Laplacian (at every other pixel of every
//    other row: the box filter would take away the finest detail, which blur removes first),
//    against the median of the recent frames'
//    (the scene sets the scale: a leafy facade and a white wall differ a hundredfold), so a frame
//    blurred by motion falls out while the scene's own level is accepted;
//  - exposure: the darkest and brightest 5 % of the levels, and the share of burnt-out highlights;
//  - motion against the last keyframe: corners found in the keyframe (one per grid cell, the
//    strongest Shi-Tomasi response) followed frame to frame by pyramidal Lucas-Kanade, each kept
//    only when the flow back from the new frame returns it within a pixel (Kalal, Mikolajczyk &
//    Matas, "Forward-Backward Error", ICPR 2010: a jump the flow cannot follow fails here). The
//    corners lost in frames the gate rejects (blurred, badly exposed) are looked for again in the
//    next accepted frame from the last accepted one, so a bad frame does not cost the overlap. From
//    them: the parallax since the keyframe (the median distance of the corners from where the
//    best homography of the keyframe puts them: a camera turning on the spot, or a plane, gives
//    none, depth seen from a new place does), the share still followed (the overlap with the
//    keyframe), and the median displacement since the previous frame (how fast the view moves).
// With the frame's pose against the live model (GateMapPose, from the capture's map tracking) and
// the last keyframe's in the same map, the baseline is measured in 3D instead of by the parallax:
// the median, over the map points the pose rests on, of the angle between their rays from the
// last keyframe and from this frame (the triangulation angle a point seen in both would get).
// A sharp, well-exposed frame becomes a keyframe when it has enough baseline to triangulate
// from, or when the overlap has fallen so low that the next one would not register
// (docs/capture.md gives the rules and the reasons for their defaults). Steady state makes no heap
// allocation: every buffer is sized within the first three frames and the second keyframe
// (tests/tracker/keyframe_gate_allocation_test.cc).
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "core/base/image.h"
#include "core/base/status.h"
#include "core/features/optical_flow.h"
#include "core/geometry/correspondence.h"
#include "core/math/rigid3.h"
#include "core/math/sim3.h"

namespace reconar {

struct KeyframeGateOptions {
  int analysis_width = 320;  // frames are box-filtered by an integer factor down to at most this
  // Sharpness: blurred below sharpness_ratio x the median of the last sharpness_window frames'
  // (those with a usable exposure); until min_history frames are seen, against their maximum.
  double sharpness_ratio = 0.6;
  int sharpness_window = 31;
  int min_history = 5;
  // Exposure, from the analysis image's histogram. Too dark when even its brightest 5 % are under
  // min_bright_level; too bright when even its darkest 5 % are over max_dark_level; highlights
  // burnt out (at or above 251) over more than max_highlight_fraction of it. A black or white
  // background around a well-exposed object passes (docs/capture.md).
  double min_bright_level = 60.0;
  double max_dark_level = 195.0;
  double max_highlight_fraction = 0.25;
  // Motion, as fractions of the analysis width.
  double keyframe_parallax = 0.02;       // a keyframe once the parallax since the last one reaches this ...
  double keyframe_overlap = 0.6;         // ... or fewer than this share of its corners are still followed
  double lost_overlap = 0.25;            // fewer than this: lost (the next keyframe would not register)
  double max_frame_motion = 0.06;        // more per frame: "too fast"
  // With map poses: a keyframe once the median triangulation angle to the last keyframe reaches
  // this, instead of keyframe_parallax. The mapper's own minimum for triangulating a point
  // (MapperOptions::min_triangulation_angle_deg, COLMAP's too): half the points the new keyframe
  // shares with the last one reach it, most of those it shares with the one before.
  double keyframe_angle_deg = 1.5;
  bool use_map_poses = true;
  int grid_columns = 10, grid_rows = 8;  // one corner per cell
  int lost_frames_to_restart = 30;       // after this many lost frames in a row, start again from a new keyframe

  Status Check() const;
};

enum class GateVerdict : uint8_t {
  kKeyframe,     // taken
  kBlurred,      // sharpness under the threshold
  kBadExposure,  // too dark, too bright, or highlights burnt out
  kTooClose,     // sharp and exposed, but not far enough from the last keyframe
  kLost,         // too little overlap with the last keyframe
};
const char* GateVerdictName(GateVerdict verdict);

// Every advice GateFrameReport::advice can hold, for a display that has to be able to show them.
struct GateAdvice {
  static constexpr const char* kTooDark = "too dark";
  static constexpr const char* kTooBright = "too bright";
  static constexpr const char* kHarshLight = "light too harsh: highlights burnt out";
  static constexpr const char* kTooFast = "too fast";
  static constexpr const char* kBlurred = "hold steady: blurred";
  static constexpr const char* kMoveSideways = "move sideways";
  static constexpr const char* kLost = "go back: lost";
  static constexpr const char* kRestarted = "started again: go back to join the earlier views";
  static constexpr std::array<const char*, 8> kAll = {kTooDark, kTooBright,    kHarshLight, kTooFast,
                                                      kBlurred, kMoveSideways, kLost,       kRestarted};
};

// A frame's pose against a map (the capture's live model), for the motion test. map_version tells
// maps apart (each has a frame of its own); 0: no pose. The points are borrowed for the call.
struct GateMapPose {
  int map_version = 0;
  Rigid3 cam_from_world;
  const Eigen::Vector3d* points = nullptr;  // the map points the pose rests on (its inliers)
  int num_points = 0;
};

struct GateFrameReport {
  GateVerdict verdict = GateVerdict::kTooClose;
  const char* advice = "";           // plain words for the person: "too fast", "too dark", "move sideways", ...
  double sharpness = 0.0;            // variance of the Laplacian (grey levels^2)
  double sharpness_threshold = 0.0;  // what this frame had to reach
  double mean_level = 0.0;
  double dark_level = 0.0;          // the 5th percentile of the grey levels
  double bright_level = 0.0;        // the 95th percentile
  double highlight_fraction = 0.0;  // share at or above 251
  double motion = 0.0;        // median displacement since the last keyframe / analysis width
  double parallax = 0.0;      // median distance from the keyframe's homography / analysis width
  double frame_motion = 0.0;  // median displacement since the previous frame / analysis width
  double overlap = 1.0;       // share of the keyframe's corners still followed
  // Median triangulation angle to the last keyframe from the map poses (degrees); < 0 when not
  // measured (no pose for this frame or the keyframe in the same map): the parallax decides then.
  double triangulation_angle_deg = -1.0;
  int corners = 0;            // corners found in the last keyframe
  bool restarted = false;     // a keyframe taken after being lost for lost_frames_to_restart frames
  bool recovered = false;     // the corners were found again from the keyframe after being lost
};

class KeyframeGate {
 public:
  explicit KeyframeGate(const KeyframeGateOptions& options = KeyframeGateOptions());

  // Judges the next frame (8-bit grey, any size; every frame the same size).
  // InvalidArgument for an empty frame, a frame of another size than the first, or bad options.
  // map_pose: the frame's pose against the live model, when known (may be null).
  Status Process(ImageView<const uint8_t> gray, GateFrameReport* report, const GateMapPose* map_pose = nullptr);

  int keyframes() const { return keyframes_; }
  // The map of the last keyframe's pose (0: none), and that pose carried into a newer map:
  // new_from_old takes the old map's frame into the new one's (the maps' shared keyframes give it).
  int keyframe_map_version() const { return keyframe_map_version_; }
  void MoveKeyframeToMap(int map_version, const Sim3& new_from_old);

 private:
  static constexpr int kMaxCorners = 256;
  static constexpr int kMaxAnglePoints = 1024;  // of a map pose's points, the first this many
  static constexpr int kMinAnglePoints = 12;

  void Downscale(ImageView<const uint8_t> gray);
  void MeasureImage(ImageView<const uint8_t> gray, GateFrameReport* report) const;
  double SharpnessReference() const;
  void RememberSharpness(double sharpness);
  void TakeKeyframe(const GateMapPose* map_pose);
  double TriangulationAngleDeg(const GateMapPose& map_pose);
  Status FollowCorners(bool accepted, GateFrameReport* report);
  double Parallax(int count);
  Status ConsistentFlow(const ImagePyramid& previous, const ImagePyramid& next, const Eigen::Vector2f* from,
                        int count);

  KeyframeGateOptions options_;
  OpticalFlowOptions flow_options_;
  int frame_width_ = 0, frame_height_ = 0, factor_ = 1;
  Image<uint8_t> small_;
  static constexpr int kPyramids = 3;
  ImagePyramid pyramids_[kPyramids];
  ImagePyramid keyframe_pyramid_;  // a copy (its storage reused from the first keyframe on)
  // Indices into pyramids_: the newest frame's, the one before it, and the last accepted frame's
  // (sharp and well exposed; -1: none yet).
  int newest_ = kPyramids - 1, previous_ = -1, accepted_ = -1;
  int frames_since_accepted_ = 0;
  bool have_keyframe_ = false;
  int keyframes_ = 0;
  int lost_frames_ = 0;
  std::array<Eigen::Vector2f, kMaxCorners> keyframe_corners_{};
  std::array<Eigen::Vector2f, kMaxCorners> corners_{};  // in the newest frame
  std::array<FlowResult, kMaxCorners> flow_{};
  std::array<Eigen::Vector2f, kMaxCorners> forward_{};  // forward flow's results, tracked back
  std::array<FlowResult, kMaxCorners> backward_flow_{};
  std::array<bool, kMaxCorners> alive_{};
  std::array<Eigen::Vector2f, kMaxCorners> accepted_corners_{};  // corners_ and alive_ in the last accepted frame
  std::array<bool, kMaxCorners> accepted_alive_{};
  std::array<Eigen::Vector2f, kMaxCorners> retry_from_{};  // of the corners lost since, looked for again
  std::array<int, kMaxCorners> retry_index_{};
  std::array<float, kMaxCorners> scratch_{};
  std::array<Correspondence, kMaxCorners> pairs_{};  // keyframe corner -> its place now
  std::array<Correspondence, kMaxCorners> inlier_pairs_{};
  std::array<double, kMaxCorners> residuals_{};
  int num_corners_ = 0;
  int keyframe_map_version_ = 0;  // of the last keyframe's pose; 0: none
  Eigen::Vector3d keyframe_centre_ = Eigen::Vector3d::Zero();
  std::array<double, kMaxAnglePoints> angles_{};
  std::array<double, 64> sharpness_history_{};
  int history_count_ = 0, history_next_ = 0;
  double sharpness_max_ = 0.0;
  std::vector<uint32_t> column_sums_;  // one row of the frame, for the box filter
};

}  // namespace reconar
