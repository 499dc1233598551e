#pragma once
// Designs and as-built points with exact truth for the tests of `reconar compare` (core/compare):
// boxes as triangle meshes and points sampled on them. Test support only.
#include <random>
#include <vector>

#include <Eigen/Core>

#include "core/math/rigid3.h"
#include "core/mesh/mesh.h"

namespace reconar::testing {

// The axis-aligned box [min, max] as 12 triangles, counter-clockwise seen from outside.
Mesh BoxMesh(const Eigen::Vector3d& min, const Eigen::Vector3d& max);

// The mesh with every vertex moved by `motion`.
Mesh MovedMesh(const Mesh& mesh, const Rigid3& motion);

// Points on the triangles of `mesh`, about `spacing` apart, each with its face normal and a normal
// noise of `noise` (1 sigma) along it; triangles facing down (-z, standing on the ground) are left
// out. Appended to *points and *normals.
void SampleMeshFaces(const Mesh& mesh, double spacing, double noise, std::mt19937* random,
                     std::vector<Eigen::Vector3d>* points, std::vector<Eigen::Vector3d>* normals);

}  // namespace reconar::testing
