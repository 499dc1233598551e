#pragma once
// The dense-accuracy runs shared by the e2e tests and bench/dense: a project folder with known
// cameras -> RunDenseStage -> figures against what the dataset lets us check.
//  - templeRing (Middlebury, ground-truth cameras): no reference mesh is public, so the checks are
//    the share of points inside the object's published tight bounding box and the point count.
//  - the rendered bunny (tests/dense/bunny_dense.h, needs GLES): Middlebury accuracy and
//    completeness against bun_zipper.ply, for the points and for their Poisson mesh.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/pipeline/dense_stage.h"
#include "tests/dense/middlebury_import.h"

namespace reconar {
namespace testing {

// Axis-aligned box, world units.
struct Box3 {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();

  bool Contains(const Eigen::Vector3f& p, double margin) const {
    const Eigen::Vector3d q = p.cast<double>();
    return (q.array() >= min.array() - margin).all() && (q.array() <= max.array() + margin).all();
  }
};

// templeRing's tight bounding box as its README.txt gives it (metres, world frame of templeR_par.txt).
Box3 TempleRingBoundingBox();

// DenseStageOptions for these runs: no progress bar, the given method, level and threads, the rest
// default.
DenseStageOptions DenseRunOptions(DenseMethod method, int level, int num_threads);

// The positions of <project>/dense/points.ply.
Result<std::vector<Eigen::Vector3f>> ReadDensePoints(const std::string& project_dir);

struct TempleRingDenseOptions {
  MiddleburyImportOptions import;  // view_stride 1 = all 47 views
  DenseMethod method = DenseMethod::kPmvs;
  bool remove_outliers = true;     // DenseStageOptions::remove_outliers
  int level = 1;                   // 0 full 640 x 480, 1 half
  int num_threads = 0;
  PatchMatchOptions patchmatch;  // DenseStageOptions::patchmatch
  // Margin around the tight box: ~6 pixel footprints at level 0 (0.5 m / 1520 px = 0.33 mm), so
  // that the points' own error (a few footprints for PMVS on templeRing) keeps them inside.
  double box_margin_m = 0.002;
};

struct TempleRingDenseFigures {
  MiddleburyImportReport import;
  DenseStageReport dense;
  size_t points = 0;
  size_t points_in_box = 0;
  double in_box_fraction = 0.0;
  double seconds_dense = 0.0;  // wall time of RunDenseStage
};

// Imports <par_path> into project_dir (created) and runs the dense stage on it.
Result<TempleRingDenseFigures> RunTempleRingDense(const std::string& par_path, const std::string& project_dir,
                                                  const TempleRingDenseOptions& options);

}  // namespace testing
}  // namespace reconar
