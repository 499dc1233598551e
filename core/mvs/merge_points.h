#pragma once
// Merging the oriented points of several PMVS runs (one per view cluster, core/mvs/view_clustering.h):
// clusters overlap, so a surface seen by two clusters comes back twice. A point is dropped when a
// better-scored point already kept lies within its footprint (the world size of one pixel in the
// closest view of its cluster) and faces the same side (normals less than 90 degrees apart).
// Points are visited by decreasing score (ties: cluster order, then index), so the result is
// deterministic. Cost: a hash grid with the median footprint as cell size.
#include <vector>

#include "core/mvs/dense_view.h"
#include "core/mvs/oriented_points.h"

namespace reconar {

struct MergeInput {
  OrientedPoints points;
  // One footprint per point, world units; <= 0 means "keep unconditionally" (nothing to compare).
  std::vector<float> footprints;
};

// World size of one pixel at `position` in the closest of `views` that has it in front of the
// camera and inside the image: depth / fx. 0 when no view sees it.
float PixelFootprint(const std::vector<const DenseView*>& views, const Eigen::Vector3f& position);

struct MergeReport {
  size_t input_points = 0;
  size_t duplicates_dropped = 0;
};

// `kept_footprints`, when given, receives the footprint of every kept point (in the result's order),
// so that the result can be merged again without computing them anew.
OrientedPoints MergeOrientedPoints(const std::vector<MergeInput>& parts, MergeReport* report = nullptr,
                                   std::vector<float>* kept_footprints = nullptr);

}  // namespace reconar
