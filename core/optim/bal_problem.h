#pragma once
// "Bundle Adjustment in the Large" problems (Agarwal, Snavely, Seitz & Szeliski, ECCV 2010):
// the text format and the in-memory problem the bundle adjuster works on.
#include <cmath>
#include <string>
#include <vector>

#include "core/base/status.h"

namespace reconar {

struct BalObservation {
  int camera = 0;
  int point = 0;
  double x = 0.0;  // pixels; BAL: origin at the principal point, y up. Radial: image pixels.
  double y = 0.0;
  double weight = 1.0;  // the residual is multiplied by this (1 / its standard deviation)
};

// A point held to a place in a frame: the residual weight * ((R(w) X + t) / s - local), three
// components, outside the robust loss, where the frame is a camera block whose pose (w, t) is
// frame_from_world and whose focal slot (index 6) is the frame's scale s; the residual does not
// change when the whole problem is scaled. A printed tag is such a frame: its four corners
// anchored at (+-1/2, +-1/2, 0), s its edge (free, and shared by every tag through an intrinsics
// group), keep the corners a square while its pose and edge move with the cameras; weight = 1 / the
// corners' standard deviation relative to the edge. The frame block projects nothing: its other
// intrinsic slots have no effect.
struct PointAnchor {
  int frame = 0;
  int point = 0;
  double local[3] = {0.0, 0.0, 0.0};
  double weight = 1.0;
};

// Cameras of CameraSize doubles each, points of 3, and the observations linking them. The
// camera model that gives the doubles their meaning is chosen by the bundle adjuster's overload:
// BalProblem (bal_camera_model.h) or RadialProblem (radial_camera_model.h).
template <int CameraSize>
struct BundleProblem {
  static constexpr int kCameraSize = CameraSize;
  static constexpr int kPointSize = 3;

  std::vector<double> cameras;  // kCameraSize doubles per camera
  std::vector<double> points;   // kPointSize doubles per point
  std::vector<BalObservation> observations;
  std::vector<PointAnchor> point_anchors;  // optional

  int num_cameras() const { return static_cast<int>(cameras.size()) / kCameraSize; }
  int num_points() const { return static_cast<int>(points.size()) / kPointSize; }
  double* camera(int i) { return cameras.data() + static_cast<size_t>(i) * kCameraSize; }
  const double* camera(int i) const {
    return cameras.data() + static_cast<size_t>(i) * kCameraSize;
  }
  double* point(int j) { return points.data() + static_cast<size_t>(j) * kPointSize; }
  const double* point(int j) const { return points.data() + static_cast<size_t>(j) * kPointSize; }

  // InvalidArgument if the arrays are not whole blocks or an observation indexes out of range.
  Status Check() const {
    if (cameras.size() % kCameraSize != 0) {
      return InvalidArgument("BundleProblem: cameras not " + std::to_string(kCameraSize) + "-blocks");
    }
    if (points.size() % kPointSize != 0) return InvalidArgument("BundleProblem: points not 3-blocks");
    for (size_t k = 0; k < observations.size(); ++k) {
      const BalObservation& o = observations[k];
      if (o.camera < 0 || o.camera >= num_cameras() || o.point < 0 || o.point >= num_points()) {
        return InvalidArgument("BundleProblem: observation " + std::to_string(k) +
                               " indexes a missing camera or point");
      }
    }
    for (size_t k = 0; k < point_anchors.size(); ++k) {
      const PointAnchor& anchor = point_anchors[k];
      if (anchor.frame < 0 || anchor.frame >= num_cameras() || anchor.point < 0 || anchor.point >= num_points()) {
        return InvalidArgument("BundleProblem: point anchor " + std::to_string(k) + " indexes a missing frame or point");
      }
      if (!(anchor.weight >= 0.0) || !std::isfinite(anchor.weight) || !std::isfinite(anchor.local[0]) ||
          !std::isfinite(anchor.local[1]) || !std::isfinite(anchor.local[2])) {
        return InvalidArgument("BundleProblem: point anchor " + std::to_string(k) + " is not finite");
      }
    }
    return Status::Ok();
  }
};

// BAL / Bundler cameras: angle-axis r (3), t (3), f, k1, k2.
using BalProblem = BundleProblem<9>;
// SfM cameras (radial_camera_model.h): angle-axis r (3), t (3), f, k1, k2, cx, cy, aspect.
using RadialProblem = BundleProblem<12>;

// Parses BAL text: "<num_cameras> <num_points> <num_observations>", then num_observations lines
// "<camera> <point> <x> <y>", then 9 values per camera and 3 per point (whitespace separated).
// Errors are CorruptData "path:line: reason" (truncated file, bad counts, non-numeric token,
// index out of range) or NotFound/IoError when the file cannot be read.
Result<BalProblem> ReadBalProblem(const std::string& path);

// Same parser on text already in memory; `name` prefixes the error messages.
Result<BalProblem> ParseBalProblem(const std::string& text, const std::string& name);

}  // namespace reconar
