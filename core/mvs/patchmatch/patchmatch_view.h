#pragma once
// PatchMatch on one reference view (Bleyer et al. 2011; Xu & Tao 2019, ACMH): random planes,
// then sweeps that visit the pixels of one checkerboard colour in parallel (all of them depend
// only on pixels of the other colour), each testing the planes of neighbours (in each of the four
// directions the cheapest of the pixels 1, 3, ... 11 away; see separate_near_neighbours) and a
// few random and perturbed planes of shrinking range. The cost of a plane is
// 1 - NCC between a bilaterally weighted window of the reference and its homography warp into a
// source view, averaged over the best cost_top_k sources; the geometric term of Schoenberger et
// al. 2016 (sec. 4.2) is optional.
#include <cstdint>
#include <vector>

#include "core/base/image.h"
#include "core/mvs/dense_view.h"
#include "core/mvs/patchmatch/depth_map.h"
#include "core/mvs/patchmatch/patchmatch_mvs.h"

namespace reconar {

class ThreadPool;

struct PatchMatchViewInput {
  const DenseView* reference = nullptr;
  const Image<float>* reference_grey = nullptr;  // grey in [0, 1] (Gray8ToFloat), same size as the view
  std::vector<const DenseView*> sources;
  std::vector<const Image<float>*> source_greys;
  // The sources' depth maps, for the geometric term (an empty map contributes its maximum).
  std::vector<const DepthMap*> source_depths;
  double depth_min = 0.0, depth_max = 0.0;
  uint64_t seed = 0;  // the view's stream of random hypotheses
};

// Photometric PatchMatch: random initialisation of `map` (reset to the reference's size), then
// options.iterations sweeps.
void RunPhotometricPatchMatch(const PatchMatchViewInput& input, const PatchMatchOptions& options, ThreadPool* pool,
                              DepthMap* map);

// Coarse to fine: `coarse_map`, the photometric result on `coarse_view` (the reference at half
// resolution, same pose), gives every pixel its starting plane; then options.fine_iterations sweeps.
void RunPatchMatchFromCoarse(const PatchMatchViewInput& input, const DepthMap& coarse_map, const DenseView& coarse_view,
                             const PatchMatchOptions& options, ThreadPool* pool, DepthMap* map);

// Geometric consistency: from the planes in `map` (a photometric result), options.geometric_iterations
// sweeps whose cost adds the geometric term against input.source_depths; map->cost is then the
// photometric cost of the final planes again.
void RunGeometricPatchMatch(const PatchMatchViewInput& input, const PatchMatchOptions& options, ThreadPool* pool,
                            DepthMap* map);

}  // namespace reconar
