#include "core/texture/photo_gains.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

#include "core/base/median.h"

namespace reconar {
namespace {

// Huber's constant for 95 % efficiency under Gaussian noise, in units of the residuals' scale.
constexpr double kHuberThreshold = 1.345;
// The median of the RMS of three standard normals (sqrt of chi-square(3)'s median over 3): the
// median RMS residual divided by it estimates the residuals' standard deviation.
constexpr double kMedianRmsOfThreeNormals = 0.8880;

bool Usable(const FaceCandidate& candidate) {
  for (const float value : candidate.colour) {
    if (value < kMinGainColour || value > kMaxGainColour) return false;
  }
  return true;
}

}  // namespace

std::vector<Eigen::Vector3f> EstimatePhotoGains(const FaceCandidateTable& table, size_t num_photos,
                                                const PhotoGainOptions& options) {
  if (num_photos == 0) return {};
  const size_t num_faces = table.begin.empty() ? 0 : table.begin.size() - 1;
  const size_t num_candidates = table.candidates.size();
  // Per candidate (floats: a million candidates are common): its log colour and weight; weight 0 for
  // a candidate left out, or on a face with fewer than two usable candidates.
  std::vector<Eigen::Vector3f> log_colour(num_candidates, Eigen::Vector3f::Zero());
  std::vector<float> weight(num_candidates, 0.0f);
  for (size_t f = 0; f < num_faces; ++f) {
    const size_t begin = table.begin[f], end = table.begin[f + 1];
    size_t usable = 0;
    for (size_t k = begin; k < end; ++k) usable += Usable(table.candidates[k]);
    if (usable < 2) continue;
    for (size_t k = begin; k < end; ++k) {
      const FaceCandidate& candidate = table.candidates[k];
      if (!Usable(candidate)) continue;
      weight[k] = 1.0f;
      for (int c = 0; c < 3; ++c) log_colour[k][c] = std::log(candidate.colour[static_cast<size_t>(c)]);
    }
  }

  const Eigen::Index n = static_cast<Eigen::Index>(num_photos);
  Eigen::MatrixXd system(n, n);
  Eigen::MatrixX3d rhs(n, 3), log_gain = Eigen::MatrixX3d::Zero(n, 3);
  std::vector<float> rms(num_candidates, 0.0f);  // per candidate, its last RMS log residual
  std::vector<float> residuals;
  residuals.reserve(num_candidates);
  auto photo_of = [&](size_t k) { return static_cast<Eigen::Index>(table.candidates[k].photo); };
  auto face_mean = [&](size_t begin, size_t end, double* total_weight) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double total = 0.0;
    for (size_t k = begin; k < end; ++k) {
      sum += weight[k] * (log_colour[k].cast<double>() + log_gain.row(photo_of(k)).transpose());
      total += weight[k];
    }
    *total_weight = total;
    return total > 0.0 ? Eigen::Vector3d(sum / total) : Eigen::Vector3d::Zero();
  };

  for (int round = 0; round < std::max(1, options.max_rounds); ++round) {
    if (round > 0) {
      // Huber weights from the residuals of the last solution, against the faces' weighted means.
      residuals.clear();
      for (size_t f = 0; f < num_faces; ++f) {
        const size_t begin = table.begin[f], end = table.begin[f + 1];
        double total = 0.0;
        const Eigen::Vector3d mean = face_mean(begin, end, &total);
        if (total <= 0.0) continue;
        for (size_t k = begin; k < end; ++k) {
          if (weight[k] <= 0.0) continue;
          const Eigen::Vector3d residual = log_colour[k].cast<double>() + log_gain.row(photo_of(k)).transpose() - mean;
          rms[k] = static_cast<float>(std::sqrt(residual.squaredNorm() / 3.0));
          residuals.push_back(rms[k]);
        }
      }
      if (residuals.empty()) break;
      const double scale = MedianInPlace(residuals.data(), residuals.size()) / kMedianRmsOfThreeNormals;
      if (!(scale > 0.0)) break;
      const double threshold = kHuberThreshold * scale;
      for (size_t k = 0; k < num_candidates; ++k) {
        if (weight[k] > 0.0f) weight[k] = rms[k] <= threshold ? 1.0f : static_cast<float>(threshold / rms[k]);
      }
    }
    // Normal equations: with r_f eliminated, each face adds w_p (a_p - mean_f(a)) = -w_p (x_p - mean_f(x)).
    system.setZero();
    rhs.setZero();
    for (size_t f = 0; f < num_faces; ++f) {
      const size_t begin = table.begin[f], end = table.begin[f + 1];
      double total = 0.0;
      Eigen::Vector3d mean_colour = Eigen::Vector3d::Zero();
      for (size_t k = begin; k < end; ++k) {
        mean_colour += weight[k] * log_colour[k].cast<double>();
        total += weight[k];
      }
      if (total <= 0.0) continue;
      mean_colour /= total;
      for (size_t k = begin; k < end; ++k) {
        if (weight[k] <= 0.0) continue;
        const Eigen::Index p = photo_of(k);
        system(p, p) += weight[k];
        rhs.row(p) -= weight[k] * (log_colour[k].cast<double>() - mean_colour).transpose();
        const double scaled = static_cast<double>(weight[k]) / total;
        for (size_t j = begin; j < end; ++j) system(p, photo_of(j)) -= scaled * weight[j];
      }
    }
    const double mean_diagonal = n > 0 ? system.diagonal().mean() : 0.0;
    system.diagonal().array() += 1e-6 * mean_diagonal + 1e-12;
    const Eigen::MatrixX3d solution = system.ldlt().solve(rhs);
    const double change = (solution - log_gain).cwiseAbs().maxCoeff();
    log_gain = solution;
    if (round > 0 && change < options.tolerance) break;
  }

  std::vector<Eigen::Vector3f> gains(num_photos);
  for (size_t p = 0; p < num_photos; ++p) {
    gains[p] = log_gain.row(static_cast<Eigen::Index>(p)).transpose().array().exp().cast<float>();
  }
  // One common scale keeps the mean colour of all the candidates as the photos show it.
  Eigen::Vector3d observed = Eigen::Vector3d::Zero(), levelled = Eigen::Vector3d::Zero();
  for (const FaceCandidate& candidate : table.candidates) {
    const Eigen::Vector3f& gain = gains[static_cast<size_t>(candidate.photo)];
    for (int c = 0; c < 3; ++c) {
      observed[c] += candidate.colour[static_cast<size_t>(c)];
      levelled[c] += gain[c] * candidate.colour[static_cast<size_t>(c)];
    }
  }
  for (int c = 0; c < 3; ++c) {
    if (levelled[c] <= 0.0) continue;
    const float scale = static_cast<float>(observed[c] / levelled[c]);
    for (Eigen::Vector3f& gain : gains) gain[c] *= scale;
  }
  return gains;
}

void ApplyPhotoGains(const std::vector<Eigen::Vector3f>& gains, FaceCandidateTable* table) {
  for (FaceCandidate& candidate : table->candidates) {
    for (size_t c = 0; c < 3; ++c) candidate.colour[c] *= gains[static_cast<size_t>(candidate.photo)][static_cast<int>(c)];
  }
}

}  // namespace reconar
