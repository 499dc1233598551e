#pragma once
// The mapper's initial pair (like COLMAP's mapper, with a look at the geometry first): pairs with
// parallax are taken in match-count order, as far down the list as needed, and one is tried
// (two-view geometry, triangulation, one adjustment) only when a quick two-view reconstruction
// (relative pose, each inlier's triangulation angle) could give enough points at enough median
// triangulation angle; the first that does, and whose points a third image sees enough of to
// register, starts the model. When none does, the bounds are halved and the pairs tried again,
// down to MapperOptions::init_min_points_floor / init_min_angle_floor_deg; a model no third image
// can join is the last resort.
#include <set>
#include <string>
#include <utility>
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
// kMatchCount: the pairs as above. kGeometry: the pairs that pass the quick test ranked by their
// inliers at the bounds' angle or more (for a start again after a failed one, see
// MapperOptions::min_model_images: in a dense sequence the best-matched pairs that pass start
// models that stall).
enum class InitialPairOrder { kMatchCount, kGeometry };

// Quick two-view scores kept across the starts of one model (MapperOptions::init_max_starts):
// they depend only on the pair and the cameras' priors, the same at every start.
struct InitialPairScores {
  std::vector<std::vector<double>> angles;  // per pair: the inliers' triangulation angles, sorted
  std::vector<char> scored;                 // per pair
};

// Pairs of images in `excluded` (image_a, image_b as in the pair) are passed over: the starts
// that failed before. Sets report->initial_image_a, initial_image_b.
Status InitializeFromBestPair(MapperModel* model, const std::vector<MapperImage>& images,
                              const std::vector<MapperPair>& pairs, const MapperOptions& options, MapperReport* report,
                              const std::set<std::pair<int, int>>& excluded = {},
                              InitialPairOrder order_by = InitialPairOrder::kMatchCount,
                              InitialPairScores* scores = nullptr);

// Registers the pair (essential matrix, relative pose), triangulates, adjusts and filters. An
// empty string on success; otherwise the reason, with the model reset (MapperModel::Reset).
Result<std::string> TryInitialPair(MapperModel* model, const std::vector<MapperImage>& images, const MapperPair& pair,
                                   const InitialPairBounds& bounds, const MapperOptions& options, MapperReport* report);

// Empty when the model's points meet the bounds, otherwise why not.
std::string CheckInitialModel(const MapperModel& model, const std::string& pair_name, const InitialPairBounds& bounds);

// Empty when an image outside the model sees enough of its points to register under the looser
// of the two registration rules (or when there is no other image); otherwise why the model is a
// dead end.
std::string CheckExtendable(const MapperModel& model, const std::string& pair_name, const MapperOptions& options);

}  // namespace reconar
