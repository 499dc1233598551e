#include "tracker/calibration.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>

#include "core/geometry/homography_four_point.h"
#include "core/math/lm_loop.h"
#include "tracker/tag_pose.h"

namespace reconar {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Matrix26d = Eigen::Matrix<double, 2, 6>;

enum Intrinsic { kFx = 0, kFy, kCx, kCy, kK1, kK2 };
constexpr int kNumIntrinsics = 6;

// A planar tag instance or a board view: object points in the target frame and their pixels
// (already in the (0, 0)-centre convention).
struct Target {
  int image = 0;
  int tag_id = -1;
  std::vector<Eigen::Vector3d> object;
  std::vector<Eigen::Vector2d> pixels;
  Rigid3 cam_from_target;
};

// ---------------------------------------------------------------------------------------------
// Input validation and target assembly.

Status CheckObservations(const CalibrationObservations& observations) {
  bool tag_outside_layout = false;
  for (const CalibrationImage& image : observations.images) {
    for (const TagCorners& tag : image.tags) tag_outside_layout |= observations.layout.Find(tag.tag_id) == nullptr;
  }
  if (tag_outside_layout && (!(observations.tag_size > 0.0) || !std::isfinite(observations.tag_size))) {
    return InvalidArgument("calibration: tag_size must be a positive number of metres");
  }
  const CalibrationImage* first = nullptr;
  for (const CalibrationImage& image : observations.images) {
    if (image.width <= 0 || image.height <= 0) {
      return InvalidArgument("calibration: image '" + image.name + "' has no size");
    }
    if (first != nullptr && (image.width != first->width || image.height != first->height)) {
      return InvalidArgument("calibration: image '" + image.name + "' is " + std::to_string(image.width) + "x" +
                             std::to_string(image.height) + " but '" + first->name + "' is " +
                             std::to_string(first->width) + "x" + std::to_string(first->height) +
                             " (one camera, one size)");
    }
    if (first == nullptr) first = &image;
    for (const TagCorners& tag : image.tags) {
      for (const Eigen::Vector2d& corner : tag.corners) {
        if (!corner.allFinite()) {
          return InvalidArgument("calibration: image '" + image.name + "', tag " + std::to_string(tag.tag_id) +
                                 ": non-finite corner");
        }
      }
    }
  }
  return Status::Ok();
}

// The size of a tag: the layout's for its tags, tag_size otherwise.
double TagSize(const CalibrationObservations& observations, int tag_id) {
  const LayoutTag* in_layout = observations.layout.Find(tag_id);
  return in_layout != nullptr ? in_layout->size : observations.tag_size;
}

std::vector<Target> AssembleTargets(const CalibrationObservations& observations) {
  std::vector<Target> targets;
  for (int i = 0; i < static_cast<int>(observations.images.size()); ++i) {
    Target board;
    board.image = i;
    for (const TagCorners& tag : observations.images[i].tags) {
      const LayoutTag* in_layout = observations.layout.Find(tag.tag_id);
      const std::array<Eigen::Vector3d, 4> tag_corners = TagCornersInTagFrame(TagSize(observations, tag.tag_id));
      Target single;
      single.image = i;
      single.tag_id = tag.tag_id;
      Target& target = in_layout != nullptr ? board : single;
      for (int k = 0; k < 4; ++k) {
        target.object.push_back(in_layout != nullptr ? in_layout->layout_from_tag * tag_corners[k] : tag_corners[k]);
        target.pixels.push_back(tag.corners[k]);
      }
      if (!single.object.empty()) targets.push_back(std::move(single));
    }
    if (!board.object.empty()) targets.push_back(std::move(board));
  }
  return targets;
}

// ---------------------------------------------------------------------------------------------
// Closed form (Zhang 2000, sec. 3.1) in normalised pixels x_n = (x - centre) / scale, where the
// intrinsics are K_n = [fx/scale 0 (cx-centre_x)/scale; 0 fy/scale (cy-centre_y)/scale; 0 0 1].

struct PixelNormalisation {
  Eigen::Vector2d centre;
  double scale = 1.0;

  Eigen::Vector2d Apply(const Eigen::Vector2d& pixel) const { return (pixel - centre) / scale; }
};

// h_i^T B h_j as coefficients of b = (B11, B12, B22, B13, B23, B33).
Vector6d ConicRow(const Eigen::Matrix3d& H, int i, int j) {
  const Eigen::Vector3d a = H.col(i), c = H.col(j);
  Vector6d v;
  v << a(0) * c(0), a(0) * c(1) + a(1) * c(0), a(1) * c(1), a(2) * c(0) + a(0) * c(2), a(2) * c(1) + a(1) * c(2),
      a(2) * c(2);
  return v;
}

struct ClosedFormResult {
  bool ok = false;
  bool degenerate = false;  // the constraint matrix is rank deficient (see min_constraint_ratio)
  double constraint_ratio = 0.0;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;  // normalised units
};

// Solves for B with skew 0 and, when `principal_point_at_centre`, B13 = B23 = 0; with a fixed
// aspect ratio a the y coordinate is first divided by a so that B11 = B22.
ClosedFormResult SolveConic(const std::vector<Eigen::Matrix3d>& homographies, bool principal_point_at_centre,
                            bool fix_aspect, double aspect, double min_constraint_ratio) {
  // Columns of the reduced unknown vector as combinations of the full b.
  std::vector<std::vector<int>> columns;  // each entry: indices of b summed into that unknown
  if (fix_aspect) {
    columns.push_back({0, 2});
  } else {
    columns.push_back({0});
    columns.push_back({2});
  }
  if (!principal_point_at_centre) {
    columns.push_back({3});
    columns.push_back({4});
  }
  columns.push_back({5});
  const int k = static_cast<int>(columns.size());
  Eigen::MatrixXd A(2 * homographies.size(), k);
  const Eigen::Matrix3d unscale_y = Eigen::Vector3d(1.0, 1.0 / (fix_aspect ? aspect : 1.0), 1.0).asDiagonal();
  for (size_t n = 0; n < homographies.size(); ++n) {
    Eigen::Matrix3d H = unscale_y * homographies[n];
    H /= std::sqrt(H.col(0).squaredNorm() + H.col(1).squaredNorm());
    const Vector6d rows[2] = {ConicRow(H, 0, 1), ConicRow(H, 0, 0) - ConicRow(H, 1, 1)};
    for (int r = 0; r < 2; ++r) {
      for (int c = 0; c < k; ++c) {
        double sum = 0.0;
        for (int index : columns[c]) sum += rows[r](index);
        A(2 * n + r, c) = sum;
      }
    }
  }
  ClosedFormResult result;
  if (A.rows() < k - 1) {
    result.degenerate = true;
    return result;
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  const Eigen::VectorXd& sigma = svd.singularValues();
  result.constraint_ratio = sigma(0) > 0.0 && sigma.size() >= k ? sigma(k - 2) / sigma(0) : 0.0;
  if (!(result.constraint_ratio >= min_constraint_ratio)) {
    result.degenerate = true;
    return result;
  }
  Eigen::VectorXd reduced = svd.matrixV().col(k - 1);
  Vector6d b = Vector6d::Zero();
  for (int c = 0; c < k; ++c) {
    for (int index : columns[c]) b(index) = reduced(c);
  }
  if (b(0) < 0.0) b = -b;
  const double b11 = b(0), b22 = b(2), b13 = b(3), b23 = b(4), b33 = b(5);
  if (!(b11 > 0.0) || !(b22 > 0.0)) return result;
  const double cx = -b13 / b11, cy = -b23 / b22;
  const double lambda = b33 - b13 * b13 / b11 - b23 * b23 / b22;
  if (!(lambda > 0.0)) return result;
  result.fx = std::sqrt(lambda / b11);
  result.fy = std::sqrt(lambda / b22) * (fix_aspect ? aspect : 1.0);
  result.cx = cx;
  result.cy = cy * (fix_aspect ? aspect : 1.0);
  result.ok = std::isfinite(result.fx) && std::isfinite(result.fy) && std::isfinite(result.cx) &&
              std::isfinite(result.cy);
  return result;
}

// cam_from_tag from x_n ~ K_n [r1 r2 t] (tag plane coordinates in metres).
Rigid3 PoseFromHomography(const Eigen::Matrix3d& H, const Eigen::Matrix3d& K) {
  const Eigen::Matrix3d M = K.inverse() * H;
  double lambda = 1.0 / M.col(0).norm();
  if (M(2, 2) < 0.0) lambda = -lambda;  // the tag centre in front of the camera
  Eigen::Matrix3d R;
  R.col(0) = lambda * M.col(0);
  R.col(1) = lambda * M.col(1);
  R.col(2) = R.col(0).cross(R.col(1));
  return Rigid3{NearestRotation(R), lambda * M.col(2)};
}

// ---------------------------------------------------------------------------------------------
// Joint refinement.

// Which intrinsics move: intrinsics = base + T * free (the columns of T are free directions).
struct IntrinsicsParameterisation {
  Eigen::Matrix<double, kNumIntrinsics, Eigen::Dynamic> T;

  static IntrinsicsParameterisation From(const CalibrationOptions& options) {
    std::vector<Vector6d> columns;
    Vector6d e = Vector6d::Zero();
    e(kFx) = 1.0;
    if (options.fix_aspect_ratio) e(kFy) = options.aspect_ratio;
    columns.push_back(e);
    if (!options.fix_aspect_ratio) columns.push_back(Vector6d::Unit(kFy));
    if (!options.fix_principal_point) {
      columns.push_back(Vector6d::Unit(kCx));
      columns.push_back(Vector6d::Unit(kCy));
    }
    if (options.estimate_k1) columns.push_back(Vector6d::Unit(kK1));
    if (options.estimate_k1 && options.estimate_k2) columns.push_back(Vector6d::Unit(kK2));
    IntrinsicsParameterisation p;
    p.T.resize(kNumIntrinsics, static_cast<int>(columns.size()));
    for (size_t c = 0; c < columns.size(); ++c) p.T.col(static_cast<int>(c)) = columns[c];
    return p;
  }
  int size() const { return static_cast<int>(T.cols()); }
};

struct State {
  Vector6d intrinsics;  // fx, fy, cx, cy, k1, k2
  std::vector<Rigid3> poses;
};

// Pixel of X (target frame) and its Jacobians w.r.t. the 6 intrinsics and the pose update
// (dw, dt) with R <- exp(dw) R, t <- t + dt. False when X is not in front of the camera.
bool ProjectWithJacobians(const Vector6d& k, const Rigid3& pose, const Eigen::Vector3d& X, Eigen::Vector2d* pixel,
                          Matrix26d* d_intrinsics, Matrix26d* d_pose) {
  const Eigen::Vector3d rotated = pose.rotation * X;
  const Eigen::Vector3d c = rotated + pose.translation;
  if (!(c.z() > 0.0)) return false;
  const double inv_z = 1.0 / c.z();
  const Eigen::Vector2d p = c.head<2>() * inv_z;
  RadialCamera camera;
  camera.focal = k(kFx);
  camera.aspect = k(kFy) / k(kFx);
  camera.cx = k(kCx);
  camera.cy = k(kCy);
  camera.k1 = k(kK1);
  camera.k2 = k(kK2);
  *pixel = camera.PixelFromNormalised(p);
  if (d_intrinsics == nullptr) return pixel->allFinite();
  const double r2 = p.squaredNorm();
  const Eigen::Vector2d q = camera.Distortion(r2) * p;
  *d_intrinsics << q.x(), 0.0, 1.0, 0.0, k(kFx) * p.x() * r2, k(kFx) * p.x() * r2 * r2,  //
      0.0, q.y(), 0.0, 1.0, k(kFy) * p.y() * r2, k(kFy) * p.y() * r2 * r2;
  Eigen::Matrix<double, 2, 3> dp_dc;
  dp_dc << inv_z, 0.0, -p.x() * inv_z, 0.0, inv_z, -p.y() * inv_z;
  const Eigen::Matrix<double, 2, 3> du_dc = camera.PixelFromNormalisedJacobian(p) * dp_dc;
  // d(exp(dw) R X) / d dw = -[R X]x, whose column j is e_j x (R X).
  Eigen::Matrix3d dc_dw;
  for (int j = 0; j < 3; ++j) dc_dw.col(j) = Eigen::Vector3d::Unit(j).cross(rotated);
  d_pose->leftCols<3>() = du_dc * dc_dw;
  d_pose->rightCols<3>() = du_dc;
  return pixel->allFinite() && d_intrinsics->allFinite() && d_pose->allFinite();
}

// Normal equations [U W; W^T V] of the free intrinsics and the poses.
struct NormalEquations {
  Eigen::MatrixXd U;                // m x m
  Eigen::VectorXd g_intrinsics;     // m
  std::vector<Matrix6d> V;          // per target
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, 6>> W;  // per target, m x 6
  std::vector<Vector6d> g_pose;
  double cost = 0.0;  // 1/2 sum rho(|r|^2)
};

bool Linearize(const std::vector<Target>& targets, const IntrinsicsParameterisation& param, const RobustLoss& loss,
               const State& x, NormalEquations* eq) {
  const int m = param.size();
  eq->U.setZero(m, m);
  eq->g_intrinsics.setZero(m);
  eq->V.assign(targets.size(), Matrix6d::Zero());
  eq->W.assign(targets.size(), Eigen::Matrix<double, Eigen::Dynamic, 6>::Zero(m, 6));
  eq->g_pose.assign(targets.size(), Vector6d::Zero());
  eq->cost = 0.0;
  Eigen::Vector2d pixel;
  Matrix26d d_intrinsics, d_pose;
  for (size_t t = 0; t < targets.size(); ++t) {
    const Target& target = targets[t];
    for (size_t i = 0; i < target.object.size(); ++i) {
      if (!ProjectWithJacobians(x.intrinsics, x.poses[t], target.object[i], &pixel, &d_intrinsics, &d_pose)) {
        return false;
      }
      const Eigen::Vector2d r = pixel - target.pixels[i];
      double rho = 0.0, weight = 0.0;
      loss.Evaluate(r.squaredNorm(), &rho, &weight);
      eq->cost += 0.5 * rho;
      const Eigen::Matrix<double, 2, Eigen::Dynamic> Ji = d_intrinsics * param.T;
      eq->U.noalias() += weight * Ji.transpose() * Ji;
      eq->g_intrinsics.noalias() += weight * Ji.transpose() * r;
      eq->V[t].noalias() += weight * d_pose.transpose() * d_pose;
      eq->W[t].noalias() += weight * Ji.transpose() * d_pose;
      eq->g_pose[t].noalias() += weight * d_pose.transpose() * r;
    }
  }
  return std::isfinite(eq->cost);
}

// Solves the damped system (diagonal += diag / radius; radius = inf: undamped) by the Schur
// complement of the pose blocks. Returns false when a factorisation fails.
bool SolveSchur(const NormalEquations& eq, double radius, double min_diagonal, Eigen::VectorXd* d_intrinsics,
                std::vector<Vector6d>* d_poses, double* predicted_reduction) {
  const double damping = std::isinf(radius) ? 0.0 : 1.0 / radius;
  const Eigen::VectorXd u_diag = eq.U.diagonal().cwiseMax(min_diagonal);
  Eigen::MatrixXd S = eq.U;
  S.diagonal() += damping * u_diag;
  Eigen::VectorXd rhs = -eq.g_intrinsics;
  std::vector<Eigen::LLT<Matrix6d>> v_factors(eq.V.size());
  std::vector<Vector6d> v_diags(eq.V.size());
  for (size_t t = 0; t < eq.V.size(); ++t) {
    v_diags[t] = eq.V[t].diagonal().cwiseMax(min_diagonal);
    Matrix6d v = eq.V[t];
    v.diagonal() += damping * v_diags[t];
    v_factors[t].compute(v);
    if (v_factors[t].info() != Eigen::Success) return false;
    const Eigen::Matrix<double, 6, Eigen::Dynamic> v_inv_wt = v_factors[t].solve(eq.W[t].transpose());
    S.noalias() -= eq.W[t] * v_inv_wt;
    rhs.noalias() += v_inv_wt.transpose() * eq.g_pose[t];
  }
  Eigen::LLT<Eigen::MatrixXd> s_factor(S);
  if (s_factor.info() != Eigen::Success) return false;
  *d_intrinsics = s_factor.solve(rhs);
  d_poses->resize(eq.V.size());
  double model_decrease = -eq.g_intrinsics.dot(*d_intrinsics) +
                          damping * d_intrinsics->dot(u_diag.cwiseProduct(*d_intrinsics));
  for (size_t t = 0; t < eq.V.size(); ++t) {
    (*d_poses)[t] = v_factors[t].solve(-eq.g_pose[t] - eq.W[t].transpose() * *d_intrinsics);
    model_decrease += -eq.g_pose[t].dot((*d_poses)[t]) + damping * (*d_poses)[t].dot(v_diags[t].cwiseProduct((*d_poses)[t]));
  }
  *predicted_reduction = 0.5 * model_decrease;
  if (!d_intrinsics->allFinite()) return false;
  for (const Vector6d& dp : *d_poses) {
    if (!dp.allFinite()) return false;
  }
  return true;
}

State Plus(const State& x, const IntrinsicsParameterisation& param, const Eigen::VectorXd& d_intrinsics,
           const std::vector<Vector6d>& d_poses) {
  State next = x;
  next.intrinsics += param.T * d_intrinsics;
  for (size_t t = 0; t < x.poses.size(); ++t) {
    next.poses[t].rotation = RotationFromAngleAxis(d_poses[t].head<3>()) * x.poses[t].rotation;
    next.poses[t].translation += d_poses[t].tail<3>();
  }
  return next;
}

// The joint refinement as a RunLm problem (core/math/lm_loop.h): the step from SolveSchur, the
// step size over the free intrinsics and the pose translations.
class Refinement {
 public:
  Refinement(const std::vector<Target>& targets, const IntrinsicsParameterisation& param,
             const CalibrationOptions& options, State* x)
      : targets_(targets), param_(param), options_(options), x_(x) {}

  bool Linearize() { return reconar::Linearize(targets_, param_, options_.loss, *x_, &eq_); }
  double Cost() const { return eq_.cost; }
  double MaxGradient() const {
    double max_gradient = eq_.g_intrinsics.size() > 0 ? eq_.g_intrinsics.cwiseAbs().maxCoeff() : 0.0;
    for (const Vector6d& g : eq_.g_pose) max_gradient = std::max(max_gradient, g.cwiseAbs().maxCoeff());
    return max_gradient;
  }
  bool SolveStep(double radius) {
    return SolveSchur(eq_, radius, options_.lm.min_diagonal, &d_intrinsics_, &d_poses_, &predicted_);
  }
  double StepNorm() const {
    double step_sq = d_intrinsics_.squaredNorm();
    for (const Vector6d& dp : d_poses_) step_sq += dp.tail<3>().squaredNorm();
    return std::sqrt(step_sq);
  }
  double StateNorm() const {
    double sq = (param_.T.transpose() * x_->intrinsics).squaredNorm();
    for (const Rigid3& pose : x_->poses) sq += pose.translation.squaredNorm();
    return std::sqrt(sq);
  }
  double PredictedReduction() const { return predicted_; }
  bool EvaluateStep(double* cost) {
    next_ = Plus(*x_, param_, d_intrinsics_, d_poses_);
    const bool ok = reconar::Linearize(targets_, param_, options_.loss, next_, &trial_);
    *cost = trial_.cost;
    return ok;
  }
  void AcceptStep() {
    *x_ = next_;
    std::swap(eq_, trial_);
  }

 private:
  const std::vector<Target>& targets_;
  const IntrinsicsParameterisation& param_;
  const CalibrationOptions& options_;
  State* x_;
  State next_;
  NormalEquations eq_, trial_;
  Eigen::VectorXd d_intrinsics_;
  std::vector<Vector6d> d_poses_;
  double predicted_ = 0.0;
};

// Squared pixel errors of every corner of every target.
std::vector<std::vector<double>> SquaredErrors(const std::vector<Target>& targets, const State& x) {
  std::vector<std::vector<double>> errors(targets.size());
  Eigen::Vector2d pixel;
  for (size_t t = 0; t < targets.size(); ++t) {
    for (size_t i = 0; i < targets[t].object.size(); ++i) {
      const bool in_front =
          ProjectWithJacobians(x.intrinsics, x.poses[t], targets[t].object[i], &pixel, nullptr, nullptr);
      errors[t].push_back(in_front ? (pixel - targets[t].pixels[i]).squaredNorm()
                                   : std::numeric_limits<double>::infinity());
    }
  }
  return errors;
}

double Rms(const std::vector<std::vector<double>>& errors) {
  double sum = 0.0;
  size_t count = 0;
  for (const auto& target : errors) {
    for (double e : target) sum += e;
    count += target.size();
  }
  return count > 0 ? std::sqrt(sum / static_cast<double>(count)) : 0.0;
}

CameraIntrinsics ToIntrinsics(const Vector6d& k, int width, int height) {
  CameraIntrinsics intrinsics;
  intrinsics.width = width;
  intrinsics.height = height;
  intrinsics.fx = k(kFx);
  intrinsics.fy = k(kFy);
  intrinsics.cx = k(kCx);
  intrinsics.cy = k(kCy);
  intrinsics.k1 = k(kK1);
  intrinsics.k2 = k(kK2);
  return intrinsics;
}

}  // namespace

CalibrationImage MakeCalibrationImage(std::string name, int width, int height, const TagDetectionList& detections) {
  CalibrationImage image;
  image.name = std::move(name);
  image.width = width;
  image.height = height;
  for (const TagDetection& detection : detections) {
    TagCorners tag;
    tag.tag_id = detection.id;
    for (int k = 0; k < 4; ++k) tag.corners[k] = detection.corners[k];
    image.tags.push_back(tag);
  }
  return image;
}

Status CalibrationOptions::Check() const {
  if (!(aspect_ratio > 0.0) || !std::isfinite(aspect_ratio)) {
    return InvalidArgument("CalibrationOptions: aspect_ratio must be positive");
  }
  if (estimate_k2 && !estimate_k1) return InvalidArgument("CalibrationOptions: estimate_k2 needs estimate_k1");
  RECONAR_RETURN_IF_ERROR(lm.Check().WithContext("CalibrationOptions.lm"));
  if (!(loss.scale > 0.0) || !std::isfinite(loss.scale)) {
    return InvalidArgument("CalibrationOptions: loss.scale must be positive");
  }
  if (min_targets < 1) return InvalidArgument("CalibrationOptions: min_targets must be >= 1");
  if (min_images < 1) return InvalidArgument("CalibrationOptions: min_images must be >= 1");
  if (min_targets_for_free_principal_point < 2) {
    return InvalidArgument("CalibrationOptions: min_targets_for_free_principal_point must be >= 2");
  }
  if (!(min_constraint_ratio >= 0.0) || !(min_constraint_ratio < 1.0)) {
    return InvalidArgument("CalibrationOptions: min_constraint_ratio must be in [0, 1)");
  }
  if (!(max_relative_focal_stddev > 0.0)) {
    return InvalidArgument("CalibrationOptions: max_relative_focal_stddev must be positive");
  }
  return Status::Ok();
}

Result<CalibrationReport> CalibrateIntrinsics(const CalibrationObservations& observations,
                                              const CalibrationOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  RECONAR_RETURN_IF_ERROR(CheckObservations(observations));
  std::vector<Target> targets = AssembleTargets(observations);
  int num_images_used = 0;
  for (size_t i = 0; i < observations.images.size(); ++i) {
    num_images_used += observations.images[i].tags.empty() ? 0 : 1;
  }
  if (static_cast<int>(targets.size()) < options.min_targets || num_images_used < options.min_images) {
    return FailedPrecondition("calibration: too few views: " + std::to_string(targets.size()) +
                              " targets in " + std::to_string(num_images_used) + " images with tags (need " +
                              std::to_string(options.min_targets) + " targets and " +
                              std::to_string(options.min_images) + " images)");
  }
  const int width = observations.images.front().width;
  const int height = observations.images.front().height;
  PixelNormalisation norm;
  norm.centre = Eigen::Vector2d(0.5 * (width - 1), 0.5 * (height - 1));
  norm.scale = std::max(width, height);

  // 1. A homography per tag instance (board views are built from tags, so each of their tags is planar).
  struct TagView {
    int image;
    int tag_id;
    Eigen::Matrix3d H;  // normalised pixels ~ H (tag plane x, y, 1)
    double area;        // pixels^2, to pick the best-resolved tag of a board view
  };
  std::vector<TagView> tag_views;
  for (int i = 0; i < static_cast<int>(observations.images.size()); ++i) {
    for (const TagCorners& tag : observations.images[i].tags) {
      const std::array<Eigen::Vector3d, 4> tag_corners = TagCornersInTagFrame(TagSize(observations, tag.tag_id));
      std::array<Correspondence, 4> samples;
      for (int k = 0; k < 4; ++k) samples[k] = {tag_corners[k].head<2>(), norm.Apply(tag.corners[k])};
      std::array<Eigen::Matrix3d, 1> models;
      if (HomographyFourPoint::Estimate(samples.data(), 4, &models) != 1) continue;
      const Eigen::Vector2d d1 = tag.corners[2] - tag.corners[0], d2 = tag.corners[3] - tag.corners[1];
      tag_views.push_back({i, tag.tag_id, models[0], 0.5 * std::abs(d1.x() * d2.y() - d1.y() * d2.x())});
    }
  }
  std::vector<Eigen::Matrix3d> homographies;
  for (const TagView& view : tag_views) homographies.push_back(view.H);

  // 2. Closed-form intrinsics.
  ClosedFormResult closed;
  const bool try_free_principal_point = !options.fix_principal_point &&
                                        static_cast<int>(homographies.size()) >=
                                            options.min_targets_for_free_principal_point;
  if (try_free_principal_point) {
    closed = SolveConic(homographies, false, options.fix_aspect_ratio, options.aspect_ratio,
                        options.min_constraint_ratio);
    // The principal point must lie inside the image.
    if (closed.ok && (std::abs(closed.cx) * norm.scale > 0.5 * width || std::abs(closed.cy) * norm.scale > 0.5 * height)) {
      closed.ok = false;
    }
  }
  const bool principal_point_from_closed_form = closed.ok;
  if (!closed.ok) {
    closed = SolveConic(homographies, true, options.fix_aspect_ratio, options.aspect_ratio,
                        options.min_constraint_ratio);
  }
  if (!closed.ok) {
    std::ostringstream message;
    message << "calibration: degenerate views: the " << homographies.size()
            << " tag homographies do not determine the focal length (";
    if (closed.degenerate) {
      message << "all targets nearly fronto-parallel or too few: constraint ratio " << closed.constraint_ratio
              << " < " << options.min_constraint_ratio;
    } else {
      message << "no positive-definite image of the absolute conic";
    }
    message << "); photograph the tags from several oblique angles";
    return FailedPrecondition(message.str());
  }
  Eigen::Matrix3d K_normalised = Eigen::Matrix3d::Identity();
  K_normalised(0, 0) = closed.fx;
  K_normalised(1, 1) = closed.fy;
  K_normalised(0, 2) = closed.cx;
  K_normalised(1, 2) = closed.cy;

  State x;
  x.intrinsics << closed.fx * norm.scale, closed.fy * norm.scale, closed.cx * norm.scale + norm.centre.x(),
      closed.cy * norm.scale + norm.centre.y(), 0.0, 0.0;
  if (options.fix_aspect_ratio) x.intrinsics(kFy) = options.aspect_ratio * x.intrinsics(kFx);

  // 3. Target poses: single tags from their homography, boards from their best tag.
  std::map<std::pair<int, int>, std::vector<const TagView*>> views_by_image_and_tag;  // (image, tag_id)
  for (const TagView& view : tag_views) views_by_image_and_tag[{view.image, view.tag_id}].push_back(&view);
  std::vector<Target> usable;
  for (Target& target : targets) {
    std::vector<Rigid3> candidates;
    if (target.tag_id >= 0) {
      // A single tag: the homography of its instance (the same id twice in one image: each one's own).
      const auto& views = views_by_image_and_tag[{target.image, target.tag_id}];
      for (const TagView* view : views) {
        const Rigid3 pose = PoseFromHomography(view->H, K_normalised);
        candidates.push_back(pose);
      }
    } else {
      for (const TagView& view : tag_views) {
        if (view.image != target.image) continue;
        const LayoutTag* in_layout = observations.layout.Find(view.tag_id);
        if (in_layout == nullptr) continue;
        candidates.push_back(PoseFromHomography(view.H, K_normalised) * in_layout->layout_from_tag.Inverse());
      }
    }
    if (candidates.empty()) continue;  // no usable homography (coincident corners)
    double best_error = std::numeric_limits<double>::infinity();
    State one;
    one.intrinsics = x.intrinsics;
    for (const Rigid3& candidate : candidates) {
      one.poses = {candidate};
      const double error = Rms(SquaredErrors({target}, one));
      if (error < best_error) {
        best_error = error;
        target.cam_from_target = candidate;
      }
    }
    if (std::isfinite(best_error)) usable.push_back(std::move(target));
  }
  targets = std::move(usable);
  if (static_cast<int>(targets.size()) < options.min_targets) {
    return FailedPrecondition("calibration: too few usable targets: " + std::to_string(targets.size()) +
                              " have a valid initial pose (need " + std::to_string(options.min_targets) + ")");
  }
  for (const Target& target : targets) x.poses.push_back(target.cam_from_target);

  CalibrationReport report;
  report.closed_form = ToIntrinsics(x.intrinsics, width, height);
  report.principal_point_from_closed_form = principal_point_from_closed_form;
  report.constraint_ratio = closed.constraint_ratio;
  report.initial_rms_px = Rms(SquaredErrors(targets, x));

  // 4. Joint refinement. With the principal point fixed it sits at the image centre.
  if (options.fix_principal_point) {
    x.intrinsics(kCx) = norm.centre.x();
    x.intrinsics(kCy) = norm.centre.y();
  }
  const IntrinsicsParameterisation param = IntrinsicsParameterisation::From(options);
  Refinement refinement(targets, param, options, &x);
  const LmSummary summary = RunLm(refinement, options.lm);
  if (summary.termination == LmTermination::kNumericFailure) {
    return NumericFailure("calibration: the reprojection error is not finite at the initial estimate");
  }
  report.iterations = summary.iterations;
  report.termination = summary.termination;
  report.converged = summary.converged();

  // Covariance of the free intrinsics: sigma^2 (U - W V^-1 W^T)^-1 at the solution.
  NormalEquations eq;
  if (!Linearize(targets, param, options.loss, x, &eq)) {
    return NumericFailure("calibration: the refined reprojection error is not finite");
  }
  int num_corners = 0;
  for (const Target& target : targets) num_corners += static_cast<int>(target.object.size());
  const int dof = 2 * num_corners - param.size() - 6 * static_cast<int>(targets.size());
  Eigen::MatrixXd information = eq.U;
  bool information_ok = true;
  for (size_t t = 0; t < targets.size(); ++t) {
    Eigen::LLT<Matrix6d> v(eq.V[t]);
    if (v.info() != Eigen::Success) {
      information_ok = false;
      break;
    }
    information.noalias() -= eq.W[t] * v.solve(eq.W[t].transpose());
  }
  Eigen::FullPivLU<Eigen::MatrixXd> lu(information);
  if (!information_ok || dof <= 0 || !lu.isInvertible()) {
    return FailedPrecondition("calibration: degenerate views: the intrinsics are not constrained by the " +
                              std::to_string(targets.size()) + " targets (singular information matrix)");
  }
  const double sigma2 = 2.0 * eq.cost / dof;
  const Eigen::MatrixXd covariance = param.T * (sigma2 * lu.inverse()) * param.T.transpose();
  for (int j = 0; j < kNumIntrinsics; ++j) report.stddev[j] = std::sqrt(std::max(0.0, covariance(j, j)));

  report.intrinsics = ToIntrinsics(x.intrinsics, width, height);
  if (!(report.intrinsics.fx > 0.0) || !(report.intrinsics.fy > 0.0) ||
      !(report.stddev[kFx] <= options.max_relative_focal_stddev * report.intrinsics.fx) ||
      !(report.stddev[kFy] <= options.max_relative_focal_stddev * report.intrinsics.fy)) {
    std::ostringstream message;
    message << "calibration: degenerate views: they do not constrain the focal length: fx = " << report.intrinsics.fx << " +- "
            << report.stddev[kFx] << ", fy = " << report.intrinsics.fy << " +- " << report.stddev[kFy]
            << " px (limit " << options.max_relative_focal_stddev * 100.0
            << " %); photograph the tags from several oblique angles";
    return FailedPrecondition(message.str());
  }

  const std::vector<std::vector<double>> errors = SquaredErrors(targets, x);
  report.rms_px = Rms(errors);
  report.image_rms_px.assign(observations.images.size(), 0.0);
  std::vector<double> image_sum(observations.images.size(), 0.0);
  std::vector<int> image_count(observations.images.size(), 0);
  for (size_t t = 0; t < targets.size(); ++t) {
    CalibrationTargetPose pose;
    pose.image = targets[t].image;
    pose.tag_id = targets[t].tag_id;
    pose.cam_from_target = x.poses[t];
    pose.num_corners = static_cast<int>(errors[t].size());
    pose.rms_px = Rms({errors[t]});
    report.targets.push_back(pose);
    for (double e : errors[t]) image_sum[pose.image] += e;
    image_count[pose.image] += pose.num_corners;
  }
  for (size_t i = 0; i < image_sum.size(); ++i) {
    if (image_count[i] > 0) {
      report.image_rms_px[i] = std::sqrt(image_sum[i] / image_count[i]);
      ++report.num_images_used;
    }
  }
  report.num_targets = static_cast<int>(targets.size());
  report.num_corners = num_corners;
  return report;
}

}  // namespace reconar
