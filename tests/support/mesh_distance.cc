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
constexpr uint32_t kLeafSize = 4;
// Median splits halve every node, so the depth stays below 33 for 2^32 primitives; nearest-first
// traversal keeps at most one pending sibling per level.
constexpr int kMaxStack = 64;

// A uniform double in [0, 1) from 53 random bits: the same sequence on every platform, unlike
// std::uniform_real_distribution.
double Uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

Eigen::Vector3d ClosestPointOnSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double length_squared = ab.squaredNorm();
  if (length_squared <= 0.0) return a;
  const double t = std::clamp((p - a).dot(ab) / length_squared, 0.0, 1.0);
  return a + t * ab;
}

// Ericson, "Real-Time Collision Detection" (2005), 5.1.5: Voronoi regions of the vertices, then
// the edges, then the face. Triangles of (numerically) zero area take the nearest of their edges.
Eigen::Vector3d ClosestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                       const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a;
  const Eigen::Vector3d ac = c - a;
  if (ab.cross(ac).squaredNorm() <= 1e-24 * ab.squaredNorm() * ac.squaredNorm()) {
    Eigen::Vector3d best = ClosestPointOnSegment(p, a, b);
    for (const Eigen::Vector3d& candidate : {ClosestPointOnSegment(p, a, c), ClosestPointOnSegment(p, b, c)}) {
      if ((candidate - p).squaredNorm() < (best - p).squaredNorm()) best = candidate;
    }
    return best;
  }
  const Eigen::Vector3d ap = p - a;
  const double d1 = ab.dot(ap);
  const double d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp);
  const double d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + (d1 / (d1 - d3)) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp);
  const double d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  }
  const double inverse = 1.0 / (va + vb + vc);
  return a + ab * (vb * inverse) + ac * (vc * inverse);
}

double BoxDistanceSquared(const Eigen::Vector3f& p, const Eigen::Vector3f& box_min, const Eigen::Vector3f& box_max) {
  double sum = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    const double below = static_cast<double>(box_min[axis]) - p[axis];
    const double above = static_cast<double>(p[axis]) - box_max[axis];
    const double gap = std::max({below, above, 0.0});
    sum += gap * gap;
  }
  return sum;
}

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

MeshDistanceField::MeshDistanceField(const Mesh& mesh) {
  std::vector<std::array<Eigen::Vector3f, 3>> corners;
  if (mesh.triangles.empty()) {
    corners.reserve(mesh.positions.size());
    for (const Eigen::Vector3f& p : mesh.positions) corners.push_back({p, p, p});
  } else {
    corners.reserve(mesh.triangles.size());
    for (const std::array<uint32_t, 3>& t : mesh.triangles) {
      corners.push_back({mesh.positions[t[0]], mesh.positions[t[1]], mesh.positions[t[2]]});
    }
  }
  if (corners.empty()) return;
  std::vector<uint32_t> order(corners.size());
  for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  nodes_.reserve(2 * corners.size() / kLeafSize + 1);
  Build(order, 0, static_cast<uint32_t>(order.size()), corners);
  corners_.reserve(corners.size());
  for (const uint32_t id : order) corners_.push_back(corners[id]);
  primitive_ids_ = std::move(order);
}

uint32_t MeshDistanceField::Build(std::vector<uint32_t>& order, uint32_t begin, uint32_t end,
                                  const std::vector<std::array<Eigen::Vector3f, 3>>& corners) {
  const uint32_t index = static_cast<uint32_t>(nodes_.size());
  nodes_.emplace_back();
  Eigen::Vector3f box_min = Eigen::Vector3f::Constant(std::numeric_limits<float>::infinity());
  Eigen::Vector3f box_max = -box_min;
  Eigen::Vector3f centre_min = box_min;
  Eigen::Vector3f centre_max = box_max;
  for (uint32_t i = begin; i < end; ++i) {
    const std::array<Eigen::Vector3f, 3>& c = corners[order[i]];
    for (const Eigen::Vector3f& corner : c) {
      box_min = box_min.cwiseMin(corner);
      box_max = box_max.cwiseMax(corner);
    }
    const Eigen::Vector3f centre = (c[0] + c[1] + c[2]) / 3.0f;
    centre_min = centre_min.cwiseMin(centre);
    centre_max = centre_max.cwiseMax(centre);
  }
  nodes_[index].box_min = box_min;
  nodes_[index].box_max = box_max;
  if (end - begin <= kLeafSize) {
    nodes_[index].first = begin;
    nodes_[index].count = end - begin;
    return index;
  }
  int axis = 0;
  (centre_max - centre_min).maxCoeff(&axis);
  const uint32_t middle = begin + (end - begin) / 2;
  auto centre_on_axis = [&](uint32_t id) { return corners[id][0][axis] + corners[id][1][axis] + corners[id][2][axis]; };
  std::nth_element(order.begin() + begin, order.begin() + middle, order.begin() + end,
                   [&](uint32_t l, uint32_t r) { return centre_on_axis(l) < centre_on_axis(r); });
  Build(order, begin, middle, corners);
  const uint32_t second = Build(order, middle, end, corners);
  nodes_[index].first = second;
  nodes_[index].count = 0;
  return index;
}

ClosestSurfacePoint MeshDistanceField::Closest(const Eigen::Vector3f& point) const {
  ClosestSurfacePoint result;
  result.distance = kInfinity;
  if (nodes_.empty()) return result;
  const Eigen::Vector3d p = point.cast<double>();
  double best_squared = kInfinity;
  uint32_t stack[kMaxStack];
  int size = 0;
  stack[size++] = 0;
  while (size > 0) {
    const Node& node = nodes_[stack[--size]];
    if (BoxDistanceSquared(point, node.box_min, node.box_max) >= best_squared) continue;
    if (node.count > 0) {
      for (uint32_t i = node.first; i < node.first + node.count; ++i) {
        const std::array<Eigen::Vector3f, 3>& c = corners_[i];
        const Eigen::Vector3d closest =
            ClosestPointOnTriangle(p, c[0].cast<double>(), c[1].cast<double>(), c[2].cast<double>());
        const double squared = (closest - p).squaredNorm();
        if (squared < best_squared) {
          best_squared = squared;
          result.point = closest;
          result.primitive = primitive_ids_[i];
        }
      }
      continue;
    }
    const uint32_t first_child = static_cast<uint32_t>(&node - nodes_.data()) + 1;
    const uint32_t second_child = node.first;
    const double first_distance = BoxDistanceSquared(point, nodes_[first_child].box_min, nodes_[first_child].box_max);
    const double second_distance =
        BoxDistanceSquared(point, nodes_[second_child].box_min, nodes_[second_child].box_max);
    // The nearer child goes on top of the stack, so it is searched first.
    const bool first_is_nearer = first_distance <= second_distance;
    const uint32_t nearer = first_is_nearer ? first_child : second_child;
    const uint32_t farther = first_is_nearer ? second_child : first_child;
    if (std::max(first_distance, second_distance) < best_squared) stack[size++] = farther;
    if (std::min(first_distance, second_distance) < best_squared) stack[size++] = nearer;
  }
  result.distance = std::sqrt(best_squared);
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
