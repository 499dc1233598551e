#pragma once
// Pyramidal Lucas-Kanade point tracking: where a small window around a point of one frame went in
// the next frame. Bouguet, "Pyramidal Implementation of the Lucas Kanade Feature Tracker" (Intel,
// 2000) for the coarse-to-fine scheme; at each level the translation is solved by the
// inverse-compositional algorithm (Baker & Matthews, "Lucas-Kanade 20 Years On: A Unifying
// Framework", IJCV 2004, sec. 3.2): the template's gradients and its 2x2 Hessian are computed once
// per level, so an iteration only samples the new frame's window (bilinear) and solves a 2x2 system.
//
// Conventions: pixel (x, y) = column, row, with (0, 0) at the centre of the top-left pixel (as
// SIFT and the cameras). Level l + 1 of a pyramid is level l smoothed by the binomial [1 4 6 4 1]/16
// in both directions and decimated by keeping every even pixel, so x_l = x_0 / 2^l exactly.
// Intensities are grey levels 0..255 as floats.
//
// Memory: ImagePyramid keeps its storage across frames and grows it only for a larger image, so
// building a pyramid for every frame of a video allocates on the first frame only. TrackPoints
// works on the stack (windows of at most kMaxFlowWindowRadius); it never allocates. Samples outside
// an image read the nearest border pixel, so no point, however far outside, reads out of bounds.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/base/image.h"
#include "core/base/status.h"

namespace reconar {

inline constexpr int kMaxPyramidLevels = 8;
inline constexpr int kMaxFlowWindowRadius = 15;

class ImagePyramid {
 public:
  // Levels 0 .. num_levels - 1 of `gray` (fewer when a level would be smaller than 8 pixels on a
  // side). InvalidArgument for an empty image or num_levels outside [1, kMaxPyramidLevels].
  Status Build(ImageView<const uint8_t> gray, int num_levels);

  int num_levels() const { return num_levels_; }
  int width() const { return num_levels_ > 0 ? widths_[0] : 0; }
  int height() const { return num_levels_ > 0 ? heights_[0] : 0; }
  ImageView<const float> level(int l) const {
    return ImageView<const float>(widths_[l], heights_[l], widths_[l], storage_.data() + offsets_[l]);
  }
  size_t capacity_bytes() const { return (storage_.capacity() + scratch_.capacity()) * sizeof(float); }

 private:
  std::vector<float> storage_;  // every level, one after the other
  std::vector<float> scratch_;  // one vertically smoothed row
  int num_levels_ = 0;
  int widths_[kMaxPyramidLevels] = {};
  int heights_[kMaxPyramidLevels] = {};
  size_t offsets_[kMaxPyramidLevels] = {};
};

struct OpticalFlowOptions {
  int window_radius = 6;     // the window is (2r + 1)^2 pixels at every level; <= kMaxFlowWindowRadius
  int num_levels = 4;        // levels used (at most the pyramids'); motion up to ~ r 2^(levels - 1) px
  int max_iterations = 12;   // per level
  double epsilon_px = 0.01;  // a level ends when its step is shorter than this (level pixels)
  // The window needs texture in two directions: the smaller eigenvalue of its mean structure
  // tensor (1/N) sum g g^T (g: intensity gradient, grey levels per pixel) at least this.
  double min_eigenvalue = 2.0;
  // Mean absolute intensity difference between the two windows at the found point (level 0).
  double max_mean_error = 24.0;

  // InvalidArgument naming the first offending field.
  Status Check() const;
};

enum class FlowStatus : uint8_t {
  kTracked,      // converged inside the frame with an error below max_mean_error
  kOutOfBounds,  // the point or its result lies outside the frame, or a result was not finite
  kFlatWindow,   // the window of the previous frame lacks texture in two directions
  kLargeError,   // the windows differ by more than max_mean_error at the result
};
const char* FlowStatusName(FlowStatus status);

struct FlowResult {
  Eigen::Vector2f point = Eigen::Vector2f::Zero();  // in the next frame (valid when kTracked)
  FlowStatus status = FlowStatus::kOutOfBounds;
  float mean_error = 0.0f;  // mean |I - T| at level 0 (grey levels)
};

// For each of `count` points of `previous` (level 0 pixels), its position in `next`, starting from
// `guesses[i]` (a predicted position in `next`) or from the point itself when guesses is null.
// InvalidArgument when the pyramids differ in size or level count, or the options fail Check().
Status TrackPoints(const ImagePyramid& previous, const ImagePyramid& next, const OpticalFlowOptions& options,
                   const Eigen::Vector2f* points, const Eigen::Vector2f* guesses, int count, FlowResult* results);

// Templates kept across frames: the level-0 window of a point in the frame where it was found,
// matched against later frames without the drift of chaining frame-to-frame flow. A template
// takes FlowTemplateFloats(window_radius) floats of storage the caller owns.
int FlowTemplateFloats(int window_radius);
// Fills `storage` with the window of `pyramid`'s level 0 around `point` (samples, gradients and
// their 2x2 tensor); false (storage unspecified) when the point is outside the image, the window
// is flat (options.min_eigenvalue) or the options fail Check().
bool MakeFlowTemplate(const ImagePyramid& pyramid, const Eigen::Vector2f& point, const OpticalFlowOptions& options,
                      float* storage);
// The position in `next`'s level 0 of a template made with the same options, by inverse-compositional
// iterations from `guess` (which must be within about window_radius pixels of the answer: no pyramid).
FlowResult AlignFlowTemplate(const ImagePyramid& next, const float* storage, const Eigen::Vector2f& guess,
                             const OpticalFlowOptions& options);

}  // namespace reconar
