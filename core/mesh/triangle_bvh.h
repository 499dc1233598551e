#pragma once
// A bounding-volume hierarchy over a mesh's triangles, for ray queries on large meshes (a point
// picked in a photo or on the screen met with the model's surface, a visibility test): built once,
// its nodes in one array, queries allocate nothing.
//
// Binary tree of axis-aligned boxes; a node splits its triangles at the median of their centroids
// along the longest axis of the centroids' box, down to leaves of at most kLeafSize triangles.
// Rays are met with triangles by Moller & Trumbore (1997), both faces counted; the nearest point of
// the surface to a point is found depth first, nearer box first, pruned by the best so far
// (closest point on a triangle after Ericson, Real-Time Collision Detection, 5.1.5).
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/mesh/mesh.h"

namespace reconar {

struct RayHit {
  int triangle = -1;      // index into the mesh's triangles; -1: the ray meets nothing
  double distance = 0.0;  // along the ray, in units of its direction's length
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
};

struct NearestSurfacePoint {
  int triangle = -1;       // index into the mesh's triangles; -1: none within the bound
  double distance = 0.0;   // from the query point
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  bool interior = false;   // the nearest point lies inside the triangle, not on an edge or corner
};

class TriangleBvh {
 public:
  static constexpr int kLeafSize = 4;

  explicit TriangleBvh(const Mesh& mesh);

  // The nearest triangle the ray origin + t direction meets for min_distance < t < max_distance.
  RayHit Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double min_distance = 0.0,
                   double max_distance = 1e300) const;

  // The surface point nearest to `query` no farther than max_distance. `hint`: a triangle likely
  // near the query (the previous query's answer when the queries come in spatial order), tried
  // first so that its distance prunes the search; any value is safe.
  NearestSurfacePoint Nearest(const Eigen::Vector3d& query, double max_distance = 1e300, int hint = -1) const;

  // Nearest for each of `count` queries, the same distances (an exact tie may name another
  // triangle); faster for queries near one another (in spatial order): the tree is searched once
  // for each group of them. `candidates` is scratch.
  void NearestBatch(const Eigen::Vector3d* queries, size_t count, double max_distance, NearestSurfacePoint* nearest,
                    std::vector<int>* candidates) const;

  int num_triangles() const { return static_cast<int>(order_.size()); }  // the usable ones

 private:
  struct Node {
    Eigen::Vector3f box_min, box_max;
    int first = 0;  // leaf: first index into order_; inner: the second child (the first follows the node)
    int count = 0;  // leaf: its triangles; inner: 0
  };
  int Build(int begin, int end, std::vector<Eigen::Vector3f>* centroids);

  struct NearestSearch {
    double best2 = INFINITY;
    // best2 in single precision, a little longer: box distances come out a little long.
    float prune2 = INFINITY;
    NearestSurfacePoint nearest;
    void SetBest(double d2) {
      best2 = d2;
      prune2 = static_cast<float>(d2 * (1.0 + 1e-5) + 1e-12);
    }
  };
  NearestSearch StartSearch(const Eigen::Vector3d& query, double max_distance, int hint) const;
  // Triangle at position k of order_ against the search's best.
  void TryTriangle(int k, const Eigen::Vector3d& query, const Eigen::Vector3f& query_f, NearestSearch* search) const;

  std::vector<int> order_;  // the usable triangles (indices in range, finite corners) in leaf order
  // Per position in order_ (per mesh triangle while building): the corners, and their min and max.
  std::vector<std::array<Eigen::Vector3f, 3>> corners_;
  std::vector<std::array<Eigen::Vector3f, 2>> boxes_;
  std::vector<int> position_of_;  // per mesh triangle: its position in order_, -1 when not usable
  std::vector<Node> nodes_;
};

}  // namespace reconar
