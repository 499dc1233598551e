#include "core/geometry/ransac_options.h"

#include <cmath>
#include <string>

namespace reconar {

Status RansacOptions::Check() const {
  if (!(max_residual > 0.0) || !std::isfinite(max_residual)) {
    return InvalidArgument("RansacOptions.max_residual must be positive and finite, got " + std::to_string(max_residual));
  }
  if (!(confidence > 0.0 && confidence < 1.0)) {
    return InvalidArgument("RansacOptions.confidence must be in (0, 1), got " + std::to_string(confidence));
  }
  if (max_iterations < 1) {
    return InvalidArgument("RansacOptions.max_iterations must be >= 1, got " + std::to_string(max_iterations));
  }
  if (min_iterations < 0 || min_iterations > max_iterations) {
    return InvalidArgument("RansacOptions.min_iterations must be in [0, max_iterations], got " +
                           std::to_string(min_iterations));
  }
  if (local_iterations < 0) {
    return InvalidArgument("RansacOptions.local_iterations must be >= 0, got " + std::to_string(local_iterations));
  }
  if (local_inner_samples < 0) {
    return InvalidArgument("RansacOptions.local_inner_samples must be >= 0, got " + std::to_string(local_inner_samples));
  }
  if (local_sample_size_factor < 1) {
    return InvalidArgument("RansacOptions.local_sample_size_factor must be >= 1, got " +
                           std::to_string(local_sample_size_factor));
  }
  if (!(local_threshold_multiplier >= 1.0) || !std::isfinite(local_threshold_multiplier)) {
    return InvalidArgument("RansacOptions.local_threshold_multiplier must be >= 1, got " +
                           std::to_string(local_threshold_multiplier));
  }
  return Status::Ok();
}

const char* RansacStatusName(RansacStatus status) {
  switch (status) {
    case RansacStatus::kSuccess: return "success";
    case RansacStatus::kTooFewSamples: return "too few samples";
    case RansacStatus::kNoModel: return "no model";
  }
  return "unknown";
}

}  // namespace reconar
