#pragma once
// Patch-based multi-view stereo after Furukawa & Ponce, "Accurate, Dense, and Robust Multiview
// Stereopsis", PAMI 32(8), 2010 (PMVS): match Harris/DoG features along epipolar lines into
// oriented patches, expand them into empty neighbouring image cells, and filter by visibility,
// depth-map and neighbourhood consistency. A patch is a mu x mu grid on a plane (centre c, unit
// normal n towards its reference camera R), scored by the mean NCC between its projection into R
// and into each other image that sees it.
//
// Conventions: DenseView (core/mvs/dense_view.h): undistorted pinhole, pixel centres at integers,
// cam_from_world poses. Output in world coordinates.
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/mvs/dense_view.h"
#include "core/mvs/oriented_points.h"

namespace reconar {

struct PatchMvsOptions {
  int patch_size = 5;              // mu: a patch is mu x mu samples, one pixel apart in R (odd, 3..15)
  int cell_size = 2;               // beta: image cells of beta x beta pixels, at most one patch wanted per cell
  double max_view_angle = M_PI / 3;  // iota: an image sees a patch if angle(normal, ray to camera) < iota
  double min_ncc = 0.7;            // an image supports a patch when its NCC with R is at least this
  // Standard deviation sigma_n of the image noise, grey levels (0..255). It sets the texture floor
  // (MinTextureStd): under noise, a true match whose texture has standard deviation s correlates
  // at about s^2 / (s^2 + sigma_n^2) between two images, which reaches min_ncc only when the
  // observed deviation sqrt(s^2 + sigma_n^2) >= sigma_n / sqrt(1 - min_ncc) (1.83 sigma_n for 0.7).
  // Reference windows below that floor are refused: what passes the NCC test there is noise or
  // quantisation pattern (e.g. the dark background of a studio capture).
  double image_noise_std = 2.0;
  int min_visible_views = 3;       // gamma: images (R included) that must support a patch
  int expansion_iterations = 3;    // rounds of expansion followed by filtering
  int num_threads = 0;             // 0 = all cores
  bool show_progress = false;
  std::string progress_label = "patch MVS expansion";  // of the expansion rounds' progress line

  Status Check() const;
  // The texture floor sigma_n / sqrt(1 - min_ncc) in grey levels (see image_noise_std).
  double MinTextureStd() const { return image_noise_std / std::sqrt(1.0 - min_ncc); }
};

struct PatchMvsReport {
  size_t features = 0;          // Harris + DoG features over all images
  size_t initial_patches = 0;   // patches accepted by feature matching
  size_t expanded_patches = 0;  // patches added by expansion (all rounds)
  size_t final_patches = 0;     // after the last filtering
  double seconds_features = 0.0;
  double seconds_matching = 0.0;
  double seconds_expansion = 0.0;
  double seconds_filtering = 0.0;
};

// Reconstructs oriented points from at least min_visible_views registered views. Fails with
// InvalidArgument on bad options, null or empty views, and FailedPrecondition when no patch
// survives (e.g. textureless or unrelated images).
Result<OrientedPoints> RunPatchMvs(const std::vector<const DenseView*>& views, const PatchMvsOptions& options,
                                   PatchMvsReport* report = nullptr);

}  // namespace reconar
