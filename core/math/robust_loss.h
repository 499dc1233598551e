#pragma once
// Robust losses rho(s) of the squared residual norm s = |r|^2; a robust cost is 1/2 sum rho(s_k)
// (the bundle adjuster, core/optim/bundle_adjuster.h; the pose refinement,
// core/geometry/absolute_pose.h). The solvers reweight each residual block by sqrt(rho'(s))
// (iteratively reweighted least squares, Triggs, McLauchlan, Hartley & Fitzgibbon, "Bundle
// Adjustment - A Modern Synthesis", 2000, sec. 3.4), dropping the rho'' term so the Gauss-Newton
// matrix stays positive semi-definite.
#include <cmath>

namespace reconar {

enum class LossType {
  kTrivial,  // rho(s) = s
  kHuber,    // rho(s) = s for s <= c^2, 2 c sqrt(s) - c^2 beyond
  kCauchy,   // rho(s) = c^2 log(1 + s / c^2)
};

struct RobustLoss {
  LossType type = LossType::kTrivial;
  double scale = 1.0;  // c, in residual units (pixels)

  // rho(s) and rho'(s).
  void Evaluate(double s, double* rho, double* drho) const {
    const double c2 = scale * scale;
    switch (type) {
      case LossType::kTrivial:
        *rho = s;
        *drho = 1.0;
        return;
      case LossType::kHuber:
        if (s <= c2) {
          *rho = s;
          *drho = 1.0;
        } else {
          const double r = std::sqrt(s);
          *rho = 2.0 * scale * r - c2;
          *drho = scale / r;
        }
        return;
      case LossType::kCauchy:
        *rho = c2 * std::log1p(s / c2);
        *drho = 1.0 / (1.0 + s / c2);
        return;
    }
    *rho = s;
    *drho = 1.0;
  }
};

}  // namespace reconar
