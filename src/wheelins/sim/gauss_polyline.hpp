// A polyline smoothed by a Gaussian kernel, with exact derivatives of any order.
//
// A piecewise-linear function p(u) through knots (u_i, P_i) (P in R^D), extended
// beyond its ends with given slopes, convolved with a Gaussian of standard
// deviation sigma:  p~(u) = integral p(u') G_sigma(u - u') du'.
// The result is C-infinity and has closed forms:
//   p~(u)   = sum over segments of P-terms times Phi differences and phi terms,
//   p~'(u)  = sum_i T_i [Phi((u_{i+1}-u)/s) - Phi((u_i-u)/s)]      (T_i: segment slopes)
//   p~^(k)(u) = sum_j (T_j+ - T_j-) G_sigma^(k-2)(u - u_j),  k >= 2 (G^(m): Hermite x Gaussian)
// Only knots within 10 sigma of u contribute (the rest is below 1e-22 relative).
//
// Used twice by the simulator: a path (D = 2, north/east against polyline arc length,
// corners rounded to turns of radius ~sigma) and a time-to-arc-length profile (D = 1,
// the integrated speed against time: the smoothed speed is the piecewise-constant
// speed convolved with the Gaussian, never negative, and its integral is preserved).
#pragma once

#include <array>
#include <vector>

namespace wheelins::sim {

template <int D>
class GaussPolyline {
 public:
  using Point = std::array<double, D>;
  static constexpr int kMaxDeriv = 6;

  GaussPolyline() = default;
  /// `u` strictly increasing (at least 2 knots), `p` the values; `slope_before`/`slope_after`
  /// the slopes of the linear extensions beyond the first/last knot.
  GaussPolyline(std::vector<double> u, std::vector<Point> p, double sigma, Point slope_before,
                Point slope_after);

  /// out[k][d] = d^k p~_d / du^k at u, for k = 0..kmax (kmax <= kMaxDeriv).
  void eval(double u, int kmax, Point* out) const;

  double sigma() const { return sigma_; }
  const std::vector<double>& knots() const { return u_; }
  const std::vector<Point>& values() const { return p_; }

 private:
  std::vector<double> u_;
  std::vector<Point> p_;
  std::vector<Point> slope_;  // slope_[i] on segment i (u_i, u_i+1); size n-1
  Point before_{}, after_{};
  double sigma_ = 1.0;
};

extern template class GaussPolyline<1>;
extern template class GaussPolyline<2>;

}  // namespace wheelins::sim
