#pragma once
// Middlebury multi-view stereo data (Seitz et al., CVPR 2006; e.g. templeRing) as a project folder
// that the dense stage reads: features/images.txt pointing at the dataset's PNGs and sparse/ as a
// COLMAP text model with the ground-truth cameras and no points.
//
// *_par.txt: line 1 the number of images N, then per image
//   "imgname.png k11 k12 k13 k21 k22 k23 k31 k32 k33 r11 r12 r13 r21 r22 r23 r31 r32 r33 t1 t2 t3"
// with x ~ K [R | t] X_world (R, t = cam_from_world, metres), images already undistorted.
// Pixel convention: the dataset says only "image origin top-left, x right, y down"; we read K's
// principal point in ours (centre of the top-left pixel at (0, 0)). If Middlebury meant the pixel's
// corner, every projection is off by half a pixel (0.17 mm on the temple), below what the dense
// checks here can see.
#include <string>
#include <vector>

#include "core/base/status.h"

namespace reconar {
namespace testing {

struct MiddleburyImportOptions {
  std::string image_dir;  // where the PNGs are; empty = the directory of the _par.txt file
  int view_stride = 1;    // keep every view_stride-th view (1 = all), for a cheaper run
};

struct MiddleburyImportReport {
  int views = 0;
  int cameras = 0;  // distinct intrinsics
};

// Writes <project_dir>/features/images.txt (the PNGs' absolute paths, sizes read from the files,
// focal source "ground-truth") and <project_dir>/sparse/ (cameras: focal = k11, aspect = k22 / k11,
// principal point (k13, k23), no distortion; one camera per distinct K). NotFound for a missing
// image; errors of ReadMiddleburyParInOrder (tests/support/sfm_evaluation.h).
Result<MiddleburyImportReport> ImportMiddleburyProject(const std::string& par_path, const std::string& project_dir,
                                                      const MiddleburyImportOptions& options = {});

}  // namespace testing
}  // namespace reconar
