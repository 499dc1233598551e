#pragma once
// Memory model of one dense run, used to pick the resolution level and the cluster size from a
// budget. While the multi-view stereo works on a cluster the process holds, per view of P pixels
// at the level, kViewBytesPerPixel (the undistorted DenseView: RGB + grey) and the method's work
// bytes per pixel (DenseMemoryInput::work_bytes_per_pixel):
//   PMVS (PmvsWorkBytesPerPixel)
//     kPmvsBytesPerPixel            per-pixel work images (feature responses, visibility)
//     kPmvsBytesPerCell / cell^2    cell lists and the patches that fill them: a list head per
//                                   cell, and at most one patch per cell of each image, each
//                                   patch (about 128 bytes with its image list and cell entries)
//                                   lying in the cells of at least 3 images (PMVS's gamma)
//   PatchMatch: kPatchMatchBytesPerPixel (core/mvs/patchmatch/patchmatch_mvs.h)
// plus, during undistortion, one decoded full-resolution photo (3 bytes per pixel) and its level
// copy per worker thread. The constants are a model, not a bound: the stage reports the measured
// peak RSS next to the estimate.
#include <cstddef>
#include <vector>

#include "core/base/status.h"

namespace reconar {

constexpr double kViewBytesPerPixel = 4.0;
constexpr double kPmvsBytesPerPixel = 16.0;
constexpr double kPmvsBytesPerCell = 4.0 + 128.0 / 3.0;

inline double PmvsWorkBytesPerPixel(int cell_size) {
  const double cell = static_cast<double>(cell_size < 1 ? 1 : cell_size);
  return kPmvsBytesPerPixel + kPmvsBytesPerCell / (cell * cell);
}

struct DenseMemoryInput {
  std::vector<std::pair<int, int>> image_sizes;  // full-resolution width, height of every kept image
  int max_cluster_size = 20;
  double work_bytes_per_pixel = PmvsWorkBytesPerPixel(2);  // the method's, see above
  int num_threads = 1;
  size_t baseline_bytes = 0;  // already held by the caller (model, merged points so far)
  // The automatic level skips the levels at which the longest image side exceeds this (0: none);
  // the coarsest level is taken when every level does.
  int max_image_size = 0;
};

// The finest level 0..kMaxDenseLevel at which no image's longest side exceeds max_image_size.
int FinestLevelWithinSize(const std::vector<std::pair<int, int>>& image_sizes, int max_image_size);

// Estimated peak bytes for a cluster of `cluster_size` of the largest images at `level`.
size_t EstimateDenseBytes(const DenseMemoryInput& input, int level, int cluster_size);

struct DenseLevelChoice {
  int level = 0;
  int max_cluster_size = 0;  // possibly below the requested one so that the estimate fits
  size_t estimated_bytes = 0;
  bool reduced_cluster_size = false;
  int finest_level_within_size = 0;  // requested_level -1: FinestLevelWithinSize(input), where the search began
};

// requested_level -1: the finest level from FinestLevelWithinSize(input) whose estimate fits the
// budget at the requested cluster size; otherwise that level. When even that does not fit, the
// cluster size shrinks (not below min_cluster_size). ResourceExhausted, with the numbers, when
// nothing fits.
Result<DenseLevelChoice> ChooseDenseLevel(const DenseMemoryInput& input, int requested_level, size_t budget_bytes,
                                          int min_cluster_size);

// `choice` with its cluster size raised to the largest (up to every image) whose estimate at
// choice.level still fits the budget; unchanged when it was reduced for the budget already.
DenseLevelChoice GrowClusterToBudget(const DenseMemoryInput& input, const DenseLevelChoice& choice,
                                     size_t budget_bytes);

}  // namespace reconar
