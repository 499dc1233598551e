#include "core/geometry/polynomial.h"

#include <algorithm>
#include <cmath>

namespace reconar {
namespace {

constexpr double kPi = 3.14159265358979323846;

}  // namespace

int SolveQuadraticReal(double c2, double c1, double c0, double roots[2]) {
  const double scale = std::max({std::abs(c2), std::abs(c1), std::abs(c0)});
  if (!(scale > 0.0) || !std::isfinite(scale)) return 0;
  if (std::abs(c2) <= 1e-14 * scale) {
    if (std::abs(c1) <= 1e-14 * scale) return 0;
    roots[0] = -c0 / c1;
    return 1;
  }
  const double discriminant = c1 * c1 - 4.0 * c2 * c0;
  if (discriminant < 0.0) return 0;
  // q = -(c1 + sign(c1) sqrt(D)) / 2 avoids subtracting nearly equal numbers.
  const double q = -0.5 * (c1 + std::copysign(std::sqrt(discriminant), c1));
  if (q == 0.0) {  // c1 == 0 and D == 0: double root at 0
    roots[0] = 0.0;
    return 1;
  }
  roots[0] = q / c2;
  roots[1] = c0 / q;
  return 2;
}

int SolveCubicReal(double c3, double c2, double c1, double c0, double roots[3]) {
  const double scale = std::max({std::abs(c3), std::abs(c2), std::abs(c1), std::abs(c0)});
  if (!(scale > 0.0) || !std::isfinite(scale)) return 0;
  if (std::abs(c3) <= 1e-12 * scale) return SolveQuadraticReal(c2, c1, c0, roots);

  // Monic form x^3 + a x^2 + b x + c.
  const double a = c2 / c3;
  const double b = c1 / c3;
  const double c = c0 / c3;
  const double Q = (a * a - 3.0 * b) / 9.0;
  const double R = (2.0 * a * a * a - 9.0 * a * b + 27.0 * c) / 54.0;
  const double Q3 = Q * Q * Q;
  int count = 0;
  if (R * R < Q3) {  // three real roots
    const double theta = std::acos(std::clamp(R / std::sqrt(Q3), -1.0, 1.0));
    const double m = -2.0 * std::sqrt(Q);
    roots[0] = m * std::cos(theta / 3.0) - a / 3.0;
    roots[1] = m * std::cos((theta + 2.0 * kPi) / 3.0) - a / 3.0;
    roots[2] = m * std::cos((theta - 2.0 * kPi) / 3.0) - a / 3.0;
    count = 3;
  } else {  // one real root (or a multiple root)
    const double A = -std::copysign(std::cbrt(std::abs(R) + std::sqrt(R * R - Q3)), R);
    const double B = A != 0.0 ? Q / A : 0.0;
    roots[0] = A + B - a / 3.0;
    count = 1;
  }
  for (int i = 0; i < count; ++i) {
    for (int step = 0; step < 2; ++step) {
      const double x = roots[i];
      const double f = ((x + a) * x + b) * x + c;
      const double df = (3.0 * x + 2.0 * a) * x + b;
      if (df == 0.0) break;
      const double next = x - f / df;
      const double f_next = ((next + a) * next + b) * next + c;
      if (!std::isfinite(next) || !(std::abs(f_next) < std::abs(f))) break;  // only improve
      roots[i] = next;
    }
  }
  return count;
}

}  // namespace reconar
