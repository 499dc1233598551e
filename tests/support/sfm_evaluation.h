#pragma once
// Accuracy of estimated camera poses against ground truth, for the SfM tests and benchmarks:
// a 7-DoF similarity aligns the estimated camera centres to the true ones, then each camera gets
// a centre error (ground-truth units) and a rotation error (degrees). Test support only.
#include <Eigen/Core>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/math/sim3.h"
#include "tests/support/ground_truth.h"

namespace reconar::testing {

// to = scale * rotation * from + translation; AlignSimilarity (Umeyama) is core/math/sim3.h's.
using Similarity3 = Sim3;
using reconar::AlignSimilarity;

// The median of `values` (the mean of the middle two for an even count); 0 for none.
double Median(std::vector<double> values);
// The value of rank floor(q * size) of the sorted values (q = 1: the largest); NaN for none.
double Quantile(std::vector<double> values, double q);

// The angle of the rotation a * b^T, in degrees.
double RotationAngleDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b);

// A camera's orientation and position: X_cam = cam_from_world_rotation * (X_world - centre).
struct CameraPose {
  Eigen::Matrix3d cam_from_world_rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
};

CameraPose PoseOf(const GroundTruthCamera& camera);

struct CameraPoseErrors {
  Similarity3 gt_from_estimate;
  std::vector<double> centre_errors;        // per camera, ground-truth units
  std::vector<double> rotation_errors_deg;  // per camera
  double centre_mean = 0.0;
  double centre_median = 0.0;
  double centre_max = 0.0;
  double rotation_mean_deg = 0.0;
  double rotation_median_deg = 0.0;
  double rotation_max_deg = 0.0;
  // Alignment-free: mean over camera pairs of the angle between estimated and true i_from_j.
  double relative_rotation_mean_deg = 0.0;
};

// Aligns estimated[i] to ground_truth[i] by their centres, then measures each camera.
Result<CameraPoseErrors> CameraCenterErrors(const std::vector<CameraPose>& estimated,
                                            const std::vector<CameraPose>& ground_truth);

// Ground truth by image name ("0000.jpg", "templeR0001.png").
using GroundTruthByName = std::map<std::string, GroundTruthCamera>;

// The registered cameras of the COLMAP text model in `model_dir` against the truth (7-DoF
// aligned), each image's truth found under truth_name(its name). NotFound naming an image without
// truth; the reader's error for an unreadable model; CameraCenterErrors' for fewer than 3 cameras.
struct ModelScore {
  int registered = 0;
  CameraPoseErrors errors;
};
Result<ModelScore> ScoreModelAgainstTruth(const std::string& model_dir, const GroundTruthByName& truth,
                                          const std::function<std::string(const std::string&)>& truth_name);

// The true cameras as a COLMAP text model without points in `dir` (created; WriteColmapTextModel),
// one camera per distinct K and size: so that other tools, and evaluate_sfm --colmap-truth, score
// models of rendered captures. InvalidArgument for a skewed K.
Status WriteGroundTruthModel(const GroundTruthByName& truth, const std::string& dir);

// The registered images of the COLMAP text model in `dir` as ground truth, keyed by file name (the
// last path component of their names). The reader's error for an unreadable model; Unsupported
// naming the camera for one with distortion (GroundTruthCamera is a pinhole).
Result<GroundTruthByName> ReadGroundTruthModel(const std::string& dir);

// Every NAME.camera in `dir` (Strecha gt_cameras/), keyed by NAME.
Result<GroundTruthByName> ReadStrechaGroundTruth(const std::string& dir);

// Middlebury "*_par.txt": a count, then "name k11..k33 r11..r33 t1 t2 t3" per image, with
// x ~ K [R | t] X. The file has no image size: width and height stay 0.
// In file order. CorruptData "path:line: reason" for a malformed line, a count that disagrees with
// the lines, a K that is not upper triangular with positive focal lengths and k33 = 1, or an R
// that is not a rotation (|R^T R - I| > 1e-5, det < 0; within that, R is replaced by the nearest
// rotation); Unsupported for a skewed K (k12 != 0).
struct NamedGroundTruthCamera {
  std::string name;  // "templeR0001.png"
  GroundTruthCamera camera;
};
Result<std::vector<NamedGroundTruthCamera>> ReadMiddleburyParInOrder(const std::string& path);
// The same, keyed by name.
Result<GroundTruthByName> ReadMiddleburyPar(const std::string& path);

}  // namespace reconar::testing
