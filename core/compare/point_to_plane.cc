#include "core/compare/point_to_plane.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

namespace reconar {
namespace {

// The linearised step's sums over a run of points, added in a fixed order so that the result
// does not depend on how many threads summed them.
struct StepSums {
  Eigen::Matrix<double, 6, 6> normal_matrix = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> right = Eigen::Matrix<double, 6, 1>::Zero();
  std::vector<double> residuals;  // magnitudes
  // Scratch of the nearest-point queries.
  std::vector<Eigen::Vector3d> moved;
  std::vector<NearestSurfacePoint> nearest;
  std::vector<int> candidates;
};

constexpr size_t kChunkPoints = 4096;

}  // namespace

PointToPlaneReport AlignPointsToSurface(const std::vector<Eigen::Vector3d>& points, const TriangleBvh& surface,
                                        const std::vector<Eigen::Vector3d>& face_normals,
                                        const PointToPlaneOptions& options, const Rigid3& start, ThreadPool* pool) {
  PointToPlaneReport report;
  report.surface_from_points = start;
  double bound = options.max_distance;
  std::vector<double> residuals;
  residuals.reserve(points.size());
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) centre += p / static_cast<double>(std::max<size_t>(1, points.size()));
  double extent = 0.0;
  for (const Eigen::Vector3d& p : points) extent = std::max(extent, (p - centre).norm());
  std::vector<StepSums> chunk_sums((points.size() + kChunkPoints - 1) / kChunkPoints);
  for (StepSums& sums : chunk_sums) sums.residuals.reserve(kChunkPoints);
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    // Normal equations of the linearised step about the moved points' centre: unknowns (w, t),
    // moved point q + w x (q - c) + t, residual n . (q' - s).
    const Eigen::Vector3d moved_centre = report.surface_from_points * centre;
    const auto sum_chunk = [&](size_t chunk, int) {
      StepSums& sums = chunk_sums[chunk];
      sums.normal_matrix.setZero();
      sums.right.setZero();
      sums.residuals.clear();
      const size_t begin = chunk * kChunkPoints, end = std::min(points.size(), (chunk + 1) * kChunkPoints);
      sums.moved.clear();
      for (size_t i = begin; i < end; ++i) sums.moved.push_back(report.surface_from_points * points[i]);
      sums.nearest.resize(sums.moved.size());
      surface.NearestBatch(sums.moved.data(), sums.moved.size(), bound, sums.nearest.data(), &sums.candidates);
      for (size_t i = begin; i < end; ++i) {
        const Eigen::Vector3d& q = sums.moved[i - begin];
        const NearestSurfacePoint& nearest = sums.nearest[i - begin];
        if (nearest.triangle < 0) continue;
        const Eigen::Vector3d& n = face_normals[static_cast<size_t>(nearest.triangle)];
        const double r = n.dot(q - nearest.point);
        sums.residuals.push_back(std::abs(r));
        Eigen::Matrix<double, 6, 1> row;
        row.head<3>() = (q - moved_centre).cross(n);
        row.tail<3>() = n;
        sums.normal_matrix.selfadjointView<Eigen::Lower>().rankUpdate(row);
        sums.right -= row * r;
      }
    };
    if (pool != nullptr && chunk_sums.size() > 1) {
      pool->ParallelFor(0, chunk_sums.size(), sum_chunk);
    } else {
      for (size_t chunk = 0; chunk < chunk_sums.size(); ++chunk) sum_chunk(chunk, 0);
    }
    Eigen::Matrix<double, 6, 6> normal_matrix = Eigen::Matrix<double, 6, 6>::Zero();  // lower triangle
    Eigen::Matrix<double, 6, 1> right = Eigen::Matrix<double, 6, 1>::Zero();
    residuals.clear();
    for (const StepSums& sums : chunk_sums) {
      normal_matrix += sums.normal_matrix;
      right += sums.right;
      residuals.insert(residuals.end(), sums.residuals.begin(), sums.residuals.end());
    }
    report.inliers = static_cast<int>(residuals.size());
    if (residuals.size() < 6) break;
    double squares = 0.0;
    for (double r : residuals) squares += r * r;
    report.rms = std::sqrt(squares / static_cast<double>(residuals.size()));
    report.final_distance = bound;
    // The solver reads the lower triangle, the one the rank updates filled.
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(normal_matrix);
    const double largest = eigen.eigenvalues().maxCoeff();
    Eigen::Matrix<double, 6, 1> step = Eigen::Matrix<double, 6, 1>::Zero();
    report.free_directions = 0;
    for (int k = 0; k < 6; ++k) {
      const double value = eigen.eigenvalues()[k];
      if (!(value > 1e-6 * largest)) {
        ++report.free_directions;
        continue;
      }
      const Eigen::Matrix<double, 6, 1> v = eigen.eigenvectors().col(k);
      step += v * (v.dot(right) / value);
    }
    const Eigen::Vector3d w = step.head<3>(), t = step.tail<3>();
    Rigid3 delta;
    if (w.norm() > 0.0) delta.rotation = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
    delta.translation = moved_centre + t - delta.rotation * moved_centre;
    report.surface_from_points = delta * report.surface_from_points;
    report.iterations = iteration + 1;
    // The next bound: 3 x the residuals' robust spread (1.4826 x their median), within the limits.
    std::nth_element(residuals.begin(), residuals.begin() + static_cast<long>(residuals.size() / 2), residuals.end());
    bound = std::clamp(3.0 * 1.4826 * residuals[residuals.size() / 2], options.min_distance, options.max_distance);
    if (t.norm() + w.norm() * extent < options.stop_motion) break;
  }
  return report;
}

}  // namespace reconar
