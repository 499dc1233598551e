#pragma once
// The mapper's initial pair: the best-matched pairs with parallax are tried in order (two-view
// geometry, triangulation, one adjustment) until one gives enough points at enough median
// triangulation angle; when none does, the bounds are halved and the pairs tried again, down to
// MapperOptions::init_min_points_floor / init_min_angle_floor_deg (like COLMAP's mapper).
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/sfm/mapper.h"
#include "core/sfm/mapper_model.h"

namespace reconar {

// The bounds an initial model must meet.
struct InitialPairBounds {
  int min_points = 0;
  double min_median_angle_deg = 0.0;
};

// Starts the model from the first pair that meets the bounds (relaxed as above); sets
// report->initial_pair and init_relaxations. FailedPrecondition, with the last pair's reason,
// when no pair does; InvalidArgument from a bundle adjustment passes through (see
// CountFailedAdjustment).
Status InitializeFromBestPair(MapperModel* model, const std::vector<MapperImage>& images,
                              const std::vector<MapperPair>& pairs, const MapperOptions& options, MapperReport* report);

// Registers the pair (essential matrix, relative pose), triangulates, adjusts and filters. An
// empty string on success; otherwise the reason, with the model reset (MapperModel::Reset).
Result<std::string> TryInitialPair(MapperModel* model, const std::vector<MapperImage>& images, const MapperPair& pair,
                                   const InitialPairBounds& bounds, const MapperOptions& options, MapperReport* report);

// Empty when the model's points meet the bounds, otherwise why not.
std::string CheckInitialModel(const MapperModel& model, const std::string& pair_name, const InitialPairBounds& bounds);

}  // namespace reconar
