// The Gaussian-smoothed polyline of gauss_polyline.hpp.
#include "wheelins/sim/gauss_polyline.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace wheelins::sim {
namespace {
constexpr double kInvSqrt2Pi = 0.39894228040143267794;
constexpr double kWindow = 10.0;  // in sigmas

double phi(double z) { return kInvSqrt2Pi * std::exp(-0.5 * z * z); }
double Phi(double z) { return 0.5 * std::erfc(-z * 0.70710678118654752440); }
}  // namespace

template <int D>
GaussPolyline<D>::GaussPolyline(std::vector<double> u, std::vector<Point> p, double sigma,
                                Point slope_before, Point slope_after)
    : u_(std::move(u)), p_(std::move(p)), before_(slope_before), after_(slope_after), sigma_(sigma) {
  if (u_.size() < 2 || u_.size() != p_.size())
    throw std::invalid_argument("GaussPolyline: need at least two knots and one value per knot");
  if (!(sigma_ > 0.0)) throw std::invalid_argument("GaussPolyline: sigma must be positive");
  slope_.resize(u_.size() - 1);
  for (std::size_t i = 0; i + 1 < u_.size(); ++i) {
    const double du = u_[i + 1] - u_[i];
    if (!(du > 0.0)) throw std::invalid_argument("GaussPolyline: knots must increase strictly");
    for (int d = 0; d < D; ++d) slope_[i][d] = (p_[i + 1][d] - p_[i][d]) / du;
  }
}

template <int D>
void GaussPolyline<D>::eval(double u, int kmax, Point* out) const {
  if (kmax > kMaxDeriv) throw std::invalid_argument("GaussPolyline: derivative order too high");
  for (int k = 0; k <= kmax; ++k) out[k].fill(0.0);
  const double s = sigma_;
  const std::size_t n = u_.size();
  // Knots j in [lo, hi) lie within the window.
  const std::size_t lo =
      std::lower_bound(u_.begin(), u_.end(), u - kWindow * s) - u_.begin();
  const std::size_t hi =
      std::upper_bound(u_.begin(), u_.end(), u + kWindow * s) - u_.begin();

  // Segment / extension contributions to the value and the first derivative.
  auto add_piece = [&](const Point& Pa, double a, const Point& T, double alpha_z, double beta_z,
                       double dPhi) {
    // integral over [a, b] of (Pa + T (u' - a)) G(u - u') du'
    const double dphi = phi(alpha_z) - phi(beta_z);
    for (int d = 0; d < D; ++d) {
      out[0][d] += (Pa[d] + T[d] * (u - a)) * dPhi + T[d] * s * dphi;
      if (kmax >= 1) out[1][d] += T[d] * dPhi;
    }
  };
  const std::size_t seg_lo = lo > 0 ? lo - 1 : 0;     // segments overlapping the window
  const std::size_t seg_hi = std::min(hi, n - 1);     // segment i spans knots i, i+1
  for (std::size_t i = seg_lo; i < seg_hi; ++i) {
    const double az = (u_[i] - u) / s, bz = (u_[i + 1] - u) / s;
    add_piece(p_[i], u_[i], slope_[i], az, bz, Phi(bz) - Phi(az));
  }
  if (lo == 0) {  // the extension before the first knot: (-inf, u_0]
    const double bz = (u_[0] - u) / s;
    const double P = Phi(bz);
    for (int d = 0; d < D; ++d) {
      out[0][d] += (p_[0][d] + before_[d] * (u - u_[0])) * P - before_[d] * s * phi(bz);
      if (kmax >= 1) out[1][d] += before_[d] * P;
    }
  }
  if (hi == n) {  // the extension after the last knot: [u_n-1, inf)
    const double az = (u_[n - 1] - u) / s;
    const double Q = Phi(-az);  // 1 - Phi(az), accurately
    for (int d = 0; d < D; ++d) {
      out[0][d] += (p_[n - 1][d] + after_[d] * (u - u_[n - 1])) * Q + after_[d] * s * phi(az);
      if (kmax >= 1) out[1][d] += after_[d] * Q;
    }
  }
  if (kmax < 2) return;
  // Higher derivatives: slope jumps at the knots times derivatives of the Gaussian.
  // G_s^(m)(x) = (-1)^m He_m(x/s) phi(x/s) / s^(m+1).
  for (std::size_t j = lo; j < hi; ++j) {
    const Point& Tm = j == 0 ? before_ : slope_[j - 1];
    const Point& Tp = j == n - 1 ? after_ : slope_[j];
    const double z = (u - u_[j]) / s;
    const double g = phi(z) / s;
    double he_prev = 1.0, he = z;  // He_0, He_1
    double inv_s_pow = 1.0;
    for (int k = 2; k <= kmax; ++k) {
      const int m = k - 2;
      double hm;
      if (m == 0) {
        hm = 1.0;
      } else if (m == 1) {
        hm = z;
      } else {
        const double next = z * he - (m - 1) * he_prev;  // He_m = z He_{m-1} - (m-1) He_{m-2}
        he_prev = he;
        he = next;
        hm = he;
      }
      const double w = ((m % 2) ? -1.0 : 1.0) * hm * g * inv_s_pow;
      for (int d = 0; d < D; ++d) out[k][d] += (Tp[d] - Tm[d]) * w;
      inv_s_pow /= s;
    }
  }
}

template class GaussPolyline<1>;
template class GaussPolyline<2>;

}  // namespace wheelins::sim
