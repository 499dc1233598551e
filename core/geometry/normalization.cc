#include "core/geometry/normalization.h"

#include "core/geometry/null_space.h"

#include <cmath>

namespace reconar {
namespace {

// Builds T for one image; `point` selects x1 or x2 from a correspondence.
template <typename Select>
bool NormalisingTransform(const Correspondence* samples, int count, Select point, Eigen::Matrix3d* T) {
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (int i = 0; i < count; ++i) centroid += point(samples[i]);
  centroid /= count;
  double mean_distance = 0.0;
  for (int i = 0; i < count; ++i) mean_distance += (point(samples[i]) - centroid).norm();
  mean_distance /= count;
  if (!(mean_distance > 0.0) || !std::isfinite(mean_distance)) return false;
  const double scale = std::sqrt(2.0) / mean_distance;
  *T << scale, 0.0, -scale * centroid.x(),  //
      0.0, scale, -scale * centroid.y(),    //
      0.0, 0.0, 1.0;
  return true;
}

}  // namespace

bool HartleyNormalisation(const Correspondence* samples, int count, Eigen::Matrix3d* T1,
                          Eigen::Matrix3d* T2) {
  if (count <= 0) return false;
  return NormalisingTransform(samples, count, [](const Correspondence& c) -> const Eigen::Vector2d& { return c.x1; }, T1) &&
         NormalisingTransform(samples, count, [](const Correspondence& c) -> const Eigen::Vector2d& { return c.x2; }, T2);
}

Eigen::Matrix<double, 9, 9> EpipolarNormalMatrix(const Correspondence* samples, int count, const Eigen::Matrix3d& T1,
                                                 const Eigen::Matrix3d& T2, const double* weights) {
  Eigen::Matrix<double, 9, 9> AtA = Eigen::Matrix<double, 9, 9>::Zero();
  for (int i = 0; i < count; ++i) {
    const Eigen::Matrix<double, 1, 9> row =
        EpipolarRow(ApplySimilarity(T1, samples[i].x1), ApplySimilarity(T2, samples[i].x2));
    AtA.selfadjointView<Eigen::Lower>().rankUpdate(row.transpose(), weights != nullptr ? weights[i] : 1.0);
  }
  AtA.triangularView<Eigen::StrictlyUpper>() = AtA.transpose();
  return AtA;
}

}  // namespace reconar
