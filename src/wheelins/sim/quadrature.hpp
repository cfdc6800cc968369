// The quadrature of the simulator: 4-point Gauss-Legendre nodes and weights on
// [-1, 1] (every sample is the mean rate over its interval, docs/simulator.md), and
// the integrals of the Lagrange basis through those nodes (the wheel angle at each
// node from the rolling rates at all four).
#pragma once

namespace wheelins::sim {

// 4-point Gauss-Legendre on [-1, 1].
constexpr double kGlX[4] = {-0.86113631159405257522, -0.33998104358485626480,
                            0.33998104358485626480, 0.86113631159405257522};
constexpr double kGlW[4] = {0.34785484513745385737, 0.65214515486254614263,
                            0.65214515486254614263, 0.34785484513745385737};

/// A[g][j] = integral from -1 to x_g of the Lagrange basis polynomial L_j through the
/// four nodes: alpha(node g) = alpha(start) + h/2 sum_j A[g][j] alpha_dot(node j).
struct LagrangeIntegrals {
  double A[4][4];
  LagrangeIntegrals() {
    for (int j = 0; j < 4; ++j) {
      // Coefficients of L_j(x) = prod_{m != j} (x - x_m) / (x_j - x_m), low order first.
      double c[4] = {1, 0, 0, 0};
      double denom = 1.0;
      int deg = 0;
      for (int m = 0; m < 4; ++m) {
        if (m == j) continue;
        for (int d = deg + 1; d >= 0; --d) c[d] = (d > 0 ? c[d - 1] : 0.0) - kGlX[m] * c[d];
        ++deg;
        denom *= kGlX[j] - kGlX[m];
      }
      for (int g = 0; g < 4; ++g) {
        auto prim = [&](double x) {
          double s = 0.0, p = x;
          for (int d = 0; d < 4; ++d) {
            s += c[d] * p / (d + 1);
            p *= x;
          }
          return s;
        };
        A[g][j] = (prim(kGlX[g]) - prim(-1.0)) / denom;
      }
    }
  }
};
inline const LagrangeIntegrals kLagrange;

}  // namespace wheelins::sim
