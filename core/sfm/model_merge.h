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
};

// The similarity taking `from` into `to`'s frame; FailedPrecondition, with the counts, when the
// models share too few points or no similarity explains enough of them. Both models index the
// same images (the mapper's input order) and cameras.
Result<ModelAlignment> AlignModels(const Reconstruction& to, const Reconstruction& from,
                                   const std::vector<MapperPair>& pairs, const ModelMergeOptions& options);

// `to` with `from`'s registered images that `to` lacks added at their aligned poses; each such
// image's camera keeps `to`'s intrinsics when a registered image of `to` uses it, else takes
// `from`'s. Points are not carried over: the caller triangulates the union's tracks again.
Reconstruction CombineRegisteredImages(const Reconstruction& to, const Reconstruction& from, const Sim3& to_from_from);

}  // namespace reconar
