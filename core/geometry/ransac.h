#pragma once
// Ransac<Estimator, LocalEstimator>: one robust-estimation loop for every estimator in this
// module (DESIGN.md: "One RANSAC template serves them all"). An Estimator is a type with
//   using Sample, Model; static constexpr int kMinSamples, kMaxModels;
//   static int Estimate(const Sample*, int count, std::array<Model, kMaxModels>*);
//   static void Residuals(const Sample*, int count, const Model&, double* squared_residuals);
// The loop is RANSAC (Fischler & Bolles 1981) with
//  - MSAC scoring (Torr & Zisserman 2000): cost = sum_i min(r_i^2, t^2); lower is better;
//  - the adaptive iteration count N = log(1 - confidence) / log(1 - w^kMinSamples) from the
//    inlier ratio w of the best model so far;
//  - LO-RANSAC (Chum, Matas & Kittler 2003): every new best model is locally optimised by least
//    squares (LocalEstimator with more than kMinSamples samples) on its inliers: inner RANSAC on
//    non-minimal subsets, iterated fits under a threshold shrinking to t, and a final polish.
//    A LocalEstimator that is iterative has, instead of Estimate,
//      static int Refine(const Sample*, int count, const Model& start, std::array<Model, kMaxModels>*);
//    and is started from the model whose inliers it fits;
//  - early exit from scoring a hypothesis once its partial cost exceeds the best cost;
//  - a SplitMix64 sampler seeded from the options: runs are deterministic.
// The minimal solver is called on a std::array copy of the sample; the per-run buffers
// (residuals, LO inliers) are allocated once per Run.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/base/prng.h"
#include "core/base/status.h"
#include "core/geometry/ransac_options.h"

namespace reconar {

namespace ransac_internal {

// Iterations after which an all-inlier minimal sample of `sample_size` has been drawn with
// probability `confidence` when a fraction `inlier_ratio` of the samples are inliers:
// log(1 - confidence) / log(1 - inlier_ratio^sample_size), clamped to [0, max_iterations].
inline int RequiredIterationsForRatio(double inlier_ratio, int sample_size, double confidence, int max_iterations) {
  if (!(inlier_ratio > 0.0)) return max_iterations;
  if (inlier_ratio >= 1.0) return 0;
  const double p_all_inliers = std::pow(inlier_ratio, sample_size);
  const double log_miss = std::log1p(-p_all_inliers);  // log(1 - w^s), accurate for tiny w^s
  if (!(log_miss < 0.0)) return max_iterations;
  const double n = std::log(1.0 - confidence) / log_miss;
  if (!(n < max_iterations)) return max_iterations;
  return static_cast<int>(std::ceil(n));
}

// The same for num_inliers of num_samples.
inline int RequiredIterations(int num_inliers, int num_samples, int sample_size, double confidence,
                              int max_iterations) {
  if (num_samples <= 0) return max_iterations;
  return RequiredIterationsForRatio(static_cast<double>(num_inliers) / num_samples, sample_size, confidence,
                                    max_iterations);
}

// Whether Estimator has the iterative Refine (see above) rather than Estimate.
template <typename Estimator, typename = void>
struct HasRefine : std::false_type {};
template <typename Estimator>
struct HasRefine<Estimator, std::void_t<decltype(Estimator::Refine(
                                static_cast<const typename Estimator::Sample*>(nullptr), 0,
                                std::declval<const typename Estimator::Model&>(),
                                static_cast<std::array<typename Estimator::Model, Estimator::kMaxModels>*>(nullptr)))>>
    : std::true_type {};

}  // namespace ransac_internal

template <typename Estimator, typename LocalEstimator = Estimator>
class Ransac {
 public:
  using Sample = typename Estimator::Sample;
  using Model = typename Estimator::Model;
  using Report = RansacReport<Model>;
  static_assert(std::is_same_v<Sample, typename LocalEstimator::Sample>, "estimators must share Sample");
  static_assert(std::is_same_v<Model, typename LocalEstimator::Model>, "estimators must share Model");
  static_assert(Estimator::kMinSamples > 0 && Estimator::kMaxModels > 0, "bad estimator constants");

  // InvalidArgument for options failing Check() or a negative count. Otherwise a report whose
  // status says whether a model was found.
  static Result<Report> Run(const Sample* samples, int count, const RansacOptions& options) {
    RECONAR_RETURN_IF_ERROR(options.Check());
    if (count < 0 || (count > 0 && samples == nullptr)) {
      return InvalidArgument("Ransac::Run: invalid sample array (count " + std::to_string(count) + ")");
    }
    Report report;
    if (count < Estimator::kMinSamples) {
      report.status = RansacStatus::kTooFewSamples;
      return report;
    }

    const double t2 = options.max_residual * options.max_residual;
    std::vector<double> residuals(static_cast<size_t>(count));
    LocalBuffers local_buffers;
    if (options.local_optimisation) {
      local_buffers.inliers.reserve(static_cast<size_t>(count));
      local_buffers.pool.reserve(static_cast<size_t>(count));
    }

    SplitMix64 rng(options.seed);
    std::array<int, Estimator::kMinSamples> indices;
    std::array<Sample, Estimator::kMinSamples> minimal;
    std::array<Model, Estimator::kMaxModels> models;
    Candidate best;
    int required = options.max_iterations;
    int iterations = 0;
    while (iterations < options.max_iterations &&
           (iterations < options.min_iterations || iterations < required)) {
      ++iterations;
      DrawSample(&rng, count, &indices);
      for (int i = 0; i < Estimator::kMinSamples; ++i) minimal[i] = samples[indices[i]];
      const int num_models = Estimator::Estimate(minimal.data(), Estimator::kMinSamples, &models);
      bool improved = false;
      for (int m = 0; m < num_models; ++m) {
        Candidate candidate;
        if (!Score(samples, count, models[m], t2, best.cost, residuals.data(), &candidate)) continue;
        if (candidate.cost < best.cost) {
          best = candidate;
          improved = true;
        }
      }
      if (!improved) continue;
      if (options.local_optimisation && options.local_iterations > 0) {
        // A model improved by LO is itself a new best: optimise again from it (its inlier set
        // differs), until a round brings no gain.
        for (int round = 0; round < kMaxLocalRounds; ++round) {
          const double before = best.cost;
          LocalOptimise(samples, count, options, t2, &rng, residuals.data(), &local_buffers, &best);
          ++report.local_optimisations;
          if (!(best.cost < before)) break;
        }
      }
      required = ransac_internal::RequiredIterations(best.num_inliers, count, Estimator::kMinSamples,
                                                     options.confidence, options.max_iterations);
    }

    report.iterations = iterations;
    if (best.num_inliers < Estimator::kMinSamples) {
      report.status = RansacStatus::kNoModel;
      return report;
    }
    report.status = RansacStatus::kSuccess;
    report.model = best.model;
    report.cost = best.cost;
    report.num_inliers = best.num_inliers;
    Estimator::Residuals(samples, count, best.model, residuals.data());
    report.inlier_mask.resize(static_cast<size_t>(count));
    for (int i = 0; i < count; ++i) report.inlier_mask[i] = residuals[i] < t2 ? 1 : 0;
    return report;
  }

  static Result<Report> Run(const std::vector<Sample>& samples, const RansacOptions& options) {
    return Run(samples.data(), static_cast<int>(samples.size()), options);
  }

 private:
  struct Candidate {
    Model model = Model::Zero();
    double cost = std::numeric_limits<double>::infinity();
    int num_inliers = 0;
  };

  // Scratch of the LO step, allocated once per Run.
  struct LocalBuffers {
    std::vector<Sample> inliers;  // least-squares input
    std::vector<Sample> pool;     // inliers of the best model, shuffled for inner samples
  };

  static constexpr int kScoreBlock = 256;    // residuals computed between early-exit checks
  static constexpr int kMaxLocalRounds = 5;  // LO rounds per new best model from a minimal sample

  // The least-squares fit of the LO step to `samples`, started from `start` when LocalEstimator
  // is iterative.
  static int LocalFit(const Sample* samples, int count, const Model& start,
                      std::array<Model, LocalEstimator::kMaxModels>* models) {
    if constexpr (ransac_internal::HasRefine<LocalEstimator>::value) {
      return LocalEstimator::Refine(samples, count, start, models);
    } else {
      return LocalEstimator::Estimate(samples, count, models);
    }
  }

  // kMinSamples distinct indices in [0, count), count >= kMinSamples, by rejection.
  static void DrawSample(SplitMix64* rng, int count, std::array<int, Estimator::kMinSamples>* indices) {
    for (int i = 0; i < Estimator::kMinSamples; ++i) {
      bool fresh;
      do {
        (*indices)[i] = static_cast<int>(rng->UniformInt(static_cast<uint32_t>(count)));
        fresh = std::find(indices->begin(), indices->begin() + i, (*indices)[i]) == indices->begin() + i;
      } while (!fresh);
    }
  }

  // MSAC cost and inlier count of `model`. Returns false (result unset) as soon as the partial
  // cost exceeds `bound`, which cannot beat the best model any more.
  static bool Score(const Sample* samples, int count, const Model& model, double t2, double bound,
                    double* residuals, Candidate* result) {
    double cost = 0.0;
    int num_inliers = 0;
    for (int begin = 0; begin < count; begin += kScoreBlock) {
      const int length = std::min(kScoreBlock, count - begin);
      Estimator::Residuals(samples + begin, length, model, residuals + begin);
      for (int i = begin; i < begin + length; ++i) {
        if (residuals[i] < t2) {
          cost += residuals[i];
          ++num_inliers;
        } else {
          cost += t2;
        }
      }
      if (cost > bound) return false;
    }
    result->model = model;
    result->cost = cost;
    result->num_inliers = num_inliers;
    return true;
  }

  // One least-squares step: LocalEstimator on the samples whose squared residual under `model`
  // is below `threshold2`, scored at t2. `residuals_current` says that `residuals` already holds
  // the residuals of `model`. On success `residuals` holds those of result->model; on failure
  // (too few samples qualify, or no model) its content is unspecified.
  static bool LeastSquaresStep(const Sample* samples, int count, const Model& model, bool residuals_current,
                               double threshold2, double t2, double* residuals, std::vector<Sample>* inliers,
                               Candidate* result) {
    if (!residuals_current) Estimator::Residuals(samples, count, model, residuals);
    inliers->clear();
    for (int i = 0; i < count; ++i) {
      if (residuals[i] < threshold2) inliers->push_back(samples[i]);
    }
    if (static_cast<int>(inliers->size()) < LocalEstimator::kMinSamples) return false;
    std::array<Model, LocalEstimator::kMaxModels> models;
    const int num_models = LocalFit(inliers->data(), static_cast<int>(inliers->size()), model, &models);
    Candidate step_best;
    int best_index = -1;
    for (int m = 0; m < num_models; ++m) {
      Candidate candidate;
      if (Score(samples, count, models[m], t2, std::numeric_limits<double>::infinity(), residuals, &candidate) &&
          candidate.cost < step_best.cost) {
        step_best = candidate;
        best_index = m;
      }
    }
    if (best_index < 0 || step_best.num_inliers == 0) return false;
    if (best_index != num_models - 1) Estimator::Residuals(samples, count, step_best.model, residuals);
    *result = step_best;
    return true;
  }

  // Iterated least squares from best->model with the inlier threshold shrinking from
  // local_threshold_multiplier * t to t over local_iterations steps (the "iterative" LO of Chum
  // et al.); `best` is replaced by any lower-cost model on the way.
  static void ShrinkingThresholdSteps(const Sample* samples, int count, const RansacOptions& options, double t2,
                                      double* residuals, std::vector<Sample>* inliers, Candidate* best) {
    const int steps = options.local_iterations;
    const double m = options.local_threshold_multiplier;
    Model current = best->model;
    bool residuals_current = false;
    Candidate candidate;
    for (int step = 0; step < steps; ++step) {
      const double fraction = steps > 1 ? static_cast<double>(step) / (steps - 1) : 1.0;
      const double multiplier = m - (m - 1.0) * fraction;
      if (!LeastSquaresStep(samples, count, current, residuals_current, t2 * multiplier * multiplier, t2, residuals,
                            inliers, &candidate)) {
        return;
      }
      current = candidate.model;
      residuals_current = true;
      if (candidate.cost < best->cost) *best = candidate;
    }
  }

  // Least squares on the inliers (threshold t) of `model`, repeated while the cost drops.
  static void Polish(const Sample* samples, int count, const RansacOptions& options, double t2, bool residuals_current,
                     double* residuals, std::vector<Sample>* inliers, Candidate* model) {
    Candidate candidate;
    for (int polish = 0; polish < options.local_iterations; ++polish) {
      if (!LeastSquaresStep(samples, count, model->model, residuals_current, t2, t2, residuals, inliers,
                            &candidate) ||
          !(candidate.cost < model->cost)) {
        return;
      }
      *model = candidate;
      residuals_current = true;
    }
  }

  // The LO step, a variant of "inner RANSAC with iteration" (Chum, Matas & Kittler 2003), run on
  // each new best model:
  //  1. shrinking-threshold least squares from the best model;
  //  2. inner RANSAC: local_inner_samples random subsets of the best model's inliers, of size
  //     min(|inliers| / 2, local_sample_size_factor * LocalEstimator::kMinSamples), are fitted by
  //     least squares and polished like 3. Subsets that miss the few outliers inside the
  //     threshold escape the fixed point where least squares keeps fitting them;
  //  3. polish: least squares on the best model's own inliers (threshold t) while the cost drops.
  // `best` is replaced by any lower-cost model.
  static void LocalOptimise(const Sample* samples, int count, const RansacOptions& options, double t2,
                            SplitMix64* rng, double* residuals, LocalBuffers* buffers, Candidate* best) {
    ShrinkingThresholdSteps(samples, count, options, t2, residuals, &buffers->inliers, best);

    Estimator::Residuals(samples, count, best->model, residuals);
    buffers->pool.clear();
    for (int i = 0; i < count; ++i) {
      if (residuals[i] < t2) buffers->pool.push_back(samples[i]);
    }
    const int pool_size = static_cast<int>(buffers->pool.size());
    const int subset_size = std::min(pool_size / 2, options.local_sample_size_factor * LocalEstimator::kMinSamples);
    if (subset_size > LocalEstimator::kMinSamples) {
      std::array<Model, LocalEstimator::kMaxModels> models;
      for (int repetition = 0; repetition < options.local_inner_samples; ++repetition) {
        // Partial Fisher-Yates shuffle: the first subset_size entries become a uniform subset.
        for (int i = 0; i < subset_size; ++i) {
          const int j = i + static_cast<int>(rng->UniformInt(static_cast<uint32_t>(pool_size - i)));
          std::swap(buffers->pool[i], buffers->pool[j]);
        }
        const int num_models = LocalFit(buffers->pool.data(), subset_size, best->model, &models);
        for (int m = 0; m < num_models; ++m) {
          Candidate candidate;
          if (!Score(samples, count, models[m], t2, std::numeric_limits<double>::infinity(), residuals, &candidate)) {
            continue;
          }
          Polish(samples, count, options, t2, /*residuals_current=*/true, residuals, &buffers->inliers, &candidate);
          if (candidate.cost < best->cost) *best = candidate;
        }
      }
    }
    Polish(samples, count, options, t2, /*residuals_current=*/false, residuals, &buffers->inliers, best);
  }
};

}  // namespace reconar
