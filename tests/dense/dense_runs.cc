#include "tests/dense/dense_runs.h"

#include <chrono>

#include "core/mesh/mesh_io.h"
#include "core/pipeline/project.h"

namespace reconar {
namespace testing {

Box3 TempleRingBoundingBox() {
  Box3 box;
  box.min = Eigen::Vector3d(-0.023121, -0.038009, -0.091940);
  box.max = Eigen::Vector3d(0.078626, 0.121636, -0.017395);
  return box;
}

DenseStageOptions DenseRunOptions(DenseMethod method, int level, int num_threads) {
  DenseStageOptions options;
  options.method = method;
  options.level = level;
  options.num_threads = num_threads;
  options.show_progress = false;
  return options;
}

Result<std::vector<Eigen::Vector3f>> ReadDensePoints(const std::string& project_dir) {
  RECONAR_ASSIGN_OR_RETURN(Mesh points, ReadPly(project_dir + "/dense/points.ply"));
  return std::move(points.positions);
}

Result<TempleRingDenseFigures> RunTempleRingDense(const std::string& par_path, const std::string& project_dir,
                                                  const TempleRingDenseOptions& options) {
  TempleRingDenseFigures figures;
  RECONAR_ASSIGN_OR_RETURN(figures.import, ImportMiddleburyProject(par_path, project_dir, options.import));
  const auto start = std::chrono::steady_clock::now();
  DenseStageOptions dense = DenseRunOptions(options.method, options.level, options.num_threads);
  dense.remove_outliers = options.remove_outliers;
  dense.patchmatch = options.patchmatch;
  RECONAR_ASSIGN_OR_RETURN(figures.dense, RunDenseStage(Project(project_dir), dense));
  figures.seconds_dense = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  RECONAR_ASSIGN_OR_RETURN(const std::vector<Eigen::Vector3f> points, ReadDensePoints(project_dir));
  const Box3 box = TempleRingBoundingBox();
  figures.points = points.size();
  for (const Eigen::Vector3f& p : points) figures.points_in_box += box.Contains(p, options.box_margin_m) ? 1 : 0;
  figures.in_box_fraction = points.empty() ? 0.0 : static_cast<double>(figures.points_in_box) / points.size();
  return figures;
}

}  // namespace testing
}  // namespace reconar
