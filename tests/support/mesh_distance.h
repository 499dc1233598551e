#pragma once
// Geometric accuracy of a reconstructed surface against a reference surface: area-uniform surface
// samples, exact point-to-triangle-mesh distances (bounding-volume hierarchy), a two-way mesh
// comparison, and the Middlebury multi-view stereo scores (Seitz, Curless, Diebel, Scharstein,
// Szeliski, "A Comparison and Evaluation of Multi-View Stereo Reconstruction Algorithms",
// CVPR 2006). Distances are in the meshes' units (metres for our data). Test support and
// benchmarks only.
#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/mesh/triangle_bvh.h"

namespace reconar::testing {

// `count` points distributed uniformly by area over the mesh's triangles (a triangle is drawn
// with probability proportional to its area, then a uniform point inside it). Deterministic for
// a seed, on every platform. Empty when the mesh has no triangle of non-zero area.
std::vector<Eigen::Vector3f> SampleSurface(const Mesh& mesh, size_t count, uint64_t seed = 1);

struct ClosestSurfacePoint {
  double distance = 0.0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // the closest point on the surface
  uint32_t primitive = 0;  // index into mesh.triangles (or mesh.positions for a point cloud)
};

// Exact Euclidean distance from a point to the nearest triangle of a mesh (to the nearest vertex
// when the mesh is a point cloud): core/mesh/triangle_bvh.h's nearest-point query, a point cloud
// taken as triangles (p, p, p). Queries are const and thread-safe. The field copies what it
// needs: the mesh may be destroyed after construction.
class MeshDistanceField {
 public:
  explicit MeshDistanceField(const Mesh& mesh);

  // +infinity when the mesh has no triangle (no vertex for a point cloud).
  double Distance(const Eigen::Vector3f& point) const;
  // distance +infinity (and primitive 0) when the mesh is empty.
  ClosestSurfacePoint Closest(const Eigen::Vector3f& point) const;

  size_t num_primitives() const { return static_cast<size_t>(bvh_.num_triangles()); }

 private:
  TriangleBvh bvh_;
};

// Distances between the surfaces of two triangle meshes, both ways: `samples` area-uniform points
// on `mesh` are measured to `reference` (the accuracy side) and `samples` on `reference` to
// `mesh` (the completeness side).
struct MeshComparison {
  double mean_mesh_to_reference = 0.0;
  double mean_reference_to_mesh = 0.0;
  double median_mesh_to_reference = 0.0;
  double median_reference_to_mesh = 0.0;
  double rms_mesh_to_reference = 0.0;
  double rms_reference_to_mesh = 0.0;
  double p90_mesh_to_reference = 0.0;
  double p90_reference_to_mesh = 0.0;
  double max_mesh_to_reference = 0.0;
  double max_reference_to_mesh = 0.0;
  size_t samples = 0;  // per direction; 0 (and every figure NaN) when a mesh has no surface
};

struct MeshComparisonOptions {
  size_t samples = 1'000'000;
  uint64_t seed = 1;  // `mesh` is sampled with `seed`, `reference` with `seed + 1`
  int num_threads = 0;  // 0: one per hardware core
};

MeshComparison CompareMeshes(const Mesh& mesh, const Mesh& reference, const MeshComparisonOptions& options = {});

// Middlebury scores of a reconstruction given as points (dense MVS output, or a mesh's vertices
// or surface samples) against a reference surface:
// - accuracy: the distance d such that `accuracy_fraction` of `points` lie within d of the
//   reference surface (Seitz et al. use 90 %);
// - completeness: the share of the reference's vertices (its samples, as in Seitz et al.) that
//   have one of `points` within `completeness_threshold` (Seitz et al. use 1.25 mm).
// Reference vertices used by no triangle count too. With no points, accuracy is +infinity and
// completeness 0; with an empty reference both are NaN.
struct MiddleburyScores {
  double accuracy = 0.0;
  double completeness = 0.0;  // in [0, 1]
  size_t points = 0;
  size_t reference_samples = 0;
};

MiddleburyScores ScoreMiddlebury(const std::vector<Eigen::Vector3f>& points, const Mesh& reference,
                                 double accuracy_fraction = 0.9, double completeness_threshold = 0.00125);

// Per-point distances to a field, computed on up to `num_threads` threads (0: one per core).
std::vector<double> DistancesTo(const MeshDistanceField& field, const std::vector<Eigen::Vector3f>& points,
                                int num_threads = 0);

}  // namespace reconar::testing
