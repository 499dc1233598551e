#include <cmath>
#include <cstdio>
#include <string>

#include "core/base/json_writer.h"
#include "core/optim/bal_problem.h"
#include "core/optim/bundle_adjuster.h"
#include "tools/commands.h"

namespace reconar::tools {

namespace {

constexpr char kHelp[] =
    "usage: reconar bundle-adjust --bal FILE [options]\n"
    "\n"
    "Reads a 'Bundle Adjustment in the Large' problem (cameras: angle-axis, translation, f, k1, k2)\n"
    "and minimises 1/2 sum rho(|reprojection error|^2) with Levenberg-Marquardt over the Schur\n"
    "complement of the points.\n"
    "  --bal FILE            the BAL problem (text)\n"
    "  --solver S            reduced camera system: dense, sparse or auto (default auto: sparse for\n"
    "                        500 unknowns or more when their coupled blocks fill at most 60 %)\n"
    "  --loss L              trivial, huber or cauchy (default trivial)\n"
    "  --loss-scale S        robust loss scale in pixels (default 1)\n"
    "  --max-iterations N    LM iterations, accepted and rejected (default 100)\n"
    "  --threads N           worker threads (default: one per core)\n"
    "  --json                print one JSON object: file, cameras, points, observations,\n"
    "                        initial_cost, final_cost, iterations, seconds, termination\n"
    "exit codes: 0 ok (also when stopped by --max-iterations), 1 numeric failure, 2 bad usage or input\n";

Result<BundleAdjustmentOptions::LinearSolver> SolverFromArgs(const Args& args) {
  using LinearSolver = BundleAdjustmentOptions::LinearSolver;
  const std::string name = args.Get("solver", "auto");
  if (name == "dense") return LinearSolver::kDenseCholesky;
  if (name == "sparse") return LinearSolver::kSparseCholesky;
  if (name == "auto") return LinearSolver::kAuto;
  return InvalidArgument("--solver expects dense, sparse or auto, got '" + name + "'");
}

Result<RobustLoss> LossFromArgs(const Args& args) {
  RobustLoss loss;
  const std::string name = args.Get("loss", "trivial");
  if (name == "trivial") {
    loss.type = LossType::kTrivial;
  } else if (name == "huber") {
    loss.type = LossType::kHuber;
  } else if (name == "cauchy") {
    loss.type = LossType::kCauchy;
  } else {
    return InvalidArgument("--loss expects trivial, huber or cauchy, got '" + name + "'");
  }
  RECONAR_ASSIGN_OR_RETURN(loss.scale, args.GetDouble("loss-scale", 1.0, 1e-12, 1e12));
  return loss;
}

void PrintJson(const std::string& path, const BalProblem& problem, const BundleAdjustmentSummary& s) {
  JsonWriter json;
  json.BeginObject()
      .Key("file").String(path)
      .Key("cameras").Int(problem.num_cameras())
      .Key("points").Int(problem.num_points())
      .Key("observations").Int(static_cast<long long>(problem.observations.size()))
      .Key("initial_cost").Double(s.initial_cost)
      .Key("final_cost").Double(s.final_cost)
      .Key("iterations").Int(s.iterations)
      .Key("seconds").Double(s.seconds)
      .Key("termination").String(TerminationName(s.termination))
      .EndObject();
  std::printf("%s\n", json.str().c_str());
}

void PrintSummary(const std::string& path, const BalProblem& problem, const BundleAdjustmentSummary& s) {
  const bool dense = s.linear_solver == BundleAdjustmentOptions::LinearSolver::kDenseCholesky;
  std::printf("%s: %d cameras, %d points, %zu observations\n", path.c_str(), problem.num_cameras(),
              problem.num_points(), problem.observations.size());
  std::printf("cost (1/2 sum of squared residuals): %.2f -> %.2f in %d iterations (%d accepted), %.2f s, %s solver\n",
              s.initial_cost, s.final_cost, s.iterations, s.accepted_steps, s.seconds, dense ? "dense" : "sparse");
  std::printf("termination: %s\n", TerminationName(s.termination));
}

}  // namespace

int RunBundleAdjust(int argc, char** argv, int first) {
  Args args({"bal", "solver", "loss", "loss-scale", "max-iterations", "threads"}, {"json"});
  if (const auto exit_code = ParseCommand(&args, argc, argv, first, kHelp, {0, 0, {"bal"}})) return *exit_code;
  BundleAdjustmentOptions options;
  auto loss = LossFromArgs(args);
  if (!loss.ok()) return Fail(loss.status());
  options.loss = *loss;
  auto max_iterations = args.GetInt("max-iterations", options.max_iterations, 1, 1000000);
  if (!max_iterations.ok()) return Fail(max_iterations.status());
  options.max_iterations = *max_iterations;
  auto threads = args.GetThreads();
  if (!threads.ok()) return Fail(threads.status());
  options.num_threads = *threads;
  auto solver = SolverFromArgs(args);  // before the (possibly long) read
  if (!solver.ok()) return Fail(solver.status());
  options.linear_solver = *solver;

  const std::string path = args.Get("bal");
  auto problem = ReadBalProblem(path);
  if (!problem.ok()) return Fail(problem.status());

  auto summary = SolveBundleAdjustment(options, {}, &*problem);
  if (!summary.ok()) return Fail(summary.status());
  if (args.Has("json")) {
    PrintJson(path, *problem, *summary);
  } else {
    PrintSummary(path, *problem, *summary);
  }
  const bool failed = summary->termination == BundleAdjustmentSummary::Termination::kNumericFailure;
  if (failed) std::fprintf(stderr, "reconar: error: %s: bundle adjustment failed numerically\n", path.c_str());
  return failed ? 1 : 0;
}

}  // namespace reconar::tools
