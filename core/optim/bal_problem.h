#pragma once
// "Bundle Adjustment in the Large" problems (Agarwal, Snavely, Seitz & Szeliski, ECCV 2010):
// the text format and the in-memory problem the bundle adjuster works on.
#include <string>
#include <vector>

#include "core/base/status.h"

namespace reconar {

struct BalObservation {
  int camera = 0;
  int point = 0;
  double x = 0.0;  // pixels, origin at the principal point, y up (BAL convention)
  double y = 0.0;
};

struct BalProblem {
  static constexpr int kCameraSize = 9;  // angle-axis r (3), t (3), f, k1, k2
  static constexpr int kPointSize = 3;

  std::vector<double> cameras;  // kCameraSize doubles per camera
  std::vector<double> points;   // kPointSize doubles per point
  std::vector<BalObservation> observations;

  int num_cameras() const { return static_cast<int>(cameras.size()) / kCameraSize; }
  int num_points() const { return static_cast<int>(points.size()) / kPointSize; }
  double* camera(int i) { return cameras.data() + static_cast<size_t>(i) * kCameraSize; }
  const double* camera(int i) const {
    return cameras.data() + static_cast<size_t>(i) * kCameraSize;
  }
  double* point(int j) { return points.data() + static_cast<size_t>(j) * kPointSize; }
  const double* point(int j) const { return points.data() + static_cast<size_t>(j) * kPointSize; }

  // InvalidArgument if the arrays are not whole blocks or an observation indexes out of range.
  Status Check() const;
};

// Parses BAL text: "<num_cameras> <num_points> <num_observations>", then num_observations lines
// "<camera> <point> <x> <y>", then 9 values per camera and 3 per point (whitespace separated).
// Errors are CorruptData "path:line: reason" (truncated file, bad counts, non-numeric token,
// index out of range) or NotFound/IoError when the file cannot be read.
Result<BalProblem> ReadBalProblem(const std::string& path);

// Same parser on text already in memory; `name` prefixes the error messages.
Result<BalProblem> ParseBalProblem(const std::string& text, const std::string& name);

}  // namespace reconar
