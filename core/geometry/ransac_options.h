#pragma once
// Options and report of the RANSAC template (ransac.h), kept apart from the template so that
// callers that only configure RANSAC (two_view.h) need not see it.
#include <cstdint>
#include <vector>

#include "core/base/status.h"

namespace reconar {

struct RansacOptions {
  // Inlier threshold on the residual (pixels for F and H); compared against the estimators'
  // squared residuals as max_residual^2.
  double max_residual = 4.0;
  // Probability that at least one all-inlier minimal sample is drawn; drives the adaptive
  // iteration count N = log(1 - confidence) / log(1 - w^s) (Fischler & Bolles 1981).
  double confidence = 0.999;
  int min_iterations = 50;
  int max_iterations = 10000;
  // Seed of the sampler; the same seed and input give bit-identical results.
  uint64_t seed = 0x7265636F6E617221ull;  // "reconar!"
  // LO-RANSAC (Chum, Matas & Kittler, DAGM 2003): each new best model is refined by least
  // squares on its inliers: iterated fits with a threshold shrinking from
  // local_threshold_multiplier * max_residual to max_residual over local_iterations steps, then
  // local_inner_samples fits to random subsets of its inliers of size
  // min(|inliers| / 2, local_sample_size_factor * kMinSamples) (inner RANSAC), each polished by
  // up to local_iterations refits on its own inliers; see ransac.h.
  bool local_optimisation = true;
  int local_iterations = 4;
  double local_threshold_multiplier = 2.0;
  int local_inner_samples = 10;
  int local_sample_size_factor = 7;

  // InvalidArgument naming the first offending field.
  Status Check() const;
};

enum class RansacStatus {
  kSuccess,         // the best model has >= Estimator::kMinSamples inliers
  kTooFewSamples,   // fewer samples than Estimator::kMinSamples were given
  kNoModel,         // no minimal sample gave a model with >= kMinSamples inliers (e.g. every
                    // sample degenerate: coincident or collinear points)
};

const char* RansacStatusName(RansacStatus status);

template <typename Model>
struct RansacReport {
  using Status = RansacStatus;
  Status status = Status::kNoModel;
  Model model = Model::Zero();      // best model (zero unless kSuccess)
  int num_inliers = 0;              // samples with squared residual < max_residual^2 under `model`
  std::vector<char> inlier_mask;    // one entry per sample, 1 for inliers (empty unless kSuccess)
  int iterations = 0;               // minimal samples drawn
  int local_optimisations = 0;      // LO rounds run (>= 1 per new best model from a minimal sample)
  double cost = 0.0;                // MSAC cost of `model`: sum of min(r^2, max_residual^2)
};

}  // namespace reconar
