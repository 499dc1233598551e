#include "tests/dense/bunny_dense.h"

#include <chrono>

#include "core/base/atomic_file.h"
#include "core/mesh/mesh_io.h"
#include "core/pipeline/project.h"
#include "tests/dense/dense_runs.h"

namespace reconar {
namespace testing {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

Result<BunnyDenseFigures> RunBunnyDense(const Mesh& bunny, const std::string& project_dir,
                                        const BunnyDenseOptions& options) {
  BunnyDenseFigures figures;
  auto start = Clock::now();
  RECONAR_ASSIGN_OR_RETURN(figures.scene, WriteBunnyProject(bunny, options.project, project_dir));
  figures.seconds_render = SecondsSince(start);

  start = Clock::now();
  DenseStageOptions dense = DenseRunOptions(options.method, options.level, options.num_threads);
  dense.remove_outliers = options.remove_outliers;
  dense.patchmatch = options.patchmatch;
  RECONAR_ASSIGN_OR_RETURN(figures.dense, RunDenseStage(Project(project_dir), dense));
  figures.seconds_dense = SecondsSince(start);

  // Positions and normals as the dense stage wrote them: Poisson needs the normals.
  RECONAR_ASSIGN_OR_RETURN(Mesh points, ReadPly(project_dir + "/dense/points.ply"));
  start = Clock::now();
  figures.points = ScoreMiddlebury(points.positions, bunny);
  figures.seconds_scoring = SecondsSince(start);

  start = Clock::now();
  points.colors.clear();
  RECONAR_ASSIGN_OR_RETURN(const Mesh mesh, ReconstructPoissonSurface(points, options.poisson));
  figures.seconds_poisson = SecondsSince(start);
  figures.mesh_vertices = mesh.positions.size();
  figures.mesh_triangles = mesh.triangles.size();
  RECONAR_RETURN_IF_ERROR(CreateDirectories(project_dir + "/mesh"));
  RECONAR_RETURN_IF_ERROR(WritePly(project_dir + "/mesh/poisson.ply", mesh));

  start = Clock::now();
  figures.mesh = ScoreMiddlebury(mesh.positions, bunny);
  MeshComparisonOptions comparison;
  comparison.samples = options.comparison_samples;
  comparison.num_threads = options.num_threads;
  figures.mesh_to_reference = CompareMeshes(mesh, bunny, comparison);
  figures.seconds_scoring += SecondsSince(start);
  return figures;
}

}  // namespace testing
}  // namespace reconar
