#include "tests/support/mesh_distance.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "core/base/thread_pool.h"

namespace reconar::testing {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A uniform double in [0, 1) from 53 random bits: the same sequence on every platform, unlike
// std::uniform_real_distribution.
double Uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

double Mean(const std::vector<double>& values) {
  double sum = 0.0;
  for (const double value : values) sum += value;
  return sum / static_cast<double>(values.size());
}

double RootMeanSquare(const std::vector<double>& values) {
  double sum = 0.0;
  for (const double value : values) sum += value * value;
  return std::sqrt(sum / static_cast<double>(values.size()));
}

// The value at `fraction` of the sorted values (the smallest d with at least that share <= d).
double Quantile(std::vector<double> values, double fraction) {
  const double rank = std::ceil(std::clamp(fraction, 0.0, 1.0) * static_cast<double>(values.size()));
  const size_t index = std::min(values.size() - 1, static_cast<size_t>(std::max(rank, 1.0)) - 1);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(index), values.end());
  return values[index];
}

// Points bucketed in a uniform grid of cells at least `radius` wide, sorted by cell: "is there a
// point within `radius` of q" looks at the 27 cells around q's cell.
class PointGrid {
 public:
  PointGrid(const std::vector<Eigen::Vector3f>& points, double radius) : points_(points), radius_(radius) {
    Eigen::Vector3d box_max = Eigen::Vector3d::Constant(-kInfinity);
    origin_ = -box_max;
    for (const Eigen::Vector3f& point : points) {
      if (!point.allFinite()) continue;
      origin_ = origin_.cwiseMin(point.cast<double>());
      box_max = box_max.cwiseMax(point.cast<double>());
    }
    if (!(box_max.array() >= origin_.array()).all()) return;
    // 21 bits per axis in the cell key; widen the cells when the extent would not fit.
    cell_size_ = std::max({radius, (box_max - origin_).maxCoeff() / double(kCellsPerAxis - 2), 1e-300});
    entries_.reserve(points.size());
    for (uint32_t i = 0; i < points.size(); ++i) {
      if (points[i].allFinite()) entries_.push_back({KeyOf(points[i].cast<double>()), i});
    }
    std::sort(entries_.begin(), entries_.end());
  }

  bool AnyWithin(const Eigen::Vector3f& query) const {
    if (entries_.empty() || !query.allFinite()) return false;
    const Eigen::Vector3d q = query.cast<double>();
    const Eigen::Vector3d cell = ((q - origin_) / cell_size_).array().floor();
    const double radius_squared = radius_ * radius_;
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const Eigen::Vector3d neighbour = cell + Eigen::Vector3d(dx, dy, dz);
          if ((neighbour.array() < 0.0).any() || (neighbour.array() >= double(kCellsPerAxis)).any()) continue;
          const uint64_t key = Pack(neighbour);
          auto it = std::lower_bound(entries_.begin(), entries_.end(), std::pair<uint64_t, uint32_t>(key, 0));
          for (; it != entries_.end() && it->first == key; ++it) {
            if ((points_[it->second].cast<double>() - q).squaredNorm() <= radius_squared) return true;
          }
        }
      }
    }
    return false;
  }

 private:
  static constexpr uint64_t kCellsPerAxis = uint64_t{1} << 21;

  static uint64_t Pack(const Eigen::Vector3d& cell) {
    return (static_cast<uint64_t>(cell.x()) << 42) | (static_cast<uint64_t>(cell.y()) << 21) |
           static_cast<uint64_t>(cell.z());
  }
  uint64_t KeyOf(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d cell = ((p - origin_) / cell_size_).array().floor().min(double(kCellsPerAxis - 1));
    return Pack(cell);
  }

  const std::vector<Eigen::Vector3f>& points_;
  double radius_;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  double cell_size_ = 1.0;
  std::vector<std::pair<uint64_t, uint32_t>> entries_;  // (cell key, point index), sorted
};

template <typename Fn>
void ParallelChunks(size_t count, int num_threads, const Fn& fn) {
  constexpr size_t kChunk = 4096;
  ThreadPool pool(ThreadPool::ResolveThreadCount(num_threads));
  const size_t chunks = (count + kChunk - 1) / kChunk;
  pool.ParallelFor(0, chunks, [&](size_t chunk, int) {
    const size_t end = std::min(count, (chunk + 1) * kChunk);
    for (size_t i = chunk * kChunk; i < end; ++i) fn(i);
  });
}

}  // namespace

std::vector<Eigen::Vector3f> SampleSurface(const Mesh& mesh, size_t count, uint64_t seed) {
  std::vector<double> cumulative_area;
  cumulative_area.reserve(mesh.triangles.size());
  double total = 0.0;
  for (const std::array<uint32_t, 3>& triangle : mesh.triangles) {
    const Eigen::Vector3d a = mesh.positions[triangle[0]].cast<double>();
    const Eigen::Vector3d b = mesh.positions[triangle[1]].cast<double>();
    const Eigen::Vector3d c = mesh.positions[triangle[2]].cast<double>();
    total += 0.5 * (b - a).cross(c - a).norm();
    cumulative_area.push_back(total);
  }
  std::vector<Eigen::Vector3f> samples;
  if (!(total > 0.0) || !std::isfinite(total)) return samples;
  samples.reserve(count);
  std::mt19937_64 rng(seed);
  for (size_t i = 0; i < count; ++i) {
    const double pick = Uniform01(rng) * total;
    const size_t t = std::min<size_t>(
        mesh.triangles.size() - 1,
        static_cast<size_t>(std::upper_bound(cumulative_area.begin(), cumulative_area.end(), pick) -
                            cumulative_area.begin()));
    const std::array<uint32_t, 3>& triangle = mesh.triangles[t];
    // Osada et al., "Shape Distributions" (2002), 4.2: uniform over the triangle.
    const double root = std::sqrt(Uniform01(rng));
    const double v = Uniform01(rng);
    const Eigen::Vector3d a = mesh.positions[triangle[0]].cast<double>();
    const Eigen::Vector3d b = mesh.positions[triangle[1]].cast<double>();
    const Eigen::Vector3d c = mesh.positions[triangle[2]].cast<double>();
    samples.push_back(((1.0 - root) * a + root * (1.0 - v) * b + root * v * c).cast<float>());
  }
  return samples;
}

namespace {

// A point cloud as triangles (p, p, p): the nearest triangle is then the nearest point.
Mesh AsTriangles(const Mesh& mesh) {
  if (!mesh.triangles.empty()) return mesh;
  Mesh points;
  points.positions = mesh.positions;
  for (uint32_t i = 0; i < mesh.positions.size(); ++i) points.triangles.push_back({i, i, i});
  return points;
}

}  // namespace

MeshDistanceField::MeshDistanceField(const Mesh& mesh) : bvh_(AsTriangles(mesh)) {}

ClosestSurfacePoint MeshDistanceField::Closest(const Eigen::Vector3f& point) const {
  ClosestSurfacePoint result;
  result.distance = kInfinity;
  const NearestSurfacePoint nearest = bvh_.Nearest(point.cast<double>());
  if (nearest.triangle < 0) return result;
  result.distance = nearest.distance;
  result.point = nearest.point;
  result.primitive = static_cast<uint32_t>(nearest.triangle);
  return result;
}

double MeshDistanceField::Distance(const Eigen::Vector3f& point) const { return Closest(point).distance; }

std::vector<double> DistancesTo(const MeshDistanceField& field, const std::vector<Eigen::Vector3f>& points,
                                int num_threads) {
  std::vector<double> distances(points.size());
  ParallelChunks(points.size(), num_threads, [&](size_t i) { distances[i] = field.Distance(points[i]); });
  return distances;
}

MeshComparison CompareMeshes(const Mesh& mesh, const Mesh& reference, const MeshComparisonOptions& options) {
  MeshComparison comparison;
  const std::vector<Eigen::Vector3f> mesh_samples = SampleSurface(mesh, options.samples, options.seed);
  const std::vector<Eigen::Vector3f> reference_samples = SampleSurface(reference, options.samples, options.seed + 1);
  if (mesh_samples.empty() || reference_samples.empty()) {
    comparison.mean_mesh_to_reference = comparison.mean_reference_to_mesh = kNaN;
    comparison.median_mesh_to_reference = comparison.median_reference_to_mesh = kNaN;
    comparison.rms_mesh_to_reference = comparison.rms_reference_to_mesh = kNaN;
    comparison.p90_mesh_to_reference = comparison.p90_reference_to_mesh = kNaN;
    comparison.max_mesh_to_reference = comparison.max_reference_to_mesh = kNaN;
    comparison.samples = 0;
    return comparison;
  }
  const std::vector<double> to_reference =
      DistancesTo(MeshDistanceField(reference), mesh_samples, options.num_threads);
  const std::vector<double> to_mesh = DistancesTo(MeshDistanceField(mesh), reference_samples, options.num_threads);
  comparison.mean_mesh_to_reference = Mean(to_reference);
  comparison.mean_reference_to_mesh = Mean(to_mesh);
  comparison.median_mesh_to_reference = Quantile(to_reference, 0.5);
  comparison.median_reference_to_mesh = Quantile(to_mesh, 0.5);
  comparison.rms_mesh_to_reference = RootMeanSquare(to_reference);
  comparison.rms_reference_to_mesh = RootMeanSquare(to_mesh);
  comparison.p90_mesh_to_reference = Quantile(to_reference, 0.9);
  comparison.p90_reference_to_mesh = Quantile(to_mesh, 0.9);
  comparison.max_mesh_to_reference = *std::max_element(to_reference.begin(), to_reference.end());
  comparison.max_reference_to_mesh = *std::max_element(to_mesh.begin(), to_mesh.end());
  comparison.samples = options.samples;
  return comparison;
}

MiddleburyScores ScoreMiddlebury(const std::vector<Eigen::Vector3f>& points, const Mesh& reference,
                                 double accuracy_fraction, double completeness_threshold) {
  MiddleburyScores scores;
  scores.points = points.size();
  scores.reference_samples = reference.positions.size();
  if (reference.positions.empty()) {
    scores.accuracy = scores.completeness = kNaN;
    return scores;
  }
  if (points.empty()) {
    scores.accuracy = kInfinity;
    scores.completeness = 0.0;
    return scores;
  }
  scores.accuracy = Quantile(DistancesTo(MeshDistanceField(reference), points), accuracy_fraction);
  const PointGrid grid(points, completeness_threshold);
  std::vector<uint8_t> covered(reference.positions.size(), 0);
  ParallelChunks(reference.positions.size(), 0, [&](size_t i) { covered[i] = grid.AnyWithin(reference.positions[i]); });
  size_t count = 0;
  for (const uint8_t c : covered) count += c;
  scores.completeness = static_cast<double>(count) / static_cast<double>(covered.size());
  return scores;
}

}  // namespace reconar::testing
