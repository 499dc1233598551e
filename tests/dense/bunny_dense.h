#pragma once
// The rendered bunny (tests/dense/bunny_scene.h) through the dense stage and Poisson, scored
// against the very mesh that was rendered (bun_zipper.ply) with the Middlebury measures
// (tests/support/mesh_distance.h): accuracy = distance within which 90 % of the points lie,
// completeness = share of the reference vertices with a point within 1.25 mm.
// Needs a current GLES 3 context (the renders).
#include <string>

#include "core/base/status.h"
#include "core/mesh/mesh.h"
#include "core/mesh/poisson/poisson.h"
#include "core/pipeline/dense_stage.h"
#include "tests/dense/bunny_scene.h"
#include "tests/support/mesh_distance.h"

namespace reconar {
namespace testing {

struct BunnyDenseOptions {
  BunnyProjectOptions project;
  DenseMethod method = DenseMethod::kPmvs;
  bool remove_outliers = true;  // DenseStageOptions::remove_outliers
  int level = 0;
  int num_threads = 0;
  PatchMatchOptions patchmatch;  // DenseStageOptions::patchmatch
  PoissonOptions poisson;  // depth 8; trim set by the caller (0 keeps Poisson's closure of the unseen base)
  size_t comparison_samples = 200'000;
};

struct BunnyDenseFigures {
  BunnySceneReport scene;
  DenseStageReport dense;
  MiddleburyScores points;     // the dense points
  MiddleburyScores mesh;       // the Poisson mesh's vertices
  MeshComparison mesh_to_reference;
  size_t mesh_vertices = 0, mesh_triangles = 0;
  double seconds_render = 0.0, seconds_dense = 0.0, seconds_poisson = 0.0, seconds_scoring = 0.0;
};

// Renders the scene into project_dir, runs the dense stage, scores the points, meshes them
// (ReconstructPoissonSurface with options.poisson) and scores the mesh; the mesh is written to
// <project_dir>/mesh/poisson.ply for inspection.
Result<BunnyDenseFigures> RunBunnyDense(const Mesh& bunny, const std::string& project_dir,
                                        const BunnyDenseOptions& options);

}  // namespace testing
}  // namespace reconar
