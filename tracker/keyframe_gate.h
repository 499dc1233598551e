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
//    Matas, "Forward-Backward Error", ICPR 2010: a jump the flow cannot follow fails here). From
//    them: the parallax since the keyframe (the median distance of the corners from where the
//    best homography of the keyframe puts them: a camera turning on the spot, or a plane, gives
//    none, depth seen from a new place does), the share still followed (the overlap with the
//    keyframe), and the median displacement since the previous frame (how fast the view moves).
// A sharp, well-exposed frame becomes a keyframe when it has enough parallax to triangulate
// from, or when the overlap has fallen so low that the next one would not register
// (docs/capture.md gives the rules and the reasons for their defaults). Steady state makes no heap allocation: every
// buffer is sized on the first frame (tests/tracker/keyframe_gate_allocation_test.cc).
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "core/base/image.h"
#include "core/base/status.h"
#include "core/features/optical_flow.h"
#include "core/geometry/correspondence.h"

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
  int corners = 0;            // corners found in the last keyframe
  bool restarted = false;     // a keyframe taken after being lost for lost_frames_to_restart frames
  bool recovered = false;     // the corners were found again from the keyframe after being lost
};

class KeyframeGate {
 public:
  explicit KeyframeGate(const KeyframeGateOptions& options = KeyframeGateOptions());

  // Judges the next frame (8-bit grey, any size; every frame the same size).
  // InvalidArgument for an empty frame, a frame of another size than the first, or bad options.
  Status Process(ImageView<const uint8_t> gray, GateFrameReport* report);

  int keyframes() const { return keyframes_; }

 private:
  static constexpr int kMaxCorners = 256;

  void Downscale(ImageView<const uint8_t> gray);
  void MeasureImage(ImageView<const uint8_t> gray, GateFrameReport* report) const;
  double SharpnessReference() const;
  void RememberSharpness(double sharpness);
  void TakeKeyframe();
  Status FollowCorners(GateFrameReport* report);
  double Parallax(int count);
  Status ConsistentFlow(const ImagePyramid& previous, const ImagePyramid& next, const Eigen::Vector2f* from);

  KeyframeGateOptions options_;
  OpticalFlowOptions flow_options_;
  int frame_width_ = 0, frame_height_ = 0, factor_ = 1;
  Image<uint8_t> small_;
  ImagePyramid pyramids_[2];
  ImagePyramid keyframe_pyramid_;  // a copy (its storage reused from the first keyframe on)
  int current_ = 0;                // index of the pyramid of the newest frame
  bool have_keyframe_ = false;
  int keyframes_ = 0;
  int lost_frames_ = 0;
  std::array<Eigen::Vector2f, kMaxCorners> keyframe_corners_{};
  std::array<Eigen::Vector2f, kMaxCorners> corners_{};  // in the newest frame
  std::array<FlowResult, kMaxCorners> flow_{};
  std::array<Eigen::Vector2f, kMaxCorners> forward_{};  // forward flow's results, tracked back
  std::array<FlowResult, kMaxCorners> backward_flow_{};
  std::array<bool, kMaxCorners> alive_{};
  std::array<float, kMaxCorners> scratch_{};
  std::array<Correspondence, kMaxCorners> pairs_{};  // keyframe corner -> its place now
  std::array<Correspondence, kMaxCorners> inlier_pairs_{};
  std::array<double, kMaxCorners> residuals_{};
  int num_corners_ = 0;
  std::array<double, 64> sharpness_history_{};
  int history_count_ = 0, history_next_ = 0;
  double sharpness_max_ = 0.0;
  std::vector<uint32_t> column_sums_;  // one row of the frame, for the box filter
};

}  // namespace reconar
