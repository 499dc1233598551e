#pragma once
// The choice of which intrinsics beyond the focal the mapper's final adjustment refines: the
// principal point (MapperOptions::principal_point), the distortion (refine_distortion;
// k1 = k2 = 0 otherwise) and the pixel aspect ratio (refine_aspect), by forward selection under
// the Bayesian information criterion (Schwarz 1978): BIC = 2 cost / s^2 + (free intrinsics)
// ln(residuals), s^2 the residual variance of the model with everything allowed free. Every
// candidate is adjusted (final_ba_iterations, final_ba_function_tolerance) from the same state
// on the same observations.
#include <vector>

#include "core/base/status.h"
#include "core/sfm/mapper.h"
#include "core/sfm/mapper_adjustment.h"
#include "core/sfm/mapper_model.h"

namespace reconar {

// Leaves the model in the chosen candidate's adjusted state and records the choice in `report`
// (principal_point_refined, distortion_refined, aspect_refined). A candidate whose adjustment
// fails numerically is counted (CountFailedAdjustment) and not chosen; InvalidArgument is
// returned.
Result<IntrinsicsChoice> SelectIntrinsicsModel(MapperModel* model, const std::vector<MapperImage>& images,
                                               const MapperOptions& options, MapperReport* report);

}  // namespace reconar
