#pragma once
// Real roots of low-degree polynomials, used by the seven-point solver.

namespace reconar {

// Real roots of c3 x^3 + c2 x^2 + c1 x + c0 = 0, written to roots[0..return). Returns 0..3.
// Falls back to the quadratic / linear formula when the leading coefficients vanish relative
// to the others. Closed form (trigonometric for three real roots, Cardano otherwise), then two
// Newton steps on the original polynomial to polish each root.
int SolveCubicReal(double c3, double c2, double c1, double c0, double roots[3]);

// Real roots of c2 x^2 + c1 x + c0 = 0 (cancellation-free form). Returns 0..2.
int SolveQuadraticReal(double c2, double c1, double c0, double roots[2]);

}  // namespace reconar
