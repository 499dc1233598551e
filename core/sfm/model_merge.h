#pragma once
// Merging two models of one image set (the issue-17 multi-model mapper): the similarity that takes
// one model into the other's frame, from the 3D points the two share. Two points are the same
// when a verified match joins their observations (the models hold disjoint images), or when one
// image registered in both observes both with one keypoint. The similarity is found by RANSAC over
// 3-point samples (AlignSimilarity) and verified in the images: a shared point is an inlier when
// each model's estimate of it, moved into the other model, reprojects within the bound in every
// view of the other model that observes it. COLMAP merges the same way (Reconstruction::Merge,
// with its common images' points).
#include <vector>

#include "core/base/status.h"
#include "core/math/sim3.h"
#include "core/sfm/mapper.h"
#include "core/sfm/reconstruction.h"

namespace reconar {

struct ModelMergeOptions {
  double max_error_px = 4.0;      // the reprojection bound of an inlier, in both models' views
  int min_inliers = 12;           // an alignment needs this many inliers ...
  double min_inlier_ratio = 0.5;  // ... and this fraction of the shared points
  int max_iterations = 2000;      // RANSAC samples (all triples when there are fewer)
};

struct ModelAlignment {
  Sim3 to_from_from;  // X_to = scale * R X_from + t
  int num_shared_points = 0;
  int num_inliers = 0;
  // Set when the alignment came from the two-view geometry of one verified pair between the
  // models (AlignModelsByTwoViewGeometry): its images, `to`'s first.
  int pair_to_image = -1, pair_from_image = -1;
};

// The similarity taking `from` into `to`'s frame; FailedPrecondition, with the counts, when the
// models share too few points or no similarity explains enough of them. Both models index the
// same images (the mapper's input order) and cameras.
Result<ModelAlignment> AlignModels(const Reconstruction& to, const Reconstruction& from,
                                   const std::vector<MapperPair>& pairs, const ModelMergeOptions& options);

// When the models share too few points for AlignModels: the similarity from a verified pair
// between them (an image registered in `to`, one in `from`; a pair the two-view check found
// nearly planar too: the calibrated relative pose holds for a plane seen with a baseline, and the
// points then tell). The pair's relative pose
// (pair_pose.h, under `to`'s intrinsics where `to` uses the camera) gives the rotation between
// the frames and the direction of the baseline; the length of the baseline in `to`'s units is
// the one `to`'s points seen in the pair put on the `from` image's rays, and the ratio of the
// units is the one `from`'s points seen in the pair put on the `to` image's rays
// (FitBaselineLength; each needs min_points agreeing points). The pair with the most agreeing
// points on the weaker side is taken. FailedPrecondition, with the best pair's counts, when no pair
// gives both. The caller verifies the joined model (MapperOptions::merge_models).
Result<ModelAlignment> AlignModelsByTwoViewGeometry(const Reconstruction& to, const Reconstruction& from,
                                                    const std::vector<MapperPair>& pairs, const MapperOptions& options,
                                                    int min_points);

// `to` with `from`'s registered images that `to` lacks added at their aligned poses; each such
// image's camera keeps `to`'s intrinsics when a registered image of `to` uses it, else takes
// `from`'s. Points are not carried over: the caller triangulates the union's tracks again.
Reconstruction CombineRegisteredImages(const Reconstruction& to, const Reconstruction& from, const Sim3& to_from_from);

}  // namespace reconar
