#include "core/optim/bundle_adjuster.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <optional>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <memory>

#include "core/base/thread_pool.h"
#include "core/math/lm_loop.h"
#include "core/optim/bal_camera_model.h"
#include "core/optim/cholmod_ldlt.h"
#include "core/optim/radial_camera_model.h"

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

// SimplicialLDLT whose numeric factorisation reads our upper-triangular, naturally ordered S in
// place: Eigen 3.4's factorize() builds a temporary SparseMatrix header (a heap allocation) on
// every call even when it then uses the input directly. Its work vectors are on the stack up to
// EIGEN_STACK_ALLOCATION_LIMIT (128 KiB: about 1800 cameras), on the heap beyond.
class InPlaceLdlt : public Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Upper,
                                                 Eigen::NaturalOrdering<int>> {
 public:
  void FactorizeInPlace(const Eigen::SparseMatrix<double>& upper) {
    this->template factorize_preordered<true>(upper);
  }
};

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

// One solve. Every buffer is sized in the constructor; the iteration loop does not allocate.
template <typename Model>
class Solver {
  using Problem = typename Model::Problem;
  static constexpr int kC = Problem::kCameraSize;
  using Mat99 = Eigen::Matrix<double, kC, kC>;
  using Mat93 = Eigen::Matrix<double, kC, kP>;
  using Mat29 = Eigen::Matrix<double, 2, kC, Eigen::RowMajor>;
  using Vec9 = Eigen::Matrix<double, kC, 1>;

 public:
  Solver(const BundleAdjustmentOptions& options, const BundleAdjustmentConstancy& constancy,
         Problem* problem)
      : opt_(options), problem_(problem) {
    constant_parameters_ = constancy.constant_camera_parameters;
    nc_ = problem->num_cameras();
    np_ = problem->num_points();
    no_ = static_cast<int>(problem->observations.size());
    const auto nobs = static_cast<size_t>(no_);
    const_cam_.assign(static_cast<size_t>(nc_), 0);
    const_pt_.assign(static_cast<size_t>(np_), 0);
    if (!constancy.constant_cameras.empty()) const_cam_ = constancy.constant_cameras;
    if (!constancy.constant_points.empty()) const_pt_ = constancy.constant_points;
    by_cam_.Build(nc_, problem->observations, true);
    by_pt_.Build(np_, problem->observations, false);
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
    const int n = kC * nc_;
    rhs_.resize(n);
    step_c_.resize(n);
    solution_.resize(n);
    BuildReducedSystemLayout();
    BuildSharedIntrinsics(constancy.intrinsics_group);
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
    const std::vector<BalObservation>& obs = problem_->observations;
    ParallelRange(no_, 512, [this, &obs](int begin, int end) {
      for (int k = begin; k < end; ++k) {
        const BalObservation& o = obs[static_cast<size_t>(k)];
        double* r = &residual_[2 * static_cast<size_t>(k)];
        Mat29& jc = jc_[static_cast<size_t>(k)];
        Mat23& jp = jp_[static_cast<size_t>(k)];
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
        if (const_cam_[static_cast<size_t>(o.camera)]) {
          jc.setZero();
        } else {
          for (int m : constant_parameters_) jc.col(m).setZero();
        }
        if (const_pt_[static_cast<size_t>(o.point)]) jp.setZero();
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
      }
    });
  }

  // Solves (J^T J + lambda D) dx = -J^T r by eliminating the points: with U, V, W the camera,
  // point and cross blocks, S = U - W V^-1 W^T, S dc = -gc + W V^-1 gp, then
  // dp = V^-1 (-gp - W^T dc). False if the Cholesky factorisation of S fails.
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
      }
    });
    const std::vector<BalObservation>& obs = problem_->observations;
    if (sparse_) {
      std::fill(s_sparse_.valuePtr(), s_sparse_.valuePtr() + s_sparse_.nonZeros(), 0.0);
    } else {
      s_dense_.setZero();
    }
    double* const values = sparse_ ? s_sparse_.valuePtr() : s_dense_.data();
    // Task i adds the blocks S(i, i2) for i2 <= i (original numbering), so every block of the
    // stored (upper) triangle is written by exactly one task.
    ParallelRange(nc_, 1, [this, lambda, &obs, values](int begin, int end) {
      for (int i = begin; i < end; ++i) {
        auto rhs = rhs_.segment<kC>(kC * cam_pos_[static_cast<size_t>(i)]);
        const PairBlock& diag = FindPair(i, i);
        if (const_cam_[static_cast<size_t>(i)]) {
          AddBlock(diag, Mat99::Identity(), values);
          rhs.setZero();
          continue;
        }
        Mat99 sii = u_[static_cast<size_t>(i)];
        sii.diagonal() += lambda * dc_diag_[static_cast<size_t>(i)];
        for (int m : constant_parameters_) sii(m, m) = 1.0;  // row and column are zero
        AddBlock(diag, sii, values);
        rhs = -gc_[static_cast<size_t>(i)];
        for (int q = by_cam_.offsets[i]; q < by_cam_.offsets[i + 1]; ++q) {
          const auto k = static_cast<size_t>(by_cam_.items[static_cast<size_t>(q)]);
          const int j = obs[k].point;
          rhs.noalias() += y_[k] * gp_[static_cast<size_t>(j)];
          for (int q2 = by_pt_.offsets[j]; q2 < by_pt_.offsets[j + 1]; ++q2) {
            const auto k2 = static_cast<size_t>(by_pt_.items[static_cast<size_t>(q2)]);
            const int i2 = obs[k2].camera;
            if (i2 > i || const_cam_[static_cast<size_t>(i2)]) continue;
            // S(i, i2) -= Y_ij W_i2j^T, stored as is or transposed.
            const PairBlock& p = FindPair(i, i2);
            if (p.transposed) {
              Block(p, values).noalias() -= w_[k2].lazyProduct(y_[k].transpose());
            } else {
              Block(p, values).noalias() -= y_[k].lazyProduct(w_[k2].transpose());
            }
          }
        }
      }
    });
    if (sparse_) {
      if (use_cholmod_) {
        if (!cholmod_.Factorize(s_sparse_.valuePtr())) return false;
        cholmod_.Solve(rhs_.data(), solution_.data());
      } else {
        ldlt_.FactorizeInPlace(s_sparse_);  // reads the upper triangle only
        if (ldlt_.info() != Eigen::Success) return false;
        solution_ = ldlt_.solve(rhs_);
      }
    } else if (!reduced_index_.empty()) {
      if (!SolveShared()) return false;
    } else {
      dense_llt_->compute(s_dense_);  // reads the upper triangle only
      if (dense_llt_->info() != Eigen::Success) return false;
      solution_ = rhs_;
      dense_llt_->solveInPlace(solution_);
    }
    for (int i = 0; i < nc_; ++i) {
      step_c_.segment<kC>(kC * i) = solution_.segment<kC>(kC * cam_pos_[static_cast<size_t>(i)]);
    }
    if (!step_c_.allFinite()) return false;
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

  // Shared intrinsics replace the camera parameters x by x = P y, P a 0/1 matrix mapping each
  // shared parameter to one column; the reduced system becomes P^T S P y = P^T b, assembled here
  // from the upper triangle of S (S_ab with a < b contributes to (P^T S P)_pq and, when p = q,
  // twice).
  void BuildSharedIntrinsics(const std::vector<int>& groups) {
    bool any = false;
    for (int g : groups) any |= g >= 0;
    if (!any) return;
    const int n = kC * nc_;
    reduced_index_.assign(static_cast<size_t>(n), -1);
    std::vector<int> group_first_column;
    int m = 0;
    for (int i = 0; i < nc_; ++i) {
      const int g = const_cam_[static_cast<size_t>(i)] ? -1 : groups[static_cast<size_t>(i)];
      for (int k = 0; k < kC; ++k) {
        int& index = reduced_index_[static_cast<size_t>(kC * i + k)];
        if (k < 6 || g < 0) {
          index = m++;
          continue;
        }
        if (static_cast<size_t>(g) >= group_first_column.size()) group_first_column.resize(static_cast<size_t>(g) + 1, -1);
        int& first = group_first_column[static_cast<size_t>(g)];
        if (first < 0) {
          first = m;
          m += kC - 6;
        }
        index = first + (k - 6);
      }
    }
    s_reduced_.resize(m, m);
    rhs_reduced_.resize(m);
    reduced_llt_.emplace(m);
  }

  bool SolveShared() {
    const int n = kC * nc_;
    s_reduced_.setZero();
    rhs_reduced_.setZero();
    for (int b = 0; b < n; ++b) {
      const int q = reduced_index_[static_cast<size_t>(b)];
      rhs_reduced_[q] += rhs_[b];
      for (int a = 0; a <= b; ++a) {
        const double v = s_dense_(a, b);
        if (v == 0.0) continue;
        const int p = reduced_index_[static_cast<size_t>(a)];
        if (p == q) {
          s_reduced_(p, p) += a == b ? v : 2.0 * v;
        } else {
          s_reduced_(std::min(p, q), std::max(p, q)) += v;
        }
      }
    }
    reduced_llt_->compute(s_reduced_);
    if (reduced_llt_->info() != Eigen::Success) return false;
    reduced_llt_->solveInPlace(rhs_reduced_);
    for (int a = 0; a < n; ++a) solution_[a] = rhs_reduced_[reduced_index_[static_cast<size_t>(a)]];
    return true;
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
    const std::vector<BalObservation>& obs = problem_->observations;
    ParallelRange(no_, 512, [this, &obs, &cameras, &points](int begin, int end) {
      for (int k = begin; k < end; ++k) {
        const BalObservation& o = obs[static_cast<size_t>(k)];
        double r[2];
        double rho = std::numeric_limits<double>::infinity(), drho;
        if (Model::Project(cameras.data() + static_cast<size_t>(o.camera) * kC,
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
  // Where block S(i, i2) of the reduced camera system lives: values[offset + b * stride + a]
  // holds entry (a, b) of the block, transposed when the block is stored as S(i2, i).
  struct PairBlock {
    int camera = 0;  // i2
    bool transposed = false;
    std::ptrdiff_t offset = 0;
    std::ptrdiff_t stride = 0;
  };

  const PairBlock& FindPair(int i, int i2) const {
    const auto first = pairs_.begin() + pair_offsets_[static_cast<size_t>(i)];
    const auto last = pairs_.begin() + pair_offsets_[static_cast<size_t>(i) + 1];
    const auto it =
        std::lower_bound(first, last, i2, [](const PairBlock& p, int c) { return p.camera < c; });
    return *it;
  }

  using BlockMap = Eigen::Map<Mat99, Eigen::Unaligned, Eigen::OuterStride<>>;
  static BlockMap Block(const PairBlock& p, double* values) {
    return BlockMap(values + p.offset, kC, kC, Eigen::OuterStride<>(p.stride));
  }
  static void AddBlock(const PairBlock& p, const Mat99& m, double* values) {
    if (p.transposed) {
      Block(p, values) += m.transpose();
    } else {
      Block(p, values) += m;
    }
  }

  // Camera positions in the reduced system (identity for dense; approximate minimum degree on
  // the camera graph, Amestoy, Davis & Duff 1996, for sparse), the block pattern, and the
  // symbolic factorisation: all done once, before the iterations.
  void BuildReducedSystemLayout() {
    const int n = kC * nc_;
    sparse_ = opt_.linear_solver == BundleAdjustmentOptions::LinearSolver::kSparseCholesky;
    const std::vector<BalObservation>& obs = problem_->observations;
    std::vector<std::vector<int>> neighbours(static_cast<size_t>(nc_));
    for (int i = 0; i < nc_; ++i) neighbours[static_cast<size_t>(i)].push_back(i);
    for (int j = 0; j < np_; ++j) {
      for (int q = by_pt_.offsets[j]; q < by_pt_.offsets[j + 1]; ++q) {
        for (int q2 = by_pt_.offsets[j]; q2 < by_pt_.offsets[j + 1]; ++q2) {
          const int i = obs[static_cast<size_t>(by_pt_.items[static_cast<size_t>(q)])].camera;
          const int i2 = obs[static_cast<size_t>(by_pt_.items[static_cast<size_t>(q2)])].camera;
          if (i2 < i) neighbours[static_cast<size_t>(i)].push_back(i2);
        }
      }
    }
    for (std::vector<int>& v : neighbours) {
      std::sort(v.begin(), v.end());
      v.erase(std::unique(v.begin(), v.end()), v.end());
    }
    cam_pos_.resize(static_cast<size_t>(nc_));
    for (int i = 0; i < nc_; ++i) cam_pos_[static_cast<size_t>(i)] = i;
    if (sparse_ && nc_ > 1) {
      std::vector<Eigen::Triplet<int>> triplets;
      for (int i = 0; i < nc_; ++i) {
        for (int i2 : neighbours[static_cast<size_t>(i)]) {
          triplets.emplace_back(i, i2, 1);
          triplets.emplace_back(i2, i, 1);
        }
      }
      Eigen::SparseMatrix<int> graph(nc_, nc_);
      graph.setFromTriplets(triplets.begin(), triplets.end());
      Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> pinv;
      Eigen::AMDOrdering<int> amd;
      amd(graph, pinv);  // pinv.indices()[new position] = camera
      if (pinv.size() == nc_) {
        for (int p = 0; p < nc_; ++p) cam_pos_[static_cast<size_t>(pinv.indices()[p])] = p;
      }
    }
    // Stored upper triangle: block (pr, pc) with pr <= pc; per block column, sorted row blocks.
    std::vector<std::vector<int>> column_blocks(static_cast<size_t>(nc_));
    for (int i = 0; i < nc_; ++i) {
      for (int i2 : neighbours[static_cast<size_t>(i)]) {
        const int a = cam_pos_[static_cast<size_t>(i)], b = cam_pos_[static_cast<size_t>(i2)];
        column_blocks[static_cast<size_t>(std::max(a, b))].push_back(std::min(a, b));
      }
    }
    for (std::vector<int>& v : column_blocks) std::sort(v.begin(), v.end());
    if (sparse_) {
      Eigen::VectorXi column_sizes(n);
      for (int pc = 0; pc < nc_; ++pc) {
        const auto len = static_cast<int>(column_blocks[static_cast<size_t>(pc)].size());
        column_sizes.segment<kC>(kC * pc).setConstant(kC * len);
      }
      s_sparse_.resize(n, n);
      s_sparse_.reserve(column_sizes);
      for (int pc = 0; pc < nc_; ++pc) {
        for (int b = 0; b < kC; ++b) {
          for (int pr : column_blocks[static_cast<size_t>(pc)]) {
            for (int a = 0; a < kC; ++a) s_sparse_.insert(kC * pr + a, kC * pc + b) = 0.0;
          }
        }
      }
      s_sparse_.makeCompressed();
      // CHOLMOD's supernodal factorisation when built with it; Eigen's simplicial LDL^T otherwise
      // (or if CHOLMOD refuses the pattern).
      use_cholmod_ = SparseCholesky::IsAvailable() &&
                     cholmod_.Analyze(n, s_sparse_.outerIndexPtr(), s_sparse_.innerIndexPtr()).ok();
      if (!use_cholmod_) ldlt_.analyzePattern(s_sparse_);
    } else {
      s_dense_.resize(n, n);
      // Constructed in place: Eigen's LLT leaves its status member unset until compute(), so
      // copying a fresh one reads an indeterminate value (UBSan reports it).
      dense_llt_.emplace(n);
    }
    pair_offsets_.assign(static_cast<size_t>(nc_) + 1, 0);
    for (int i = 0; i < nc_; ++i) {
      pair_offsets_[static_cast<size_t>(i) + 1] =
          pair_offsets_[static_cast<size_t>(i)] +
          static_cast<int>(neighbours[static_cast<size_t>(i)].size());
      for (int i2 : neighbours[static_cast<size_t>(i)]) {
        const int a = cam_pos_[static_cast<size_t>(i)], b = cam_pos_[static_cast<size_t>(i2)];
        const int pr = std::min(a, b), pc = std::max(a, b);
        PairBlock p;
        p.camera = i2;
        p.transposed = a > b;
        if (sparse_) {
          const std::vector<int>& rows = column_blocks[static_cast<size_t>(pc)];
          const auto rank = std::lower_bound(rows.begin(), rows.end(), pr) - rows.begin();
          p.offset = s_sparse_.outerIndexPtr()[kC * pc] + kC * rank;
          p.stride = kC * static_cast<std::ptrdiff_t>(rows.size());
        } else {
          p.offset = static_cast<std::ptrdiff_t>(kC) * pc * n + kC * pr;
          p.stride = n;
        }
        pairs_.push_back(p);
      }
    }
  }

  bool sparse_ = false;
  std::vector<int> reduced_index_;  // shared intrinsics: column of each camera parameter, or empty
  Eigen::MatrixXd s_reduced_;
  Eigen::VectorXd rhs_reduced_;
  std::optional<Eigen::LLT<Eigen::MatrixXd, Eigen::Upper>> reduced_llt_;
  std::vector<int> cam_pos_;
  std::vector<int> pair_offsets_;
  std::vector<PairBlock> pairs_;
  Eigen::MatrixXd s_dense_;
  std::optional<Eigen::LLT<Eigen::MatrixXd, Eigen::Upper>> dense_llt_;
  Eigen::SparseMatrix<double> s_sparse_;
  InPlaceLdlt ldlt_;
  SparseCholesky cholmod_;
  bool use_cholmod_ = false;
  Eigen::VectorXd rhs_, step_c_, solution_;
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
    if (options.linear_solver != BundleAdjustmentOptions::LinearSolver::kDenseCholesky) {
      return InvalidArgument("SolveBundleAdjustment: shared intrinsics need the dense solver");
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
