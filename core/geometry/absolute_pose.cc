#include "core/geometry/absolute_pose.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/QR>
#include <Eigen/SVD>

#include "core/geometry/polynomial.h"
#include "core/geometry/ransac.h"
#include "core/math/adjugate.h"

namespace reconar {
namespace {

// ---------------------------------------------------------------------------------------------
// Lambda Twist P3P.
// Unknowns are the distances lambda_i along the unit bearings y_i to the world points X_i:
// |lambda_i y_i - lambda_j y_j|^2 = a_ij = |X_i - X_j|^2, i.e. Lambda^T M_ij Lambda = a_ij with
// b_ij = y_i . y_j. The homogeneous combinations D1 = a23 M12 - a12 M23 and D2 = a23 M13 - a13 M23
// vanish on every solution; a real root gamma of det(D1 + gamma D2) = 0 makes D0 = D1 + gamma D2 a
// degenerate conic, a pair of planes through its null vector, each of which meets the conic of D2
// in (up to) two solution rays. Their scale follows from the a_ij, then Gauss-Newton polishes the
// three lambdas and R, t follow from the three camera-frame points. Unlike the paper, which
// eliminates lambda_1 on each plane, the two rays on a plane come from the 2x2 restriction of D2
// to it (no division by a possibly vanishing coefficient).

struct P3PSystem {
  double a12, a13, a23;  // squared world distances
  double b12, b13, b23;  // bearing cosines

  Eigen::Vector3d Residual(const Eigen::Vector3d& l) const {
    return Eigen::Vector3d(l(0) * l(0) + l(1) * l(1) - 2.0 * b12 * l(0) * l(1) - a12,
                           l(0) * l(0) + l(2) * l(2) - 2.0 * b13 * l(0) * l(2) - a13,
                           l(1) * l(1) + l(2) * l(2) - 2.0 * b23 * l(1) * l(2) - a23);
  }

  // Gauss-Newton on the three distance equations, kept while the residual decreases.
  void Polish(Eigen::Vector3d* lambda) const {
    Eigen::Vector3d r = Residual(*lambda);
    for (int iteration = 0; iteration < 5; ++iteration) {
      const Eigen::Vector3d& l = *lambda;
      Eigen::Matrix3d J;
      J << 2.0 * (l(0) - b12 * l(1)), 2.0 * (l(1) - b12 * l(0)), 0.0,  //
          2.0 * (l(0) - b13 * l(2)), 0.0, 2.0 * (l(2) - b13 * l(0)),   //
          0.0, 2.0 * (l(1) - b23 * l(2)), 2.0 * (l(2) - b23 * l(1));
      const double det = J.determinant();
      if (!(std::abs(det) > 0.0)) return;
      const Eigen::Vector3d next = l - J.inverse() * r;
      const Eigen::Vector3d r_next = Residual(next);
      if (!(r_next.squaredNorm() < r.squaredNorm())) return;
      *lambda = next;
      r = r_next;
    }
  }
};

// Directions v in the plane span{p, q} (orthonormal) with v^T D v = 0; appends up to two.
int RaysOnPlane(const Eigen::Matrix3d& D, const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                std::array<Eigen::Vector3d, 2>* rays) {
  Eigen::Matrix2d S;
  S(0, 0) = p.dot(D * p);
  S(0, 1) = S(1, 0) = p.dot(D * q);
  S(1, 1) = q.dot(D * q);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(S);
  const double mu1 = eigen.eigenvalues()(0), mu2 = eigen.eigenvalues()(1);
  // mu1 (f1 . v)^2 + mu2 (f2 . v)^2 = 0 needs eigenvalues of opposite sign (or one zero).
  if (mu1 > 0.0 || mu2 < 0.0) return 0;
  const Eigen::Vector2d f1 = eigen.eigenvectors().col(0), f2 = eigen.eigenvectors().col(1);
  const double s1 = std::sqrt(-mu1), s2 = std::sqrt(mu2);
  int count = 0;
  for (double sign : {1.0, -1.0}) {
    const Eigen::Vector2d v = s2 * f1 + sign * s1 * f2;
    (*rays)[count++] = v(0) * p + v(1) * q;
    if (s1 == 0.0 || s2 == 0.0) break;  // a double root
  }
  return count;
}

// R and t with lambda_i y_i = R X_i + t: R maps the world triangle's frame (two edges and their
// cross product) onto the camera's, projected onto the nearest rotation.
bool PoseFromCameraPoints(const std::array<Eigen::Vector3d, 3>& camera_points,
                          const std::array<Eigen::Vector3d, 3>& world, Matrix34d* pose) {
  Eigen::Matrix3d Y, X;
  Y.col(0) = camera_points[0] - camera_points[1];
  Y.col(1) = camera_points[0] - camera_points[2];
  Y.col(2) = Y.col(0).cross(Y.col(1));
  X.col(0) = world[0] - world[1];
  X.col(1) = world[0] - world[2];
  X.col(2) = X.col(0).cross(X.col(1));
  const Eigen::Matrix3d R_raw = Y * X.inverse();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R_raw, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
  if (R.determinant() < 0.0) return false;
  const Eigen::Vector3d t =
      (camera_points[0] + camera_points[1] + camera_points[2] - R * (world[0] + world[1] + world[2])) / 3.0;
  if (!R.allFinite() || !t.allFinite()) return false;
  pose->leftCols<3>() = R;
  pose->col(3) = t;
  return true;
}

// ---------------------------------------------------------------------------------------------
// Pose refinement (RefineAbsolutePoseInPlace).

Eigen::Matrix3d ExpRotation(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle < 1e-12) {
    Eigen::Matrix3d R;
    R << 1.0, -w.z(), w.y(), w.z(), 1.0, -w.x(), -w.y(), w.x(), 1.0;
    return R;
  }
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

// The NormalLmSolve problem: pose (dw, dt) and, when kRefineFocal, log focal.
template <bool kRefineFocal>
class PoseRefinementProblem {
 public:
  static constexpr int kDim = kRefineFocal ? 7 : 6;
  struct State {
    Eigen::Matrix3d R;
    Eigen::Vector3d t;
    double focal;
  };
  using Tangent = Eigen::Matrix<double, kDim, 1>;

  PoseRefinementProblem(const Eigen::Vector2d* points_px, const Eigen::Vector3d* world_points, const int* indices,
                        int count, const AbsolutePoseCamera& camera, const PoseRefinementOptions& options)
      : points_px_(points_px),
        world_points_(world_points),
        indices_(indices),
        count_(count),
        camera_(camera),
        loss_{options.loss, options.loss_scale_px} {}

  bool Linearize(const State& x, Eigen::Matrix<double, kDim, kDim>* jtj, Tangent* jtr, double* cost) const {
    jtj->setZero();
    jtr->setZero();
    *cost = 0.0;
    for (int k = 0; k < count_; ++k) {
      const int i = indices_[k];
      const Eigen::Vector3d rotated = x.R * world_points_[i];
      const Eigen::Vector3d X = rotated + x.t;
      if (!(X.z() > 0.0)) return false;
      const double inv_z = 1.0 / X.z();
      const Eigen::Vector2d p(X.x() * inv_z, X.y() * inv_z);
      const double r2 = p.squaredNorm();
      const double d = 1.0 + r2 * (camera_.k1 + r2 * camera_.k2);
      const Eigen::Vector2d e = x.focal * d * p + Eigen::Vector2d(camera_.cx, camera_.cy) - points_px_[i];

      Eigen::Matrix<double, 2, 3> dp_dX;
      dp_dX << inv_z, 0.0, -p.x() * inv_z, 0.0, inv_z, -p.y() * inv_z;
      const Eigen::Matrix2d de_dp =
          x.focal * (d * Eigen::Matrix2d::Identity() + 2.0 * (camera_.k1 + 2.0 * camera_.k2 * r2) * p * p.transpose());
      const Eigen::Matrix<double, 2, 3> de_dX = de_dp * dp_dX;
      Eigen::Matrix<double, 2, kDim> J;
      J.template leftCols<3>() = -de_dX * Skew(rotated);  // d(exp(dw) R X) / d dw = -[R X]x
      J.template middleCols<3>(3) = de_dX;
      if constexpr (kRefineFocal) J.col(6) = x.focal * d * p;  // f = f0 exp(df)

      double rho = 0.0, weight = 0.0;
      loss_.Evaluate(e.squaredNorm(), &rho, &weight);
      jtj->noalias() += weight * J.transpose() * J;
      jtr->noalias() += weight * J.transpose() * e;
      *cost += 0.5 * rho;
    }
    return true;
  }

  State Plus(const State& x, const Tangent& dx) const {
    State next;
    next.R = ExpRotation(dx.template head<3>()) * x.R;
    next.t = x.t + dx.template segment<3>(3);
    next.focal = x.focal;
    if constexpr (kRefineFocal) next.focal = x.focal * std::exp(dx(6));
    return next;
  }

  double Norm(const State& x) const { return 1.0 + x.t.norm(); }

 private:
  const Eigen::Vector2d* points_px_;
  const Eigen::Vector3d* world_points_;
  const int* indices_;
  int count_;
  AbsolutePoseCamera camera_;
  RobustLoss loss_;
};

template <bool kRefineFocal>
NormalLmSummary SolvePoseRefinement(const Eigen::Vector2d* points_px, const Eigen::Vector3d* world_points,
                                    const int* indices, int count, const PoseRefinementOptions& options,
                                    AbsolutePoseCamera* camera, Eigen::Matrix3d* R, Eigen::Vector3d* t) {
  using Problem = PoseRefinementProblem<kRefineFocal>;
  const Problem problem(points_px, world_points, indices, count, *camera, options);
  typename Problem::State state{*R, *t, camera->focal};
  const NormalLmSummary summary = NormalLmSolve(problem, options.lm, &state);
  if (summary.termination != NormalLmSummary::Termination::kNumericFailure) {
    *R = state.R;
    *t = state.t;
    camera->focal = state.focal;
  }
  return summary;
}

// ---------------------------------------------------------------------------------------------
// High level.

std::string Number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.3g", value);
  return buffer;
}

// Pixel inliers of the pose, ascending, and their mean error.
void PixelInliers(const std::vector<Eigen::Vector2d>& points_px, const std::vector<Eigen::Vector3d>& world_points,
                  const AbsolutePoseCamera& camera, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                  double max_error_px, std::vector<int>* inliers, double* mean_error) {
  inliers->clear();
  double sum = 0.0;
  const double t2 = max_error_px * max_error_px;
  for (size_t i = 0; i < points_px.size(); ++i) {
    const double squared = SquaredPixelError(camera, R, t, world_points[i], points_px[i]);
    if (squared < t2) {
      inliers->push_back(static_cast<int>(i));
      sum += std::sqrt(squared);
    }
  }
  *mean_error = inliers->empty() ? 0.0 : sum / static_cast<double>(inliers->size());
}

// Refinement (when asked) from the RANSAC pose and its inliers, then the final pixel inliers and
// outcome. The refinement is repeated once on the pixel inliers of the refined pose when they differ.
void FinishPose(const std::vector<Eigen::Vector2d>& points_px, const std::vector<Eigen::Vector3d>& world_points,
                AbsolutePoseCamera camera, const AbsolutePoseOptions& options, bool refine_focal, Eigen::Matrix3d R,
                Eigen::Vector3d t, std::vector<int> inliers, AbsolutePoseResult* result) {
  PoseRefinementOptions refinement = options.refinement;
  refinement.refine_focal = refine_focal;
  double mean_error = 0.0;
  constexpr int kMaxRefinementRounds = 2;
  for (int round = 0; options.refine && round < kMaxRefinementRounds; ++round) {
    if (static_cast<int>(inliers.size()) < P3PEstimator::kMinSamples + 1) break;
    AbsolutePoseCamera refined_camera = camera;
    Eigen::Matrix3d refined_R = R;
    Eigen::Vector3d refined_t = t;
    const NormalLmSummary summary =
        RefineAbsolutePoseInPlace(points_px.data(), world_points.data(), inliers.data(),
                                  static_cast<int>(inliers.size()), refinement, &refined_camera, &refined_R,
                                  &refined_t);
    if (summary.termination == NormalLmSummary::Termination::kNumericFailure) break;
    camera = refined_camera;
    R = refined_R;
    t = refined_t;
    result->refined = true;
    result->refinement = summary;
    std::vector<int> refined_inliers;
    PixelInliers(points_px, world_points, camera, R, t, options.max_error_px, &refined_inliers, &mean_error);
    const bool unchanged = refined_inliers == inliers;
    inliers = std::move(refined_inliers);
    if (unchanged) break;
  }
  PixelInliers(points_px, world_points, camera, R, t, options.max_error_px, &inliers, &mean_error);
  result->cam_from_world_rotation = R;
  result->cam_from_world_translation = t;
  result->focal = camera.focal;
  result->num_inliers = static_cast<int>(inliers.size());
  result->inliers = std::move(inliers);
  result->mean_inlier_error_px = mean_error;
  if (result->num_inliers < options.min_inliers) {
    result->outcome = AbsolutePoseResult::Outcome::kTooFewInliers;
    result->reason = "the best pose has " + std::to_string(result->num_inliers) + " inliers within " +
                     Number(options.max_error_px) + " px, need " + std::to_string(options.min_inliers);
    return;
  }
  result->outcome = AbsolutePoseResult::Outcome::kSuccess;
  result->reason.clear();
}

Status CheckInputSizes(const std::vector<Eigen::Vector2d>& points_px, const std::vector<Eigen::Vector3d>& world_points,
                       const char* function) {
  if (points_px.size() != world_points.size()) {
    return InvalidArgument(std::string(function) + ": " + std::to_string(points_px.size()) + " image points but " +
                           std::to_string(world_points.size()) + " world points");
  }
  return Status::Ok();
}

std::vector<int> MaskToIndices(const std::vector<char>& mask, const std::vector<int>& sample_to_input) {
  std::vector<int> indices;
  for (size_t k = 0; k < mask.size(); ++k) {
    if (mask[k]) indices.push_back(sample_to_input[k]);
  }
  return indices;
}

bool TooFewCorrespondences(int usable, int total, int needed, AbsolutePoseResult* result) {
  if (usable >= needed) return false;
  result->outcome = AbsolutePoseResult::Outcome::kTooFewCorrespondences;
  result->reason = std::to_string(usable) + " usable correspondences (of " + std::to_string(total) +
                   "), need at least " + std::to_string(needed);
  return true;
}

void NoModel(const std::string& why, int iterations, AbsolutePoseResult* result) {
  result->outcome = AbsolutePoseResult::Outcome::kNoModel;
  result->reason = "no pose found after " + std::to_string(iterations) + " RANSAC iterations: " + why;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

int P3PEstimator::Estimate(const Sample* samples, int count, std::array<Model, kMaxModels>* models) {
  if (count < kMinSamples) return 0;
  std::array<Eigen::Vector3d, 3> y, X;
  for (int i = 0; i < 3; ++i) {
    y[i] = samples[i].point.homogeneous().normalized();
    X[i] = samples[i].world;
  }
  P3PSystem system;
  system.a12 = (X[0] - X[1]).squaredNorm();
  system.a13 = (X[0] - X[2]).squaredNorm();
  system.a23 = (X[1] - X[2]).squaredNorm();
  system.b12 = y[0].dot(y[1]);
  system.b13 = y[0].dot(y[2]);
  system.b23 = y[1].dot(y[2]);
  // Collinear or coincident world points leave a rotation about their line free.
  const double largest = std::max({system.a12, system.a13, system.a23});
  const double area2 = (X[0] - X[1]).cross(X[0] - X[2]).squaredNorm();
  if (!(area2 > 1e-20 * largest * largest)) return 0;

  const double a12 = system.a12, a13 = system.a13, a23 = system.a23;
  const double b12 = system.b12, b13 = system.b13, b23 = system.b23;
  Eigen::Matrix3d M12, M13, M23;
  M12 << 1.0, -b12, 0.0, -b12, 1.0, 0.0, 0.0, 0.0, 0.0;
  M13 << 1.0, 0.0, -b13, 0.0, 0.0, 0.0, -b13, 0.0, 1.0;
  M23 << 0.0, 0.0, 0.0, 0.0, 1.0, -b23, 0.0, -b23, 1.0;
  const Eigen::Matrix3d D1 = a23 * M12 - a12 * M23;
  const Eigen::Matrix3d D2 = a23 * M13 - a13 * M23;

  // A real root of det(D1 + gamma D2); the smallest in magnitude keeps D1 from being drowned.
  // With no root the leading coefficient det(D2) vanished: D2 itself is the degenerate conic.
  const double c3 = D2.determinant();
  const double c2 = (Adjugate(D2).cwiseProduct(D1)).sum();
  const double c1 = (Adjugate(D1).cwiseProduct(D2)).sum();
  const double c0 = D1.determinant();
  double roots[3];
  const int num_roots = SolveCubicReal(c3, c2, c1, c0, roots);
  Eigen::Matrix3d D0 = D2;
  Eigen::Matrix3d D_other = D1;
  if (num_roots > 0) {
    double gamma = roots[0];
    for (int i = 1; i < num_roots; ++i) {
      if (std::abs(roots[i]) < std::abs(gamma)) gamma = roots[i];
    }
    D0 = D1 + gamma * D2;
    D_other = D2;
  }
  if (!D0.allFinite()) return 0;

  // D0 = sum sigma_k e_k e_k^T with one sigma ~ 0; the other two have opposite signs and
  // Lambda^T D0 Lambda = 0 splits into the planes sqrt|s_i| e_i . Lambda = +-sqrt|s_j| e_j . Lambda.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(D0);
  const Eigen::Vector3d sigma = eigen.eigenvalues();
  int zero = 0;
  for (int k = 1; k < 3; ++k) {
    if (std::abs(sigma(k)) < std::abs(sigma(zero))) zero = k;
  }
  const int i = zero == 0 ? 1 : 0;
  const int j = zero == 2 ? 1 : 2;
  if (!(sigma(i) * sigma(j) < 0.0)) return 0;
  const Eigen::Vector3d e_zero = eigen.eigenvectors().col(zero);
  const Eigen::Vector3d e_i = eigen.eigenvectors().col(i);
  const Eigen::Vector3d e_j = eigen.eigenvectors().col(j);
  const double s_i = std::sqrt(std::abs(sigma(i))), s_j = std::sqrt(std::abs(sigma(j)));

  int num_models = 0;
  for (double sign : {1.0, -1.0}) {
    // The plane (s_i e_i - sign s_j e_j) . Lambda = 0 is spanned by e_zero and s_j e_i + sign s_i e_j.
    const Eigen::Vector3d in_plane = (s_j * e_i + sign * s_i * e_j).normalized();
    std::array<Eigen::Vector3d, 2> rays;
    const int num_rays = RaysOnPlane(D_other, e_zero, in_plane, &rays);
    for (int r = 0; r < num_rays && num_models < kMaxModels; ++r) {
      const Eigen::Vector3d& ray = rays[r];
      // Scale from the sum of the three distance equations (a sum of positive semidefinite forms).
      const double form = ray.dot((M12 + M13 + M23) * ray);
      if (!(form > 0.0)) continue;
      double scale = std::sqrt((a12 + a13 + a23) / form);
      if (ray.sum() < 0.0) scale = -scale;
      Eigen::Vector3d lambda = scale * ray;
      if (!(lambda.minCoeff() > 0.0)) continue;
      system.Polish(&lambda);
      if (!(lambda.minCoeff() > 0.0)) continue;
      const std::array<Eigen::Vector3d, 3> camera_points = {lambda(0) * y[0], lambda(1) * y[1], lambda(2) * y[2]};
      if (PoseFromCameraPoints(camera_points, X, &(*models)[num_models])) ++num_models;
    }
  }
  return num_models;
}

void P3PEstimator::Residuals(const Sample* samples, int count, const Model& cam_from_world,
                             double* squared_residuals) {
  for (int i = 0; i < count; ++i) squared_residuals[i] = SquaredReprojectionError(cam_from_world, samples[i]);
}

int DltPoseEstimator::Estimate(const Sample* samples, int count, std::array<Model, kMaxModels>* models) {
  if (count < kMinSamples) return 0;
  // Hartley normalisation: image points to mean distance sqrt(2), world points to sqrt(3) from
  // their centroids (H&Z algorithm 7.1).
  Eigen::Vector2d image_centroid = Eigen::Vector2d::Zero();
  Eigen::Vector3d world_centroid = Eigen::Vector3d::Zero();
  for (int i = 0; i < count; ++i) {
    image_centroid += samples[i].point;
    world_centroid += samples[i].world;
  }
  image_centroid /= count;
  world_centroid /= count;
  double image_spread = 0.0, world_spread = 0.0;
  for (int i = 0; i < count; ++i) {
    image_spread += (samples[i].point - image_centroid).norm();
    world_spread += (samples[i].world - world_centroid).norm();
  }
  if (!(image_spread > 0.0) || !(world_spread > 0.0) || !std::isfinite(image_spread + world_spread)) return 0;
  const double image_scale = std::sqrt(2.0) * count / image_spread;
  const double world_scale = std::sqrt(3.0) * count / world_spread;

  // Each point gives p1 . X - u p3 . X = 0 and p2 . X - v p3 . X = 0 on vec(P) (row-major).
  Eigen::Matrix<double, 12, 12> AtA = Eigen::Matrix<double, 12, 12>::Zero();
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector2d x = image_scale * (samples[i].point - image_centroid);
    const Eigen::Vector4d Xh = (world_scale * (samples[i].world - world_centroid)).homogeneous();
    Eigen::Matrix<double, 12, 1> row_u = Eigen::Matrix<double, 12, 1>::Zero();
    Eigen::Matrix<double, 12, 1> row_v = Eigen::Matrix<double, 12, 1>::Zero();
    row_u.head<4>() = Xh;
    row_u.tail<4>() = -x.x() * Xh;
    row_v.segment<4>(4) = Xh;
    row_v.tail<4>() = -x.y() * Xh;
    AtA.selfadjointView<Eigen::Lower>().rankUpdate(row_u);
    AtA.selfadjointView<Eigen::Lower>().rankUpdate(row_v);
  }
  AtA.triangularView<Eigen::StrictlyUpper>() = AtA.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 12, 12>> eigen(AtA);
  if (eigen.info() != Eigen::Success) return 0;
  // A second (near) null vector: coplanar world points (P + v pi^T fits as well as P).
  if (!(eigen.eigenvalues()(1) > 1e-10 * eigen.eigenvalues()(11))) return 0;
  const Eigen::Matrix<double, 12, 1> p = eigen.eigenvectors().col(0);
  Matrix34d P_normalised;
  P_normalised << p(0), p(1), p(2), p(3), p(4), p(5), p(6), p(7), p(8), p(9), p(10), p(11);

  Eigen::Matrix3d T_inverse = Eigen::Matrix3d::Identity();
  T_inverse(0, 0) = T_inverse(1, 1) = 1.0 / image_scale;
  T_inverse.topRightCorner<2, 1>() = image_centroid;
  Eigen::Matrix4d U = Eigen::Matrix4d::Identity();
  U.topLeftCorner<3, 3>() *= world_scale;
  U.topRightCorner<3, 1>() = -world_scale * world_centroid;
  Matrix34d P = T_inverse * P_normalised * U;
  const double det = P.leftCols<3>().determinant();
  const double row_norm = P.block<1, 3>(2, 0).norm();
  if (!(det != 0.0) || !(row_norm > 0.0) || !P.allFinite()) return 0;
  P *= (det > 0.0 ? 1.0 : -1.0) / row_norm;
  (*models)[0] = P;
  return 1;
}

void DltPoseEstimator::Residuals(const Sample* samples, int count, const Model& P, double* squared_residuals) {
  for (int i = 0; i < count; ++i) squared_residuals[i] = SquaredReprojectionError(P, samples[i]);
}

bool NearestPose(const Matrix34d& P, Eigen::Matrix3d* R, Eigen::Vector3d* t) {
  if (!P.allFinite() || !(P.leftCols<3>().determinant() > 0.0)) return false;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(P.leftCols<3>(), Eigen::ComputeFullU | Eigen::ComputeFullV);
  const double scale = svd.singularValues().mean();
  if (!(scale > 0.0)) return false;
  *R = svd.matrixU() * svd.matrixV().transpose();
  *t = P.col(3) / scale;
  return R->allFinite() && t->allFinite();
}

bool DecomposeProjection(const Matrix34d& P, Eigen::Matrix3d* K, Eigen::Matrix3d* R, Eigen::Vector3d* t) {
  const Eigen::Matrix3d M = P.leftCols<3>();
  if (!P.allFinite() || !(M.determinant() > 0.0)) return false;
  // RQ from QR: with the exchange matrix E, (E M)^T = Q U gives M = (E U^T E)(E Q^T), where
  // E U^T E is upper triangular and E Q^T orthogonal.
  Eigen::Matrix3d E = Eigen::Matrix3d::Zero();
  E(0, 2) = E(1, 1) = E(2, 0) = 1.0;
  const Eigen::HouseholderQR<Eigen::Matrix3d> qr((E * M).transpose());
  const Eigen::Matrix3d Q = qr.householderQ();
  const Eigen::Matrix3d upper = qr.matrixQR().triangularView<Eigen::Upper>();
  Eigen::Matrix3d K_raw = E * upper.transpose() * E;
  Eigen::Matrix3d R_raw = E * Q.transpose();
  for (int k = 0; k < 3; ++k) {
    if (K_raw(k, k) < 0.0) {
      K_raw.col(k) = -K_raw.col(k);
      R_raw.row(k) = -R_raw.row(k);
    }
  }
  if (!(K_raw(2, 2) > 0.0) || !(R_raw.determinant() > 0.0)) return false;
  *t = K_raw.triangularView<Eigen::Upper>().solve(P.col(3));
  *K = K_raw / K_raw(2, 2);
  *R = R_raw;
  return K->allFinite() && R->allFinite() && t->allFinite();
}

Status AbsolutePoseCamera::Check() const {
  if (!(focal > 0.0) || !std::isfinite(focal)) {
    return InvalidArgument("AbsolutePoseCamera.focal must be positive and finite, got " + std::to_string(focal));
  }
  if (!std::isfinite(cx) || !std::isfinite(cy) || !std::isfinite(k1) || !std::isfinite(k2)) {
    return InvalidArgument("AbsolutePoseCamera: cx, cy, k1 and k2 must be finite");
  }
  return Status::Ok();
}

Eigen::Vector2d AbsolutePoseCamera::Distort(const Eigen::Vector2d& normalised) const {
  const double r2 = normalised.squaredNorm();
  return focal * (1.0 + r2 * (k1 + r2 * k2)) * normalised + Eigen::Vector2d(cx, cy);
}

bool AbsolutePoseCamera::Undistort(const Eigen::Vector2d& pixel, Eigen::Vector2d* normalised) const {
  const Eigen::Vector2d q = (pixel - Eigen::Vector2d(cx, cy)) / focal;
  const double rho_d = q.norm();
  if (!std::isfinite(rho_d)) return false;
  if (rho_d == 0.0 || (k1 == 0.0 && k2 == 0.0)) {
    *normalised = q;
    return true;
  }
  double rho = rho_d;
  constexpr int kMaxIterations = 20;
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    const double r2 = rho * rho;
    const double g = rho * (1.0 + r2 * (k1 + r2 * k2)) - rho_d;
    const double dg = 1.0 + r2 * (3.0 * k1 + 5.0 * r2 * k2);
    if (!(dg > 0.0)) return false;
    const double step = g / dg;
    rho -= step;
    if (!(rho > 0.0)) return false;
    if (std::abs(step) <= 1e-14 * rho) break;
  }
  const double r2 = rho * rho;
  const double residual = rho * (1.0 + r2 * (k1 + r2 * k2)) - rho_d;
  if (!(std::abs(residual) <= 1e-10 * rho_d) || !(1.0 + r2 * (3.0 * k1 + 5.0 * r2 * k2) > 0.0)) return false;
  *normalised = q * (rho / rho_d);
  return true;
}

double SquaredPixelError(const AbsolutePoseCamera& camera, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                         const Eigen::Vector3d& world_point, const Eigen::Vector2d& pixel) {
  const Eigen::Vector3d X = R * world_point + t;
  if (!(X.z() > 0.0)) return std::numeric_limits<double>::max();
  const double squared = (camera.Distort(X.head<2>() / X.z()) - pixel).squaredNorm();
  return squared < std::numeric_limits<double>::infinity() ? squared : std::numeric_limits<double>::max();
}

Status PoseRefinementOptions::Check() const {
  if (!(loss_scale_px > 0.0) || !std::isfinite(loss_scale_px)) {
    return InvalidArgument("PoseRefinementOptions.loss_scale_px must be positive and finite, got " +
                           std::to_string(loss_scale_px));
  }
  if (lm.max_iterations < 0) {
    return InvalidArgument("PoseRefinementOptions.lm.max_iterations must be >= 0, got " +
                           std::to_string(lm.max_iterations));
  }
  if (!(lm.initial_trust_region_radius > 0.0) || !(lm.min_relative_decrease >= 0.0) || !(lm.min_diagonal > 0.0) ||
      !(lm.function_tolerance >= 0.0) || !(lm.gradient_tolerance >= 0.0) || !(lm.parameter_tolerance >= 0.0)) {
    return InvalidArgument(
        "PoseRefinementOptions.lm: tolerances must be >= 0, initial_trust_region_radius and min_diagonal > 0");
  }
  return Status::Ok();
}

NormalLmSummary RefineAbsolutePoseInPlace(const Eigen::Vector2d* points_px, const Eigen::Vector3d* world_points,
                                          const int* indices, int count, const PoseRefinementOptions& options,
                                          AbsolutePoseCamera* camera, Eigen::Matrix3d* R, Eigen::Vector3d* t) {
  if (options.refine_focal) {
    return SolvePoseRefinement<true>(points_px, world_points, indices, count, options, camera, R, t);
  }
  return SolvePoseRefinement<false>(points_px, world_points, indices, count, options, camera, R, t);
}

Result<NormalLmSummary> RefineAbsolutePose(const std::vector<Eigen::Vector2d>& points_px,
                                           const std::vector<Eigen::Vector3d>& world_points,
                                           const std::vector<int>& indices, const PoseRefinementOptions& options,
                                           AbsolutePoseCamera* camera, Eigen::Matrix3d* R, Eigen::Vector3d* t) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  RECONAR_RETURN_IF_ERROR(camera->Check());
  RECONAR_RETURN_IF_ERROR(CheckInputSizes(points_px, world_points, "RefineAbsolutePose"));
  if (indices.size() < 4) {
    return InvalidArgument("RefineAbsolutePose: " + std::to_string(indices.size()) +
                           " correspondences, need at least 4");
  }
  if (!R->allFinite() || !t->allFinite()) return InvalidArgument("RefineAbsolutePose: the initial pose is not finite");
  for (int i : indices) {
    if (i < 0 || static_cast<size_t>(i) >= points_px.size()) {
      return InvalidArgument("RefineAbsolutePose: index " + std::to_string(i) + " out of range [0, " +
                             std::to_string(points_px.size()) + ")");
    }
    if (!points_px[i].allFinite() || !world_points[i].allFinite()) {
      return InvalidArgument("RefineAbsolutePose: correspondence " + std::to_string(i) + " is not finite");
    }
    if (!((*R * world_points[i] + *t).z() > 0.0)) {
      return InvalidArgument("RefineAbsolutePose: world point " + std::to_string(i) +
                             " lies behind the initial camera");
    }
  }
  const NormalLmSummary summary = RefineAbsolutePoseInPlace(points_px.data(), world_points.data(), indices.data(),
                                                            static_cast<int>(indices.size()), options, camera, R, t);
  if (summary.termination == NormalLmSummary::Termination::kNumericFailure) {
    return NumericFailure("RefineAbsolutePose: the initial cost or normal equations are not finite");
  }
  return summary;
}

Status AbsolutePoseOptions::Check() const {
  if (!(max_error_px > 0.0) || !std::isfinite(max_error_px)) {
    return InvalidArgument("AbsolutePoseOptions.max_error_px must be positive and finite, got " +
                           std::to_string(max_error_px));
  }
  if (min_inliers < P3PEstimator::kMinSamples + 1) {
    return InvalidArgument("AbsolutePoseOptions.min_inliers must be >= 4, got " + std::to_string(min_inliers));
  }
  RansacOptions ransac_checked = ransac;
  ransac_checked.max_residual = 1.0;  // replaced by max_error_px / focal
  RECONAR_RETURN_IF_ERROR(ransac_checked.Check());
  return refinement.Check();
}

const char* AbsolutePoseOutcomeName(AbsolutePoseResult::Outcome outcome) {
  switch (outcome) {
    case AbsolutePoseResult::Outcome::kSuccess: return "success";
    case AbsolutePoseResult::Outcome::kTooFewCorrespondences: return "too few correspondences";
    case AbsolutePoseResult::Outcome::kNoModel: return "no model";
    case AbsolutePoseResult::Outcome::kTooFewInliers: return "too few inliers";
  }
  return "unknown";
}

Result<AbsolutePoseResult> EstimateAbsolutePose(const std::vector<Eigen::Vector2d>& points_px,
                                                const std::vector<Eigen::Vector3d>& world_points,
                                                const AbsolutePoseCamera& camera,
                                                const AbsolutePoseOptions& options) {
  RECONAR_RETURN_IF_ERROR(camera.Check());
  RECONAR_RETURN_IF_ERROR(options.Check());
  RECONAR_RETURN_IF_ERROR(CheckInputSizes(points_px, world_points, "EstimateAbsolutePose"));

  std::vector<PoseCorrespondence> samples;
  std::vector<int> sample_to_input;
  samples.reserve(points_px.size());
  sample_to_input.reserve(points_px.size());
  for (size_t i = 0; i < points_px.size(); ++i) {
    Eigen::Vector2d normalised;
    if (!points_px[i].allFinite() || !world_points[i].allFinite() || !camera.Undistort(points_px[i], &normalised)) {
      continue;
    }
    samples.push_back(PoseCorrespondence{normalised, world_points[i]});
    sample_to_input.push_back(static_cast<int>(i));
  }

  AbsolutePoseResult result;
  result.focal = camera.focal;
  const int needed = std::max(options.min_inliers, P3PEstimator::kMinSamples + 1);
  if (TooFewCorrespondences(static_cast<int>(samples.size()), static_cast<int>(points_px.size()), needed, &result)) {
    return result;
  }

  RansacOptions ransac = options.ransac;
  ransac.max_residual = options.max_error_px / camera.focal;
  RECONAR_ASSIGN_OR_RETURN(const auto report, (Ransac<P3PEstimator, DltPoseEstimator>::Run(samples, ransac)));
  result.ransac_iterations = report.iterations;
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  if (report.status != RansacStatus::kSuccess) {
    NoModel("every minimal sample was degenerate (collinear world points?) or gave no pose with the points in front "
            "of the camera",
            report.iterations, &result);
    return result;
  }
  if (!NearestPose(report.model, &R, &t)) {
    NoModel("the best model is not a valid camera", report.iterations, &result);
    return result;
  }
  FinishPose(points_px, world_points, camera, options, options.refine_focal, R, t,
             MaskToIndices(report.inlier_mask, sample_to_input), &result);
  return result;
}

Result<AbsolutePoseResult> EstimateAbsolutePoseUnknownFocal(const std::vector<Eigen::Vector2d>& points_px,
                                                            const std::vector<Eigen::Vector3d>& world_points,
                                                            const AbsolutePoseCamera& camera,
                                                            const AbsolutePoseOptions& options) {
  RECONAR_RETURN_IF_ERROR(camera.Check());
  RECONAR_RETURN_IF_ERROR(options.Check());
  RECONAR_RETURN_IF_ERROR(CheckInputSizes(points_px, world_points, "EstimateAbsolutePoseUnknownFocal"));

  // Centred pixels scaled by the prior focal: P = K' [R | t] with K' ~ diag(f / prior, f / prior, 1).
  std::vector<PoseCorrespondence> samples;
  std::vector<int> sample_to_input;
  samples.reserve(points_px.size());
  sample_to_input.reserve(points_px.size());
  const Eigen::Vector2d centre(camera.cx, camera.cy);
  for (size_t i = 0; i < points_px.size(); ++i) {
    if (!points_px[i].allFinite() || !world_points[i].allFinite()) continue;
    samples.push_back(PoseCorrespondence{(points_px[i] - centre) / camera.focal, world_points[i]});
    sample_to_input.push_back(static_cast<int>(i));
  }

  AbsolutePoseResult result;
  result.focal = camera.focal;
  const int needed = std::max(options.min_inliers, DltPoseEstimator::kMinSamples + 1);
  if (TooFewCorrespondences(static_cast<int>(samples.size()), static_cast<int>(points_px.size()), needed, &result)) {
    return result;
  }

  RansacOptions ransac = options.ransac;
  ransac.max_residual = options.max_error_px / camera.focal;
  RECONAR_ASSIGN_OR_RETURN(const auto report, Ransac<DltPoseEstimator>::Run(samples, ransac));
  result.ransac_iterations = report.iterations;
  if (report.status != RansacStatus::kSuccess) {
    NoModel("every minimal sample was degenerate (coplanar or collinear world points?) or gave no camera with the "
            "points in front of it",
            report.iterations, &result);
    return result;
  }
  Eigen::Matrix3d K, R;
  Eigen::Vector3d t;
  if (!DecomposeProjection(report.model, &K, &R, &t)) {
    NoModel("the best projection matrix is not a finite camera", report.iterations, &result);
    return result;
  }
  AbsolutePoseCamera estimated = camera;
  estimated.focal = camera.focal * 0.5 * (K(0, 0) + K(1, 1));
  if (!(estimated.focal > 0.0) || !std::isfinite(estimated.focal)) {
    NoModel("the decomposed focal length is not positive", report.iterations, &result);
    return result;
  }
  FinishPose(points_px, world_points, estimated, options, /*refine_focal=*/true, R, t,
             MaskToIndices(report.inlier_mask, sample_to_input), &result);
  return result;
}

}  // namespace reconar
