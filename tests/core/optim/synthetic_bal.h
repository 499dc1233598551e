#pragma once
// Seeded synthetic BAL problems for the optimiser tests: cameras on a ring around a cloud of
// points, exact observations, and a perturbation helper.
#include <random>

#include "core/optim/bal_camera_model.h"
#include "core/optim/bal_problem.h"

namespace reconar::testing {

inline BalProblem MakeSyntheticBal(int num_cameras, int num_points, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  BalProblem p;
  p.cameras.resize(static_cast<size_t>(num_cameras) * 9);
  p.points.resize(static_cast<size_t>(num_points) * 3);
  for (int i = 0; i < num_cameras; ++i) {
    double* c = p.camera(i);
    for (int d = 0; d < 3; ++d) c[d] = 0.2 * unit(rng);  // rotation up to ~0.35 rad
    c[3] = 0.5 * unit(rng);
    c[4] = 0.5 * unit(rng);
    c[5] = -6.0 + 0.5 * unit(rng);  // camera looks down -z at the cloud
    c[6] = 500.0 + 50.0 * unit(rng);
    c[7] = 0.05 * unit(rng);
    c[8] = 0.01 * unit(rng);
  }
  for (double& x : p.points) x = unit(rng);
  for (int j = 0; j < num_points; ++j) {
    for (int i = 0; i < num_cameras; ++i) {
      // Every point seen by most cameras (deterministic pattern).
      if ((i + j) % 5 == 4) continue;
      double uv[2] = {0.0, 0.0};
      ProjectBal(p.camera(i), p.point(j), uv, nullptr, nullptr);
      p.observations.push_back({i, j, uv[0], uv[1]});
    }
  }
  return p;
}

inline void PerturbBal(BalProblem* p, uint32_t seed, int first_free_camera) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int i = first_free_camera; i < p->num_cameras(); ++i) {
    double* c = p->camera(i);
    for (int d = 0; d < 3; ++d) c[d] += 0.01 * n(rng);
    for (int d = 3; d < 6; ++d) c[d] += 0.05 * n(rng);
    c[6] *= 1.0 + 0.01 * n(rng);
    c[7] += 0.005 * n(rng);
    c[8] += 0.001 * n(rng);
  }
  for (double& x : p->points) x += 0.05 * n(rng);
}

}  // namespace reconar::testing
