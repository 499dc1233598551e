#pragma once
// Derivative-free minimisation of a small fixed-dimensional function by the downhill simplex of
// Nelder & Mead (1965), with the standard coefficients (reflection 1, expansion 2, contraction 1/2,
// shrink 1/2) as in Lagarias et al., "Convergence properties of the Nelder-Mead simplex method in
// low dimensions", SIAM J. Optim. 9(1), 1998. PMVS refines its patches with this method (the NCC
// score is only piecewise smooth under bilinear sampling). Fixed size, no allocation.
#include <Eigen/Core>
#include <algorithm>
#include <array>

namespace reconar {

struct NelderMeadOptions {
  int max_evaluations = 100;
  // Stop when every vertex lies within x_tolerance * initial_step (per coordinate) of the best
  // one and the cost values span at most f_tolerance.
  double x_tolerance = 0.01;
  double f_tolerance = 1e-5;
};

struct NelderMeadSummary {
  enum class Termination {
    kConverged,       // the simplex shrank below x_tolerance and its costs below f_tolerance
    kMaxEvaluations,  // max_evaluations cost evaluations were spent first
  };
  Termination termination = Termination::kMaxEvaluations;
  int evaluations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
};

// Minimises cost(x) (x an Eigen::Matrix<double, N, 1>, returns double) starting from the simplex
// {x, x + initial_step[k] e_k}. *x receives the best vertex.
template <int N, typename CostFn>
NelderMeadSummary NelderMeadMinimize(const CostFn& cost, const Eigen::Matrix<double, N, 1>& initial_step,
                                     const NelderMeadOptions& options, Eigen::Matrix<double, N, 1>* x) {
  using Vec = Eigen::Matrix<double, N, 1>;
  NelderMeadSummary summary;
  std::array<Vec, N + 1> vertex;
  std::array<double, N + 1> value;
  vertex[0] = *x;
  value[0] = cost(vertex[0]);
  summary.initial_cost = value[0];
  for (int k = 0; k < N; ++k) {
    vertex[k + 1] = *x;
    vertex[k + 1][k] += initial_step[k];
    value[k + 1] = cost(vertex[k + 1]);
  }
  summary.evaluations = N + 1;
  std::array<int, N + 1> order;
  const Vec inv_step = initial_step.cwiseAbs().cwiseMax(1e-300).cwiseInverse();
  while (true) {
    for (int i = 0; i <= N; ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](int a, int b) { return value[a] < value[b]; });
    const int best = order[0], worst = order[N], second_worst = order[N - 1];
    double spread = 0.0;
    for (int i = 1; i <= N; ++i) {
      spread = std::max(spread, ((vertex[order[i]] - vertex[best]).cwiseProduct(inv_step)).cwiseAbs().maxCoeff());
    }
    if (spread <= options.x_tolerance && value[worst] - value[best] <= options.f_tolerance) {
      summary.termination = NelderMeadSummary::Termination::kConverged;
      break;
    }
    if (summary.evaluations >= options.max_evaluations) break;
    Vec centroid = Vec::Zero();
    for (int i = 0; i <= N; ++i) {
      if (i != worst) centroid += vertex[i];
    }
    centroid /= N;
    const Vec reflected = centroid + (centroid - vertex[worst]);
    const double f_reflected = cost(reflected);
    ++summary.evaluations;
    if (f_reflected < value[best]) {
      const Vec expanded = centroid + 2.0 * (centroid - vertex[worst]);
      const double f_expanded = cost(expanded);
      ++summary.evaluations;
      if (f_expanded < f_reflected) {
        vertex[worst] = expanded;
        value[worst] = f_expanded;
      } else {
        vertex[worst] = reflected;
        value[worst] = f_reflected;
      }
      continue;
    }
    if (f_reflected < value[second_worst]) {
      vertex[worst] = reflected;
      value[worst] = f_reflected;
      continue;
    }
    const bool outside = f_reflected < value[worst];
    const Vec contracted = outside ? Vec(centroid + 0.5 * (reflected - centroid))
                                   : Vec(centroid + 0.5 * (vertex[worst] - centroid));
    const double f_contracted = cost(contracted);
    ++summary.evaluations;
    if (f_contracted < (outside ? f_reflected : value[worst])) {
      vertex[worst] = contracted;
      value[worst] = f_contracted;
      continue;
    }
    for (int i = 0; i <= N; ++i) {
      if (i == best) continue;
      vertex[i] = vertex[best] + 0.5 * (vertex[i] - vertex[best]);
      value[i] = cost(vertex[i]);
      ++summary.evaluations;
    }
  }
  int best = 0;
  for (int i = 1; i <= N; ++i) {
    if (value[i] < value[best]) best = i;
  }
  *x = vertex[best];
  summary.final_cost = value[best];
  return summary;
}

}  // namespace reconar
