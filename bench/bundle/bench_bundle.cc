// Bundle adjustment speed and accuracy, side by side with Ceres 2.1 in the same process, one
// thread each, on a BAL problem (default: ../shared/data ladybug problem-49-7776).
//   bench_bundle [BAL_FILE] [repeats=3]
// Both start from the same parameters. Ceres uses the standard BAL reprojection residual
// (Snavely camera model, automatic differentiation) with SPARSE_SCHUR; ours uses analytic
// Jacobians, the Schur complement and a dense (or block-sparse, "sparse" line) Cholesky of the
// reduced camera system. Runs
// alternate to share machine noise; medians are reported, with ratios ours / Ceres.
#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench/common/thread_cpu_time.h"
#include "core/optim/bal_problem.h"
#include "core/optim/bundle_adjuster.h"

namespace {

using Clock = std::chrono::steady_clock;

using reconar::bench::ThreadCpuSeconds;

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// BAL reprojection residual: P = R(w) X + t, p = -P.xy / P.z, u = f (1 + k1 r^2 + k2 r^4) p.
struct BalReprojectionError {
  BalReprojectionError(double x, double y) : observed_x(x), observed_y(y) {}

  template <typename T>
  bool operator()(const T* const camera, const T* const point, T* residuals) const {
    T p[3];
    ceres::AngleAxisRotatePoint(camera, point, p);
    p[0] += camera[3];
    p[1] += camera[4];
    p[2] += camera[5];
    const T xp = -p[0] / p[2];
    const T yp = -p[1] / p[2];
    const T r2 = xp * xp + yp * yp;
    const T distortion = T(1.0) + r2 * (camera[7] + camera[8] * r2);
    residuals[0] = camera[6] * distortion * xp - T(observed_x);
    residuals[1] = camera[6] * distortion * yp - T(observed_y);
    return true;
  }

  double observed_x;
  double observed_y;
};

struct Run {
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int iterations = 0;
  double wall = 0.0;
  double cpu = 0.0;
  std::string termination;
};

Run RunOurs(const reconar::BalProblem& start,
            reconar::BundleAdjustmentOptions::LinearSolver linear_solver) {
  reconar::BalProblem problem = start;
  reconar::BundleAdjustmentOptions options;
  options.num_threads = 1;
  options.linear_solver = linear_solver;
  const double cpu0 = ThreadCpuSeconds();
  const auto t0 = Clock::now();
  reconar::Result<reconar::BundleAdjustmentSummary> r =
      reconar::SolveBundleAdjustment(options, {}, &problem);
  Run run;
  run.wall = std::chrono::duration<double>(Clock::now() - t0).count();
  run.cpu = ThreadCpuSeconds() - cpu0;
  if (!r.ok()) {
    std::fprintf(stderr, "ours failed: %s\n", r.status().ToString().c_str());
    std::exit(1);
  }
  run.initial_cost = r->initial_cost;
  run.final_cost = r->final_cost;
  run.iterations = r->iterations;
  run.termination = reconar::TerminationName(r->termination);
  return run;
}

Run RunCeres(const reconar::BalProblem& start) {
  reconar::BalProblem problem = start;
  const double cpu0 = ThreadCpuSeconds();
  const auto t0 = Clock::now();
  ceres::Problem ceres_problem;
  for (const reconar::BalObservation& o : problem.observations) {
    ceres::CostFunction* cost = new ceres::AutoDiffCostFunction<BalReprojectionError, 2, 9, 3>(
        new BalReprojectionError(o.x, o.y));
    ceres_problem.AddResidualBlock(cost, nullptr, problem.camera(o.camera), problem.point(o.point));
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_SCHUR;
  options.num_threads = 1;
  options.max_num_iterations = 100;  // same cap as ours
  auto* ordering = new ceres::ParameterBlockOrdering;
  for (int j = 0; j < problem.num_points(); ++j) ordering->AddElementToGroup(problem.point(j), 0);
  for (int i = 0; i < problem.num_cameras(); ++i) ordering->AddElementToGroup(problem.camera(i), 1);
  options.linear_solver_ordering.reset(ordering);
  ceres::Solver::Summary summary;
  ceres::Solve(options, &ceres_problem, &summary);
  Run run;
  run.wall = std::chrono::duration<double>(Clock::now() - t0).count();
  run.cpu = ThreadCpuSeconds() - cpu0;
  run.initial_cost = summary.initial_cost;
  run.final_cost = summary.final_cost;
  // Steps taken, as ours counts them (Ceres' own report adds its iteration 0: one more).
  run.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps - 1;
  run.termination = ceres::TerminationTypeToString(summary.termination_type);
  return run;
}

void Print(const char* name, const Run& r, double wall, double cpu) {
  std::printf("%-6s initial %.2f final %.2f iterations %d (%s) wall %.3f s cpu %.3f s\n", name,
              r.initial_cost, r.final_cost, r.iterations, r.termination.c_str(), wall, cpu);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string path =
      argc > 1 ? argv[1]
               : std::string(RECONAR_SHARED_DATA_DIR) + "/bal_ladybug/problem-49-7776-pre.txt";
  const int repeats = argc > 2 ? std::max(1, std::atoi(argv[2])) : 3;
  reconar::Result<reconar::BalProblem> problem = reconar::ReadBalProblem(path);
  if (!problem.ok()) {
    std::fprintf(stderr, "%s\n", problem.status().ToString().c_str());
    return 1;
  }
  std::printf("%s: %d cameras, %d points, %zu observations, %d repeats\n", path.c_str(),
              problem->num_cameras(), problem->num_points(), problem->observations.size(), repeats);
  using LinearSolver = reconar::BundleAdjustmentOptions::LinearSolver;
  std::vector<double> ours_wall, ours_cpu, sparse_wall, sparse_cpu, ceres_wall, ceres_cpu;
  Run ours, sparse, ceres;
  for (int k = 0; k < repeats; ++k) {
    ours = RunOurs(*problem, LinearSolver::kDenseCholesky);
    ours_wall.push_back(ours.wall);
    ours_cpu.push_back(ours.cpu);
    sparse = RunOurs(*problem, LinearSolver::kSparseCholesky);
    sparse_wall.push_back(sparse.wall);
    sparse_cpu.push_back(sparse.cpu);
    ceres = RunCeres(*problem);
    ceres_wall.push_back(ceres.wall);
    ceres_cpu.push_back(ceres.cpu);
  }
  Print("ours", ours, Median(ours_wall), Median(ours_cpu));
  Print("sparse", sparse, Median(sparse_wall), Median(sparse_cpu));
  Print("ceres", ceres, Median(ceres_wall), Median(ceres_cpu));
  std::printf("ratios ours(dense)/ceres: final cost %.6f iterations %.3f wall %.3f cpu %.3f\n",
              ours.final_cost / ceres.final_cost,
              static_cast<double>(ours.iterations) / ceres.iterations,
              Median(ours_wall) / Median(ceres_wall), Median(ours_cpu) / Median(ceres_cpu));
  std::printf("ratios ours(sparse)/ceres: final cost %.6f iterations %.3f wall %.3f cpu %.3f\n",
              sparse.final_cost / ceres.final_cost,
              static_cast<double>(sparse.iterations) / ceres.iterations,
              Median(sparse_wall) / Median(ceres_wall), Median(sparse_cpu) / Median(ceres_cpu));
  return 0;
}
