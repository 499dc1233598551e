#pragma once
// Seeded synthetic BAL and radial problems for the optimiser tests: cameras on a ring around a
// cloud of points, exact (or noisy) observations, and perturbation helpers.
#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "core/optim/bal_camera_model.h"
#include "core/optim/bal_problem.h"
#include "core/optim/radial_camera_model.h"

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

// RADIAL cameras (640x480 pixels) 0.35 rad apart on an arc of radius 6 round a cloud of points
// in [-1, 1]^3, looking at its centre. Cameras with the same non-negative entry of `groups` have
// the same intrinsics, those of group g (f = 800 + 40 g, k1 = -0.05 + 0.02 g, ...); a camera of
// group -1 has intrinsics of its own. Point j is seen by the cameras within 2 of camera
// j % cameras (a banded camera graph), observed with Gaussian noise of `noise_px`.
inline RadialProblem MakeSyntheticRadial(const std::vector<int>& groups, int num_points, double noise_px,
                                         uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, noise_px);
  const auto num_cameras = static_cast<int>(groups.size());
  RadialProblem p;
  for (int i = 0; i < num_cameras; ++i) {
    const double angle = 0.35 * i;
    const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix();
    const Eigen::Vector3d center(6.0 * std::sin(angle), 0.3 * unit(rng), -6.0 * std::cos(angle));
    const Eigen::Vector3d t = -R * center;
    const Eigen::AngleAxisd aa(R);
    const Eigen::Vector3d w = aa.angle() * aa.axis();
    const double g = groups[static_cast<size_t>(i)] >= 0 ? groups[static_cast<size_t>(i)] : 3.0 + unit(rng);
    const double camera[12] = {w.x(), w.y(), w.z(), t.x(), t.y(), t.z(), 800.0 + 40.0 * g, -0.05 + 0.02 * g,
                               0.01 - 0.005 * g, 320.0 + 5.0 * g, 240.0 - 4.0 * g, 1.0 + 0.002 * g};
    p.cameras.insert(p.cameras.end(), camera, camera + 12);
  }
  for (int j = 0; j < num_points; ++j) {
    for (int d = 0; d < 3; ++d) p.points.push_back(unit(rng));
  }
  for (int j = 0; j < num_points; ++j) {
    const int home = j % num_cameras;
    for (int i = std::max(0, home - 2); i <= std::min(num_cameras - 1, home + 2); ++i) {
      double uv[2] = {0.0, 0.0};
      ProjectRadial(p.camera(i), p.point(j), uv, nullptr, nullptr);
      p.observations.push_back({i, j, uv[0] + noise(rng), uv[1] + noise(rng)});
    }
  }
  return p;
}

// Moves the points and the cameras not marked constant: their poses, and their intrinsics by the
// same amount for all the cameras of a group (shared intrinsics start out equal).
inline void PerturbRadial(RadialProblem* p, const std::vector<int>& groups, uint32_t seed,
                          const std::vector<char>& constant_cameras) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<double> group_change;
  for (int i = 0; i < p->num_cameras(); ++i) {
    if (constant_cameras[static_cast<size_t>(i)]) continue;
    double* c = p->camera(i);
    for (int d = 0; d < 3; ++d) c[d] += 0.01 * n(rng);
    for (int d = 3; d < 6; ++d) c[d] += 0.05 * n(rng);
    const int g = groups[static_cast<size_t>(i)];
    double* change = nullptr;
    double own[6];
    if (g >= 0) {
      if (group_change.size() < 6 * (static_cast<size_t>(g) + 1)) {
        const size_t first = group_change.size();
        group_change.resize(6 * (static_cast<size_t>(g) + 1));
        for (size_t k = first; k < group_change.size(); ++k) group_change[k] = n(rng);
      }
      change = &group_change[6 * static_cast<size_t>(g)];
    } else {
      for (double& x : own) x = n(rng);
      change = own;
    }
    c[6] *= 1.0 + 0.01 * change[0];
    c[7] += 0.005 * change[1];
    c[8] += 0.001 * change[2];
    c[9] += 2.0 * change[3];
    c[10] += 2.0 * change[4];
    c[11] += 0.001 * change[5];
  }
  for (double& x : p->points) x += 0.05 * n(rng);
}

}  // namespace reconar::testing
