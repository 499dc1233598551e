#include "core/optim/bundle_adjuster.h"

#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <memory>
#include <utility>

#include "core/base/thread_pool.h"
#include "core/math/lm_loop.h"
#include "core/optim/bal_camera_model.h"
#include "core/optim/radial_camera_model.h"
#include "core/optim/symmetric_block_system.h"

namespace reconar {
namespace {

struct BalModel {
  using Problem = BalProblem;
  static bool Project(const double* camera, const double* point, double* predicted,
                      double* jac_camera, double* jac_point) {
    return ProjectBal(camera, point, predicted, jac_camera, jac_point);
  }
};
struct RadialModel {
  using Problem = RadialProblem;
  static bool Project(const double* camera, const double* point, double* predicted,
                      double* jac_camera, double* jac_point) {
    return ProjectRadial(camera, point, predicted, jac_camera, jac_point);
  }
};

constexpr int kP = 3;
using Mat33 = Eigen::Matrix<double, kP, kP>;
using Mat23 = Eigen::Matrix<double, 2, kP, Eigen::RowMajor>;
using Vec3 = Eigen::Vector3d;
// The 9x9 block products below use lazyProduct: with 9 + 9 + depth >= 20 Eigen would otherwise
// route these fixed-size products through its general (blocked GEMM) kernel, which costs more
// than the arithmetic at this size.

// Observations grouped by camera or by point (compressed rows).
struct Grouping {
  std::vector<int> offsets;  // size groups + 1
  std::vector<int> items;    // observation indices

  void Build(int num_groups, const std::vector<BalObservation>& obs, bool by_camera) {
    offsets.assign(static_cast<size_t>(num_groups) + 1, 0);
    for (const BalObservation& o : obs)
      ++offsets[static_cast<size_t>(by_camera ? o.camera : o.point) + 1];
    for (int g = 0; g < num_groups; ++g) offsets[g + 1] += offsets[g];
    items.resize(obs.size());
    std::vector<int> fill(offsets.begin(), offsets.end() - 1);
    for (size_t k = 0; k < obs.size(); ++k) {
      const int g = by_camera ? obs[k].camera : obs[k].point;
      items[static_cast<size_t>(fill[g]++)] = static_cast<int>(k);
    }
  }
};

// Residual rows of a point anchor (bal_problem.h), two per solver observation: part 0 the x and
// y components of weight * ((R(w) X + t) / s - local), part 1 its z component and a zero row. The
// Jacobians, when asked for, are 2 x CameraSize and 2 x 3, row-major.
template <int CameraSize>
void AnchorResidual(const PointAnchor& anchor, int part, const double* frame, const double* point, double* residual,
                    double* jac_frame, double* jac_point) {
  const Eigen::Map<const Eigen::Vector3d> w(frame), x(point);
  const AngleAxisRotation rotation(w, x);
  const double scale = anchor.weight / frame[6];  // d residual / d (R X + t)
  const Eigen::Vector3d in_frame = rotation.rx + Eigen::Map<const Eigen::Vector3d>(frame + 3);
  const Eigen::Vector3d r = scale * in_frame - anchor.weight * Eigen::Map<const Eigen::Vector3d>(anchor.local);
  const int first = 2 * part, rows = part == 0 ? 2 : 1;
  residual[0] = r[first];
  residual[1] = part == 0 ? r[1] : 0.0;
  if (jac_frame != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, CameraSize, Eigen::RowMajor>> jc(jac_frame);
    jc.setZero();
    jc.block(0, 0, rows, 3) = scale * rotation.JacobianWrtAngleAxis().middleRows(first, rows);
    jc.block(0, 3, rows, 3) = scale * Eigen::Matrix3d::Identity().middleRows(first, rows);
    jc.block(0, 6, rows, 1) = -(scale / frame[6]) * in_frame.segment(first, rows);
  }
  if (jac_point != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> jp(jac_point);
    jp.setZero();
    jp.topRows(rows) = scale * rotation.Matrix().middleRows(first, rows);
  }
}

// One solve. Every buffer is sized in the constructor; the iteration loop does not allocate.
template <typename Model>
class Solver {
  using Problem = typename Model::Problem;
  static constexpr int kC = Problem::kCameraSize;
  using Mat99 = Eigen::Matrix<double, kC, kC>;
  using Mat93 = Eigen::Matrix<double, kC, kP>;
  using Mat29 = Eigen::Matrix<double, 2, kC, Eigen::RowMajor>;
  using Vec9 = Eigen::Matrix<double, kC, 1>;
  // A camera block is the pose (angle-axis, translation) and then the intrinsics, which cameras
  // may share (BundleAdjustmentConstancy::intrinsics_group).
  static constexpr int kPose = 6;
  static constexpr int kI = kC - kPose;
  using MatI3 = Eigen::Matrix<double, kI, kP>;
  using MatII = Eigen::Matrix<double, kI, kI>;
  using VecI = Eigen::Matrix<double, kI, 1>;
  // A camera pair of the reduced system (BuildReducedSystem) and a camera's coupling with a group.
  struct CameraPair {
    int camera = 0;           // i2
    int first = 0, last = 0;  // its observation pairs: pair_observations_[first, last)
    SymmetricBlockSystem::Block block;
  };
  struct Border {
    int group = 0;
    SymmetricBlockSystem::Block block;
  };

 public:
  Solver(const BundleAdjustmentOptions& options, const BundleAdjustmentConstancy& constancy,
         Problem* problem)
      : opt_(options), problem_(problem) {
    constant_parameters_ = constancy.constant_camera_parameters;
    nc_ = problem->num_cameras();
    np_ = problem->num_points();
    num_projections_ = static_cast<int>(problem->observations.size());
    obs_ = &problem->observations;
    if (!problem->point_anchors.empty()) {
      // Each anchor joins the observations as two (its rows x, y and z), so that the Schur
      // complement couples its frame with the cameras that see its point like any observer.
      observations_with_anchors_ = problem->observations;
      for (const PointAnchor& anchor : problem->point_anchors) {
        for (int part = 0; part < 2; ++part) observations_with_anchors_.push_back({anchor.frame, anchor.point, 0.0, 0.0, 1.0});
      }
      obs_ = &observations_with_anchors_;
    }
    no_ = static_cast<int>(obs_->size());
    const auto nobs = static_cast<size_t>(no_);
    const_cam_.assign(static_cast<size_t>(nc_), 0);
    const_pt_.assign(static_cast<size_t>(np_), 0);
    if (!constancy.constant_cameras.empty()) const_cam_ = constancy.constant_cameras;
    if (!constancy.constant_points.empty()) const_pt_ = constancy.constant_points;
    by_cam_.Build(nc_, *obs_, true);
    by_pt_.Build(np_, *obs_, false);
    residual_.resize(2 * nobs);
    rho_.resize(nobs);
    jc_.resize(nobs);
    jp_.resize(nobs);
    w_.resize(nobs);
    y_.resize(nobs);
    u_.resize(static_cast<size_t>(nc_));
    v_.resize(static_cast<size_t>(np_));
    vinv_.resize(static_cast<size_t>(np_));
    gc_.resize(static_cast<size_t>(nc_));
    gp_.resize(static_cast<size_t>(np_));
    dc_diag_.resize(static_cast<size_t>(nc_));
    dp_diag_.resize(static_cast<size_t>(np_));
    step_p_.resize(static_cast<size_t>(np_));
    step_c_.setZero(kC * nc_);
    for (Mat93& y : y_) y.setZero();
    BuildReducedSystem(constancy.intrinsics_group);
    cand_cameras_ = problem->cameras;
    cand_points_ = problem->points;
    const int threads = ThreadPool::ResolveThreadCount(options.num_threads);
    if (threads > 1) pool_ = std::make_unique<ThreadPool>(threads);
  }

  // The RunLm problem (core/math/lm_loop.h). The damping lambda = 1 / radius multiplies the
  // clamped diagonals; a trial step is judged by its cost alone and linearised once accepted.
  bool Linearize() {
    BuildNormalEquations();
    return std::isfinite(cost_);
  }
  double Cost() const { return cost_; }
  double MaxGradient() const {
    double m = 0.0;
    for (const Vec9& g : gc_) m = std::max(m, g.cwiseAbs().maxCoeff());
    for (const Vec3& g : gp_) m = std::max(m, g.cwiseAbs().maxCoeff());
    return m;
  }

  BundleAdjustmentOptions::LinearSolver linear_solver() const { return linear_solver_; }
  int reduced_unknowns() const { return system_.size(); }

  bool SolveStep(double radius) {
    lambda_ = 1.0 / radius;
    return SolveSchur(lambda_);
  }
  double StepNorm() const { return std::sqrt(step_c_.squaredNorm() + StepPointSquaredNorm()); }
  double StateNorm() const { return std::sqrt(SquaredNorm(problem_->cameras) + SquaredNorm(problem_->points)); }
  // L(0) - L(dx) for the model L(dx) = 1/2 |r + J dx|^2. Since (J^T J + lambda D) dx = -g,
  // this equals 1/2 (lambda dx^T D dx - g^T dx).
  double PredictedReduction() const {
    double s = 0.0;
    for (int i = 0; i < nc_; ++i) {
      const auto d = step_c_.segment<kC>(kC * i);
      s += lambda_ * d.dot(dc_diag_[static_cast<size_t>(i)].cwiseProduct(d)) - gc_[static_cast<size_t>(i)].dot(d);
    }
    for (int j = 0; j < np_; ++j) {
      const Vec3& d = step_p_[static_cast<size_t>(j)];
      s += lambda_ * d.dot(dp_diag_[static_cast<size_t>(j)].cwiseProduct(d)) - gp_[static_cast<size_t>(j)].dot(d);
    }
    return 0.5 * s;
  }

  bool EvaluateStep(double* cost) {
    ApplyStep();
    *cost = EvaluateCost(cand_cameras_, cand_points_);
    return true;
  }
  void AcceptStep() {
    problem_->cameras.swap(cand_cameras_);
    problem_->points.swap(cand_points_);
    BuildNormalEquations();
  }

 private:
  static double SquaredNorm(const std::vector<double>& v) {
    double s = 0.0;
    for (double x : v) s += x * x;
    return s;
  }
  double StepPointSquaredNorm() const {
    double s = 0.0;
    for (const Vec3& d : step_p_) s += d.squaredNorm();
    return s;
  }

  const PointAnchor& Anchor(int k) const {
    return problem_->point_anchors[static_cast<size_t>((k - num_projections_) / 2)];
  }
  int AnchorPart(int k) const { return (k - num_projections_) % 2; }

  void ZeroConstantColumns(const BalObservation& o, Mat29* jc, Mat23* jp) const {
    if (const_cam_[static_cast<size_t>(o.camera)]) {
      jc->setZero();
    } else {
      for (int m : constant_parameters_) jc->col(m).setZero();
    }
    if (const_pt_[static_cast<size_t>(o.point)]) jp->setZero();
  }

  // Runs fn(begin, end) over [0, n) in chunks, on the pool when there is one. The job lives in
  // members so the std::function wrapper holds only `this` (no allocation).
  template <typename Fn>
  void ParallelRange(int n, int chunk, const Fn& fn) {
    if (!pool_ || n <= chunk) {
      fn(0, n);
      return;
    }
    job_ = [](void* ctx, int b, int e) { (*static_cast<const Fn*>(ctx))(b, e); };
    job_ctx_ = const_cast<void*>(static_cast<const void*>(&fn));
    job_n_ = n;
    job_chunk_ = chunk;
    const size_t chunks = static_cast<size_t>((n + chunk - 1) / chunk);
    pool_->ParallelFor(0, chunks, runner_);
  }
  void RunChunk(size_t c) {
    const int b = static_cast<int>(c) * job_chunk_;
    job_(job_ctx_, b, std::min(job_n_, b + job_chunk_));
  }

  // Residuals, robust weights, Jacobians, cost, and the blocks of J^T J and J^T r.
  void BuildNormalEquations() {
    const std::vector<BalObservation>& obs = *obs_;
    ParallelRange(no_, 512, [this, &obs](int begin, int end) {
      for (int k = begin; k < end; ++k) {
        const BalObservation& o = obs[static_cast<size_t>(k)];
        double* r = &residual_[2 * static_cast<size_t>(k)];
        Mat29& jc = jc_[static_cast<size_t>(k)];
        Mat23& jp = jp_[static_cast<size_t>(k)];
        if (k >= num_projections_) {
          AnchorResidual<kC>(Anchor(k), AnchorPart(k), problem_->camera(o.camera), problem_->point(o.point), r,
                             jc.data(), jp.data());
          rho_[static_cast<size_t>(k)] = r[0] * r[0] + r[1] * r[1];
          ZeroConstantColumns(o, &jc, &jp);
          w_[static_cast<size_t>(k)].noalias() = jc.transpose() * jp;
          continue;
        }
        if (!Model::Project(problem_->camera(o.camera), problem_->point(o.point), r, jc.data(),
                        jp.data())) {
          rho_[static_cast<size_t>(k)] = std::numeric_limits<double>::infinity();
          continue;
        }
        r[0] -= o.x;
        r[1] -= o.y;
        double rho, drho;
        opt_.loss.Evaluate(o.weight * o.weight * (r[0] * r[0] + r[1] * r[1]), &rho, &drho);
        rho_[static_cast<size_t>(k)] = rho;
        if (opt_.loss.type != LossType::kTrivial || o.weight != 1.0) {
          const double sw = o.weight * std::sqrt(drho);
          r[0] *= sw;
          r[1] *= sw;
          jc *= sw;
          jp *= sw;
        }
        ZeroConstantColumns(o, &jc, &jp);
        w_[static_cast<size_t>(k)].noalias() = jc.transpose() * jp;
      }
    });
    cost_ = 0.0;
    for (double rho : rho_) cost_ += rho;
    cost_ *= 0.5;
    if (!std::isfinite(cost_)) return;
    ParallelRange(nc_, 4, [this](int begin, int end) {
      for (int i = begin; i < end; ++i) {
        Mat99& u = u_[static_cast<size_t>(i)];
        Vec9& g = gc_[static_cast<size_t>(i)];
        u.setZero();
        g.setZero();
        for (int q = by_cam_.offsets[i]; q < by_cam_.offsets[i + 1]; ++q) {
          const auto k = static_cast<size_t>(by_cam_.items[static_cast<size_t>(q)]);
          u.noalias() += jc_[k].transpose().lazyProduct(jc_[k]);
          g.noalias() += jc_[k].transpose() * Eigen::Map<const Eigen::Vector2d>(&residual_[2 * k]);
        }
        dc_diag_[static_cast<size_t>(i)] =
            u.diagonal().cwiseMax(opt_.min_diagonal).cwiseMin(opt_.max_diagonal);
      }
    });
    ParallelRange(np_, 256, [this](int begin, int end) {
      for (int j = begin; j < end; ++j) {
        Mat33& v = v_[static_cast<size_t>(j)];
        Vec3& g = gp_[static_cast<size_t>(j)];
        v.setZero();
        g.setZero();
        for (int q = by_pt_.offsets[j]; q < by_pt_.offsets[j + 1]; ++q) {
          const auto k = static_cast<size_t>(by_pt_.items[static_cast<size_t>(q)]);
          v.noalias() += jp_[k].transpose() * jp_[k];
          g.noalias() += jp_[k].transpose() * Eigen::Map<const Eigen::Vector2d>(&residual_[2 * k]);
        }
        dp_diag_[static_cast<size_t>(j)] =
            v.diagonal().cwiseMax(opt_.min_diagonal).cwiseMin(opt_.max_diagonal);
        SumGroupIntrinsicsBlocks(j);
      }
    });
  }

  // Solves (J^T J + lambda D) dx = -J^T r by eliminating the points: with U, V, W the camera,
  // point and cross blocks, S = U - W V^-1 W^T, S dc = -gc + W V^-1 gp, then
  // dp = V^-1 (-gp - W^T dc). Shared intrinsics replace the camera parameters x by x = P y, P a
  // 0/1 matrix mapping each shared parameter to its group's column, and the system by
  // P^T S P y = P^T b, assembled here directly in y. False if its factorisation fails.
  bool SolveSchur(double lambda) {
    ParallelRange(np_, 256, [this, lambda](int begin, int end) {
      for (int j = begin; j < end; ++j) {
        Mat33& vinv = vinv_[static_cast<size_t>(j)];
        if (const_pt_[static_cast<size_t>(j)]) {
          vinv.setZero();
          continue;
        }
        Mat33 v = v_[static_cast<size_t>(j)];
        v.diagonal() += lambda * dp_diag_[static_cast<size_t>(j)];
        vinv = v.inverse();  // closed-form 3x3 inverse (cofactors)
        for (int q = by_pt_.offsets[j]; q < by_pt_.offsets[j + 1]; ++q) {
          const auto k = static_cast<size_t>(by_pt_.items[static_cast<size_t>(q)]);
          y_[k].noalias() = w_[k] * vinv;
        }
        for (int e = point_groups_.offsets[j]; e < point_groups_.offsets[j + 1]; ++e) {
          zv_[static_cast<size_t>(e)].noalias() = z_[static_cast<size_t>(e)] * vinv;
        }
      }
    });
    system_.SetZero();
    ParallelRange(nc_, 1, [this, lambda](int begin, int end) {
      for (int i = begin; i < end; ++i) {
        if (const_cam_[static_cast<size_t>(i)]) continue;
        if (own_size_[static_cast<size_t>(i)] == kC) {
          AddCameraRows<kC>(i, lambda);
        } else {
          AddCameraRows<kPose>(i, lambda);
        }
      }
    });
    AddGroupBlocks(lambda);
    if (!system_.Factorize()) return false;
    system_.Solve();
    for (int i = 0; i < nc_; ++i) {
      if (const_cam_[static_cast<size_t>(i)]) continue;
      auto step = step_c_.segment<kC>(kC * i);
      const int own = own_size_[static_cast<size_t>(i)];
      step.head(own) = system_.Solution(camera_block_[static_cast<size_t>(i)]);
      const int g = group_[static_cast<size_t>(i)];
      if (g >= 0) step.template tail<kI>() = system_.Solution(GroupBlock(g));
    }
    if (!step_c_.allFinite()) return false;
    const std::vector<BalObservation>& obs = *obs_;
    ParallelRange(np_, 256, [this, &obs](int begin, int end) {
      for (int j = begin; j < end; ++j) {
        Vec3 b = -gp_[static_cast<size_t>(j)];
        for (int q = by_pt_.offsets[j]; q < by_pt_.offsets[j + 1]; ++q) {
          const auto k = static_cast<size_t>(by_pt_.items[static_cast<size_t>(q)]);
          b.noalias() -= w_[k].transpose() * step_c_.segment<kC>(kC * obs[k].camera);
        }
        step_p_[static_cast<size_t>(j)].noalias() = vinv_[static_cast<size_t>(j)] * b;
      }
    });
    return true;
  }

  // The rows of free camera i's block (its first R parameters: the pose, and its intrinsics
  // when it shares none): its diagonal block, the blocks coupling it with the cameras i2 <= i
  // that share a point with it, and those coupling it with the intrinsics groups. Every block
  // written here is written by no other camera's task.
  template <int R>
  void AddCameraRows(int i, double lambda) {
    const std::vector<BalObservation>& obs = *obs_;
    const int g = group_[static_cast<size_t>(i)];
    Mat99 sii = u_[static_cast<size_t>(i)];
    sii.diagonal() += lambda * dc_diag_[static_cast<size_t>(i)];
    for (int m : constant_parameters_) sii(m, m) = 1.0;  // row and column are zero
    system_.Add(diagonal_blocks_[static_cast<size_t>(i)], sii.template topLeftCorner<R, R>());
    const auto borders_begin = borders_.begin() + border_offsets_[static_cast<size_t>(i)];
    const auto borders_end = borders_.begin() + border_offsets_[static_cast<size_t>(i) + 1];
    const auto border_of = [borders_begin, borders_end](int group) -> const SymmetricBlockSystem::Block& {
      return std::find_if(borders_begin, borders_end, [group](const Border& b) { return b.group == group; })->block;
    };
    if (g >= 0) system_.Add(border_of(g), sii.template block<R, kI>(0, kPose));
    // S(i, i2) -= sum_j Y_ij W_i2j^T over the two cameras' own parameters, a pair at a time.
    for (int p = pair_offsets_[static_cast<size_t>(i)]; p < pair_offsets_[static_cast<size_t>(i) + 1]; ++p) {
      const CameraPair& pair = pairs_[static_cast<size_t>(p)];
      if (own_size_[static_cast<size_t>(pair.camera)] == kC) {
        SubtractPairBlock<R, kC>(pair);
      } else {
        SubtractPairBlock<R, kPose>(pair);
      }
    }
    Vec9 rhs = -gc_[static_cast<size_t>(i)];
    for (int q = by_cam_.offsets[i]; q < by_cam_.offsets[i + 1]; ++q) {
      const auto k = static_cast<size_t>(by_cam_.items[static_cast<size_t>(q)]);
      const int j = obs[k].point;
      if (const_pt_[static_cast<size_t>(j)]) continue;
      rhs.noalias() += y_[k] * gp_[static_cast<size_t>(j)];
      // The same over the shared intrinsics of the cameras seeing j, summed per group: -Y_ij Z_jg^T.
      for (int e = point_groups_.offsets[j]; e < point_groups_.offsets[j + 1]; ++e) {
        system_.SubtractProduct(border_of(point_groups_.items[static_cast<size_t>(e)]),
                                y_[k].template topRows<R>(), z_[static_cast<size_t>(e)]);
      }
    }
    system_.Rhs(camera_block_[static_cast<size_t>(i)]) = rhs.template head<R>();
    if (g >= 0) group_rhs_[static_cast<size_t>(i)] = rhs.template tail<kI>();
  }

  // Sums Y_ij W_i2j^T over the points the pair shares, in the orientation the block is stored in,
  // and subtracts it from the block once.
  template <int R, int C>
  void SubtractPairBlock(const CameraPair& pair) {
    const auto first = pair_observations_.begin() + pair.first;
    const auto last = pair_observations_.begin() + pair.last;
    if (pair.block.transposed) {
      Eigen::Matrix<double, C, R> sum = Eigen::Matrix<double, C, R>::Zero();
      for (auto it = first; it != last; ++it) {
        sum.noalias() += w_[static_cast<size_t>(it->second)].template topRows<C>().lazyProduct(
            y_[static_cast<size_t>(it->first)].template topRows<R>().transpose());
      }
      system_.SubtractStored(pair.block, sum);
    } else {
      Eigen::Matrix<double, R, C> sum = Eigen::Matrix<double, R, C>::Zero();
      for (auto it = first; it != last; ++it) {
        sum.noalias() += y_[static_cast<size_t>(it->first)].template topRows<R>().lazyProduct(
            w_[static_cast<size_t>(it->second)].template topRows<C>().transpose());
      }
      system_.SubtractStored(pair.block, sum);
    }
  }

  // The blocks among the intrinsics groups and their right-hand sides: the sums of the
  // cameras' own intrinsic blocks and, per point, -Z_jg V_j^-1 Z_jg2^T.
  void AddGroupBlocks(double lambda) {
    if (num_groups_ == 0) return;
    for (int i = 0; i < nc_; ++i) {
      const int g = group_[static_cast<size_t>(i)];
      if (g < 0) continue;
      MatII d = u_[static_cast<size_t>(i)].template bottomRightCorner<kI, kI>();
      d.diagonal() += lambda * dc_diag_[static_cast<size_t>(i)].template tail<kI>();
      system_.Add(system_.Find(GroupBlock(g), GroupBlock(g)), d);
      system_.Rhs(GroupBlock(g)) += group_rhs_[static_cast<size_t>(i)];
    }
    for (int j = 0; j < np_; ++j) {
      for (int e = point_groups_.offsets[j]; e < point_groups_.offsets[j + 1]; ++e) {
        const int g = point_groups_.items[static_cast<size_t>(e)];
        for (int e2 = e; e2 < point_groups_.offsets[j + 1]; ++e2) {
          const int g2 = point_groups_.items[static_cast<size_t>(e2)];
          system_.SubtractProduct(system_.Find(GroupBlock(g), GroupBlock(g2)), zv_[static_cast<size_t>(e)],
                                  z_[static_cast<size_t>(e2)]);
        }
      }
    }
    for (int m : constant_parameters_) {
      if (m < kPose) continue;
      for (int g = 0; g < num_groups_; ++g) system_.SetDiagonal(GroupBlock(g), m - kPose, 1.0);
    }
  }

  // Z_jg = sum of W_ij's intrinsic rows over the cameras i of group g that see point j.
  void SumGroupIntrinsicsBlocks(int j) {
    const int first = point_groups_.offsets[j], last = point_groups_.offsets[j + 1];
    if (first == last) return;
    for (int e = first; e < last; ++e) z_[static_cast<size_t>(e)].setZero();
    const std::vector<BalObservation>& obs = *obs_;
    for (int q = by_pt_.offsets[j]; q < by_pt_.offsets[j + 1]; ++q) {
      const auto k = static_cast<size_t>(by_pt_.items[static_cast<size_t>(q)]);
      const int g = group_[static_cast<size_t>(obs[k].camera)];
      if (g < 0) continue;
      const auto it = std::lower_bound(point_groups_.items.begin() + first, point_groups_.items.begin() + last, g);
      z_[static_cast<size_t>(it - point_groups_.items.begin())] += w_[k].template bottomRows<kI>();
    }
  }

  int GroupBlock(int g) const { return num_free_cameras_ + g; }

  // The unknowns of the reduced system, in blocks: one per free camera (its pose, and its own
  // intrinsics when it shares none), then one per intrinsics group (the shared intrinsics,
  // indices kPose.. of the camera block). Constant cameras have none (their step is zero); a
  // constant parameter keeps its unknown with a unit diagonal. The dense storage keeps the free
  // cameras in their order; the sparse one orders them by AMD on the camera graph, the groups
  // last. The pattern, where each block is stored, the observation pairs behind each camera pair
  // and the symbolic factorisation are all set up here, before the iterations.
  void BuildReducedSystem(const std::vector<int>& groups) {
    const std::vector<BalObservation>& obs = *obs_;
    camera_block_.assign(static_cast<size_t>(nc_), -1);
    group_.assign(static_cast<size_t>(nc_), -1);
    own_size_.assign(static_cast<size_t>(nc_), kC);
    std::vector<int> group_of_id;  // caller's group id -> ours
    std::vector<int> block_sizes;
    for (int i = 0; i < nc_; ++i) {
      if (const_cam_[static_cast<size_t>(i)]) continue;
      camera_block_[static_cast<size_t>(i)] = num_free_cameras_++;
      const int id = groups.empty() ? -1 : groups[static_cast<size_t>(i)];
      if (id < 0) {
        block_sizes.push_back(kC);
        continue;
      }
      if (static_cast<size_t>(id) >= group_of_id.size()) group_of_id.resize(static_cast<size_t>(id) + 1, -1);
      int& g = group_of_id[static_cast<size_t>(id)];
      if (g < 0) g = num_groups_++;
      group_[static_cast<size_t>(i)] = g;
      own_size_[static_cast<size_t>(i)] = kPose;
      block_sizes.push_back(kPose);
    }
    block_sizes.insert(block_sizes.end(), static_cast<size_t>(num_groups_), kI);
    group_rhs_.assign(static_cast<size_t>(nc_), VecI::Zero());

    // Per free point, the groups of the free cameras that see it (and the groups coupled
    // through it).
    std::vector<std::pair<int, int>> coupled;
    point_groups_.offsets.assign(static_cast<size_t>(np_) + 1, 0);
    point_groups_.items.clear();
    for (int j = 0; j < np_; ++j) {
      const size_t first = point_groups_.items.size();
      for (int q = by_pt_.offsets[j]; q < by_pt_.offsets[j + 1] && !const_pt_[static_cast<size_t>(j)]; ++q) {
        const int g = group_[static_cast<size_t>(obs[static_cast<size_t>(by_pt_.items[static_cast<size_t>(q)])].camera)];
        if (g >= 0) point_groups_.items.push_back(g);
      }
      const auto begin = point_groups_.items.begin() + static_cast<std::ptrdiff_t>(first);
      std::sort(begin, point_groups_.items.end());
      point_groups_.items.erase(std::unique(begin, point_groups_.items.end()), point_groups_.items.end());
      point_groups_.offsets[static_cast<size_t>(j) + 1] = static_cast<int>(point_groups_.items.size());
      for (size_t e = first; e < point_groups_.items.size(); ++e) {
        for (size_t e2 = first; e2 < e; ++e2) {
          coupled.emplace_back(GroupBlock(point_groups_.items[e2]), GroupBlock(point_groups_.items[e]));
        }
      }
    }
    std::sort(coupled.begin(), coupled.end());
    coupled.erase(std::unique(coupled.begin(), coupled.end()), coupled.end());
    z_.resize(point_groups_.items.size());
    zv_.resize(point_groups_.items.size());

    // Per free camera i, the free cameras i2 <= i it shares free points with, each with the
    // observation pairs (k of i, k2 of i2) of those points, and the groups it is coupled with.
    pair_offsets_.assign(static_cast<size_t>(nc_) + 1, 0);
    border_offsets_.assign(static_cast<size_t>(nc_) + 1, 0);
    std::vector<std::array<int, 3>> shared;  // (i2, k, k2)
    std::vector<int> coupled_groups;
    for (int i = 0; i < nc_; ++i) {
      shared.clear();
      coupled_groups.clear();
      if (group_[static_cast<size_t>(i)] >= 0) coupled_groups.push_back(group_[static_cast<size_t>(i)]);
      for (int q = by_cam_.offsets[i]; q < by_cam_.offsets[i + 1] && !const_cam_[static_cast<size_t>(i)]; ++q) {
        const int k = by_cam_.items[static_cast<size_t>(q)];
        const int j = obs[static_cast<size_t>(k)].point;
        if (const_pt_[static_cast<size_t>(j)]) continue;
        for (int q2 = by_pt_.offsets[j]; q2 < by_pt_.offsets[j + 1]; ++q2) {
          const int k2 = by_pt_.items[static_cast<size_t>(q2)];
          const int i2 = obs[static_cast<size_t>(k2)].camera;
          if (i2 <= i && !const_cam_[static_cast<size_t>(i2)]) shared.push_back({i2, k, k2});
        }
        for (int e = point_groups_.offsets[j]; e < point_groups_.offsets[j + 1]; ++e) {
          coupled_groups.push_back(point_groups_.items[static_cast<size_t>(e)]);
        }
      }
      std::sort(shared.begin(), shared.end());
      for (size_t a = 0; a < shared.size();) {
        size_t b = a;
        while (b < shared.size() && shared[b][0] == shared[a][0]) {
          pair_observations_.emplace_back(shared[b][1], shared[b][2]);
          ++b;
        }
        CameraPair pair;
        pair.camera = shared[a][0];
        pair.last = static_cast<int>(pair_observations_.size());
        pair.first = pair.last - static_cast<int>(b - a);
        pairs_.push_back(pair);
        coupled.emplace_back(camera_block_[static_cast<size_t>(pair.camera)], camera_block_[static_cast<size_t>(i)]);
        a = b;
      }
      pair_offsets_[static_cast<size_t>(i) + 1] = static_cast<int>(pairs_.size());
      std::sort(coupled_groups.begin(), coupled_groups.end());
      coupled_groups.erase(std::unique(coupled_groups.begin(), coupled_groups.end()), coupled_groups.end());
      for (int g : coupled_groups) {
        borders_.push_back({g, {}});
        coupled.emplace_back(camera_block_[static_cast<size_t>(i)], GroupBlock(g));
      }
      border_offsets_[static_cast<size_t>(i) + 1] = static_cast<int>(borders_.size());
    }
    linear_solver_ = opt_.linear_solver;
    if (linear_solver_ == BundleAdjustmentOptions::LinearSolver::kAuto) {
      const SymmetricBlockSystem::Shape shape = SymmetricBlockSystem::ShapeOf(block_sizes, coupled);
      const bool sparse = shape.unknowns >= BundleAdjustmentOptions::kMinSparseUnknowns &&
                          shape.fill <= BundleAdjustmentOptions::kMaxSparseFill;
      linear_solver_ = sparse ? BundleAdjustmentOptions::LinearSolver::kSparseCholesky
                              : BundleAdjustmentOptions::LinearSolver::kDenseCholesky;
    }
    const bool sparse = linear_solver_ == BundleAdjustmentOptions::LinearSolver::kSparseCholesky;
    system_.Build(block_sizes, coupled, num_groups_,
                  sparse ? SymmetricBlockSystem::Storage::kSparse : SymmetricBlockSystem::Storage::kDense);
    diagonal_blocks_.resize(static_cast<size_t>(nc_));
    for (int i = 0; i < nc_; ++i) {
      const int block = camera_block_[static_cast<size_t>(i)];
      if (block < 0) continue;
      diagonal_blocks_[static_cast<size_t>(i)] = system_.Find(block, block);
      for (int p = pair_offsets_[static_cast<size_t>(i)]; p < pair_offsets_[static_cast<size_t>(i) + 1]; ++p) {
        CameraPair& pair = pairs_[static_cast<size_t>(p)];
        pair.block = system_.Find(block, camera_block_[static_cast<size_t>(pair.camera)]);
      }
      for (int b = border_offsets_[static_cast<size_t>(i)]; b < border_offsets_[static_cast<size_t>(i) + 1]; ++b) {
        borders_[static_cast<size_t>(b)].block = system_.Find(block, GroupBlock(borders_[static_cast<size_t>(b)].group));
      }
    }
  }

  void ApplyStep() {
    for (int i = 0; i < nc_ * kC; ++i) {
      cand_cameras_[static_cast<size_t>(i)] =
          problem_->cameras[static_cast<size_t>(i)] + step_c_[i];
    }
    for (int j = 0; j < np_; ++j) {
      for (int d = 0; d < kP; ++d) {
        const size_t idx = static_cast<size_t>(j) * kP + static_cast<size_t>(d);
        cand_points_[idx] = problem_->points[idx] + step_p_[static_cast<size_t>(j)][d];
      }
    }
  }

  double EvaluateCost(const std::vector<double>& cameras, const std::vector<double>& points) {
    const std::vector<BalObservation>& obs = *obs_;
    ParallelRange(no_, 512, [this, &obs, &cameras, &points](int begin, int end) {
      for (int k = begin; k < end; ++k) {
        const BalObservation& o = obs[static_cast<size_t>(k)];
        double r[2];
        double rho = std::numeric_limits<double>::infinity(), drho;
        if (k >= num_projections_) {
          AnchorResidual<kC>(Anchor(k), AnchorPart(k), cameras.data() + static_cast<size_t>(o.camera) * kC,
                             points.data() + static_cast<size_t>(o.point) * kP, r, nullptr, nullptr);
          rho = r[0] * r[0] + r[1] * r[1];
        } else if (Model::Project(cameras.data() + static_cast<size_t>(o.camera) * kC,
                       points.data() + static_cast<size_t>(o.point) * kP, r, nullptr, nullptr)) {
          r[0] -= o.x;
          r[1] -= o.y;
          opt_.loss.Evaluate(o.weight * o.weight * (r[0] * r[0] + r[1] * r[1]), &rho, &drho);
        }
        rho_[static_cast<size_t>(k)] = rho;
      }
    });
    double cost = 0.0;
    for (double rho : rho_) cost += rho;
    return 0.5 * cost;
  }

  const BundleAdjustmentOptions& opt_;
  Problem* problem_;
  std::vector<int> constant_parameters_;  // indices within every camera block
  int nc_ = 0, np_ = 0, no_ = 0;
  // The observations the solver works on: the problem's projections, then two per point anchor
  // (copied with them only when there are anchors).
  const std::vector<BalObservation>* obs_ = nullptr;
  std::vector<BalObservation> observations_with_anchors_;
  int num_projections_ = 0;
  std::vector<char> const_cam_, const_pt_;
  Grouping by_cam_, by_pt_;
  std::vector<double> residual_, rho_;
  std::vector<Mat29> jc_;
  std::vector<Mat23> jp_;
  std::vector<Mat93> w_, y_;  // W = Jc^T Jp and Y = W V^-1 per observation
  std::vector<Mat99> u_;
  std::vector<Mat33> v_, vinv_;
  std::vector<Vec9> gc_, dc_diag_;
  std::vector<Vec3> gp_, dp_diag_, step_p_;
  // The reduced system (BuildReducedSystem): per camera its block (-1 when constant), its
  // intrinsics group (-1 for none) and the size of its own part of the camera block (kPose or
  // kC); per point the groups of its free observers (sorted) with Z_jg and Z_jg V_j^-1.
  std::vector<int> camera_block_, group_, own_size_;
  int num_free_cameras_ = 0, num_groups_ = 0;
  struct {
    std::vector<int> offsets;  // size points + 1
    std::vector<int> items;    // group indices
  } point_groups_;
  std::vector<MatI3> z_, zv_;
  // Per free camera: where its diagonal block is stored; the cameras i2 <= i it shares points
  // with (pairs_[pair_offsets_[i] ..], by i2), each with its observation pairs (k of i, k2 of
  // i2) and where S(i, i2) is stored; the groups it is coupled with and where those blocks are.
  std::vector<SymmetricBlockSystem::Block> diagonal_blocks_;
  std::vector<int> pair_offsets_, border_offsets_;
  std::vector<CameraPair> pairs_;
  std::vector<std::pair<int, int>> pair_observations_;
  std::vector<Border> borders_;
  std::vector<VecI> group_rhs_;  // per grouped camera: the intrinsic rows of its right-hand side
  BundleAdjustmentOptions::LinearSolver linear_solver_ = BundleAdjustmentOptions::LinearSolver::kDenseCholesky;
  SymmetricBlockSystem system_;
  Eigen::VectorXd step_c_;
  std::vector<double> cand_cameras_, cand_points_;
  double cost_ = 0.0;
  double lambda_ = 0.0;  // damping of the last SolveStep

  std::unique_ptr<ThreadPool> pool_;
  void (*job_)(void*, int, int) = nullptr;
  void* job_ctx_ = nullptr;
  int job_n_ = 0, job_chunk_ = 1;
  const std::function<void(size_t, int)> runner_ = [this](size_t c, int) { RunChunk(c); };
};

}  // namespace

Status BundleAdjustmentOptions::Check() const {
  RECONAR_RETURN_IF_ERROR(LmOptions::Check().WithContext("BundleAdjustmentOptions"));
  if (!(max_diagonal >= min_diagonal)) {
    return InvalidArgument("BundleAdjustmentOptions: need 0 < min_diagonal <= max_diagonal");
  }
  if (!(loss.scale > 0.0)) return InvalidArgument("BundleAdjustmentOptions: loss.scale <= 0");
  return Status::Ok();
}

namespace {

template <typename Model>
double CostImpl(const typename Model::Problem& problem, const RobustLoss& loss) {
  double cost = 0.0;
  for (const BalObservation& o : problem.observations) {
    double r[2];
    if (!Model::Project(problem.camera(o.camera), problem.point(o.point), r, nullptr, nullptr)) {
      return std::numeric_limits<double>::infinity();
    }
    r[0] -= o.x;
    r[1] -= o.y;
    double rho, drho;
    loss.Evaluate(o.weight * o.weight * (r[0] * r[0] + r[1] * r[1]), &rho, &drho);
    cost += rho;
  }
  for (const PointAnchor& anchor : problem.point_anchors) {
    for (int part = 0; part < 2; ++part) {
      double r[2];
      AnchorResidual<Model::Problem::kCameraSize>(anchor, part, problem.camera(anchor.frame), problem.point(anchor.point),
                                                  r, nullptr, nullptr);
      cost += r[0] * r[0] + r[1] * r[1];
    }
  }
  return 0.5 * cost;
}

template <typename Model>
Result<BundleAdjustmentSummary> SolveImpl(const BundleAdjustmentOptions& options,
                                          const BundleAdjustmentConstancy& constancy,
                                          typename Model::Problem* problem) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  if (problem == nullptr) return InvalidArgument("SolveBundleAdjustment: null problem");
  RECONAR_RETURN_IF_ERROR(problem->Check());
  if (!constancy.constant_cameras.empty() &&
      constancy.constant_cameras.size() != static_cast<size_t>(problem->num_cameras())) {
    return InvalidArgument("SolveBundleAdjustment: constant_cameras size != camera count");
  }
  if (!constancy.constant_points.empty() &&
      constancy.constant_points.size() != static_cast<size_t>(problem->num_points())) {
    return InvalidArgument("SolveBundleAdjustment: constant_points size != point count");
  }
  if (!constancy.intrinsics_group.empty()) {
    if (constancy.intrinsics_group.size() != static_cast<size_t>(problem->num_cameras())) {
      return InvalidArgument("SolveBundleAdjustment: intrinsics_group size != camera count");
    }
  }
  for (int m : constancy.constant_camera_parameters) {
    if (m < 0 || m >= Model::Problem::kCameraSize) {
      return InvalidArgument("SolveBundleAdjustment: constant camera parameter " +
                             std::to_string(m) + " out of range");
    }
  }
  const auto start = std::chrono::steady_clock::now();
  Solver<Model> solver(options, constancy, problem);
  BundleAdjustmentSummary summary;
  static_cast<LmSummary&>(summary) = RunLm(solver, options);
  summary.linear_solver = solver.linear_solver();
  summary.reduced_unknowns = solver.reduced_unknowns();
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace

double BundleAdjustmentCost(const BalProblem& problem, const RobustLoss& loss) {
  return CostImpl<BalModel>(problem, loss);
}
double BundleAdjustmentCost(const RadialProblem& problem, const RobustLoss& loss) {
  return CostImpl<RadialModel>(problem, loss);
}

Result<BundleAdjustmentSummary> SolveBundleAdjustment(const BundleAdjustmentOptions& options,
                                                      const BundleAdjustmentConstancy& constancy,
                                                      BalProblem* problem) {
  return SolveImpl<BalModel>(options, constancy, problem);
}
Result<BundleAdjustmentSummary> SolveBundleAdjustment(const BundleAdjustmentOptions& options,
                                                      const BundleAdjustmentConstancy& constancy,
                                                      RadialProblem* problem) {
  return SolveImpl<RadialModel>(options, constancy, problem);
}

}  // namespace reconar
