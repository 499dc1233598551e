#pragma once
// The mapper's bundle-adjustment adapter: the model's registered images and points become a
// RadialProblem (12 doubles per camera: angle-axis, translation, f, k1, k2, cx, cy, aspect),
// SolveBundleAdjustment (core/optim/bundle_adjuster.h) refines it, and the result is written back.
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/optim/bal_problem.h"
#include "core/sfm/mapper.h"
#include "core/sfm/mapper_model.h"
#include "core/sfm/reconstruction.h"

namespace reconar {

// Which intrinsics beyond the focal an adjustment refines.
struct IntrinsicsChoice {
  bool principal_point = false;
  bool distortion = false;
  bool aspect = false;

  bool operator==(const IntrinsicsChoice& other) const {
    return principal_point == other.principal_point && distortion == other.distortion && aspect == other.aspect;
  }
};

struct MapperAdjustment {
  int iterations = 0;
  double function_tolerance = 1e-6;  // relative cost change that ends the adjustment
  IntrinsicsChoice free;
};

// Adjusts the cameras `variable`, every point they see, and holds the other registered cameras
// that see those points constant. The focal (MapperOptions::refine_focal) and the distortion are
// refined only once three images are registered, a shared camera only in a global adjustment
// (`variable` = every registered image). Counts the adjustment and its time in `report`.
// Returns the final cost. On failure the model is left unchanged: InvalidArgument for bad options
// or a malformed problem (from SolveBundleAdjustment), NumericFailure when the adjuster ended in
// numeric failure.
Result<double> BundleAdjust(MapperModel* model, const std::vector<MapperImage>& images,
                            const std::vector<int>& variable, const MapperAdjustment& adjustment,
                            const MapperOptions& options, MapperReport* report);

// Appends the image's pose and its camera's intrinsics as the bundle adjuster's camera block
// (angle-axis, translation, focal, k1, k2, cx, cy, aspect: core/optim/radial_camera_model.h).
void AppendCameraBlock(const SfmImage& image, const SfmCamera& camera, RadialProblem* problem);

// The weight of an observation of a keypoint detected at `keypoint_scale` (MapperOptions::
// weight_by_scale: base_scale_px / scale above the base scale, else 1); a keypoint with a weight
// of its own (a tag corner: kTagCornerWeight) has that instead.
double ScaleWeight(double keypoint_scale, const MapperOptions& options);

// How well the tag squares (tag_squares.h) predict each other's size: the square tags in two folds
// (alternate ids), the model adjusted globally once per fold with only the other fold's tags held
// to squares (intrinsics held, the focal refined as options say), and each left-out tag's four
// edges and two diagonals measured against the held tags' mean edge (times the root of two for a
// diagonal). Returns those relative errors: the scale's variation across the model that a
// measurement inherits, which the squares hide in the final model's own tags. Empty with fewer
// than two square tags; `rec` is not changed.
std::vector<double> CrossCheckTagSquares(const Reconstruction& rec, const std::vector<MapperImage>& images,
                                         const MapperOptions& options, MapperReport* report);

// Records a failed adjustment in `report` (num_failed_ba, first_ba_failure) and returns Ok, so
// that the mapper carries on with the model as it was; InvalidArgument, a programming error, is
// returned instead. Ok passes through uncounted.
Status CountFailedAdjustment(const Status& status, MapperReport* report);

// The new image and up to MapperOptions::local_ba_images registered images sharing the most
// points with it (most first, ties by index).
std::vector<int> LocalBundle(const MapperModel& model, int image, const MapperOptions& options);

}  // namespace reconar
