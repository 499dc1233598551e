#pragma once
// Normals for an unoriented point cloud (Hoppe, DeRose, Duchamp, McDonald & Stuetzle 1992,
// "Surface Reconstruction from Unorganized Points", SIGGRAPH), as input for
// ReconstructPoissonSurface:
//  - direction: the eigenvector of the smallest eigenvalue of the covariance of each point's
//    `neighbors` nearest points (the point itself included), exact k-NN (point_kdtree.h);
//  - orientation: propagated along a minimum spanning tree of the symmetric k-NN graph with edge
//    cost 1 - |n_i . n_j| (Hoppe's Riemannian graph, without its extra EMST edges), flipping a
//    normal that disagrees with its tree parent. The tree of each connected component is seeded
//    at its point of largest z, whose normal is turned towards +z (the top of a closed object
//    faces up). Works for closed or open surfaces scanned from above; a component whose highest
//    point faces down (e.g. the inside of a bowl seen from below) comes out inverted.
#include "core/base/status.h"
#include "core/mesh/mesh.h"

namespace reconar {

struct NormalEstimationOptions {
  int neighbors = 10;  // k of the k-NN neighbourhoods (PCA and graph); >= 3

  Status Check() const;
};

// Overwrites points->normals with unit normals, one per position (points->triangles are ignored).
// kInvalidArgument for bad options, fewer than 3 points or non-finite positions. A point whose
// neighbourhood is degenerate (all neighbours coincide) gets the normal of its tree parent, or
// +z when it has none.
Status EstimateNormals(Mesh* points, const NormalEstimationOptions& options);

}  // namespace reconar
