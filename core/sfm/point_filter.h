#pragma once
// Outlier filtering of the mapper's points.
#include <vector>

#include "core/sfm/mapper.h"
#include "core/sfm/mapper_model.h"

namespace reconar {

// For each of `point_ids` (deleted ones are skipped): drops the observations whose reprojection
// error exceeds MapperOptions::max_reprojection_error_px, then deletes the point when fewer than
// two views remain or their triangulation angle is below min_triangulation_angle_deg.
void FilterPoints(MapperModel* model, const std::vector<int>& point_ids, const MapperOptions& options);

}  // namespace reconar
