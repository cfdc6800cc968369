// The wheels' relative radii (docs/filter.md section 15): per module, a least-squares fit
// of the speed difference to the other side against the wheels' yaw rate, combined over the
// modules and with a prior.
#include "wheelins/calib/relative_radius.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "wheelins/calib/prior.hpp"

namespace wheelins {

using calib_detail::with_prior;

void estimate_relative_radius(const std::vector<const WheelImuCalibrator*>& cals,
                              const InstallationCalibrationOptions& opt,
                              std::vector<WheelImuCalibration>& results) {
  const std::size_t n_mod = cals.size();
  if (n_mod < 2 || results.size() != n_mod || !(opt.rate_bin_s > 0.0)) return;
  double ymin = std::numeric_limits<double>::infinity(), ymax = -ymin;
  for (const auto* c : cals) {
    ymin = std::min(ymin, c->module().p_inV.y());
    ymax = std::max(ymax, c->module().p_inV.y());
  }
  if (!(ymax - ymin > 0.05)) return;  // one side only (e.g. the chips of one wheel)
  const double mid = 0.5 * (ymin + ymax);
  std::vector<int> side(n_mod);
  double y_side[2] = {0.0, 0.0};
  int n_side[2] = {0, 0};
  std::size_t bins = std::numeric_limits<std::size_t>::max();
  for (std::size_t i = 0; i < n_mod; ++i) {
    side[i] = cals[i]->module().p_inV.y() < mid ? 0 : 1;  // 0: left (v-frame y is right)
    y_side[side[i]] += cals[i]->module().p_inV.y();
    ++n_side[side[i]];
    bins = std::min(bins, cals[i]->rate_bins().end_index());
  }
  // The bins any module has data in (below the shortest series' end), in order.
  std::vector<std::size_t> indices;
  for (const auto* c : cals)
    for (const auto& e : c->rate_bins().entries())
      if (e.index < bins) indices.push_back(e.index);
  std::sort(indices.begin(), indices.end());
  indices.erase(std::unique(indices.begin(), indices.end()), indices.end());
  y_side[0] /= n_side[0];
  y_side[1] /= n_side[1];

  // Per module i, against the other side's mean speed, the fit
  //   y = track psi_dot - (v_L - v_R) = g_i v_mean + kappa_i track psi_dot,
  // with g_i = eps_i - mean eps(right) for a left module, mean eps(left) - eps_i for a
  // right one (eps: a radius's relative error, the gyro's x scale factor included: the
  // speed the filter is given is r w_x). psi_dot: the mean yaw rate of every module.
  struct Fit {
    double S11 = 0, S12 = 0, S22 = 0, b1 = 0, b2 = 0, Syy = 0;
    int n = 0;
  };
  std::vector<Fit> fit(n_mod);
  std::vector<double> v(n_mod);
  std::vector<char> ok(n_mod);
  for (const std::size_t k : indices) {
    double v_side[2] = {0, 0}, yaw = 0;
    int m[2] = {0, 0};
    for (std::size_t i = 0; i < n_mod; ++i) {
      const RateBin* b = cals[i]->rate_bins().find(k);
      ok[i] = 0;
      if (!b || b->dt < 0.9 * opt.rate_bin_s) continue;  // a gap, or the last bin
      const double rate = b->yaw_rate(cals[i]->gravity());
      if (!std::isfinite(rate)) continue;  // too slow for a yaw rate
      v[i] = cals[i]->module().wheel_radius * b->spin / b->dt;
      v_side[side[i]] += v[i];
      yaw += rate;
      ++m[side[i]];
      ok[i] = 1;
    }
    if (m[0] == 0 || m[1] == 0) continue;
    const double psi_dot = yaw / (m[0] + m[1]);
    for (std::size_t i = 0; i < n_mod; ++i) {
      if (!ok[i]) continue;
      const int o = 1 - side[i];
      const double v_other = v_side[o] / m[o];
      const double vl = side[i] == 0 ? v[i] : v_other, vr = side[i] == 0 ? v_other : v[i];
      const double track = std::abs(cals[i]->module().p_inV.y() - y_side[o]);
      const double x1 = 0.5 * (vl + vr), x2 = track * psi_dot, y = x2 - (vl - vr);
      Fit& f = fit[i];
      f.S11 += x1 * x1;
      f.S12 += x1 * x2;
      f.S22 += x2 * x2;
      f.b1 += x1 * y;
      f.b2 += x2 * y;
      f.Syy += y * y;
      ++f.n;
    }
  }
  std::vector<double> g(n_mod, 0.0), sg(n_mod, std::numeric_limits<double>::infinity());
  double D = 0.0, var_D = 0.0;
  for (std::size_t i = 0; i < n_mod; ++i) {
    const Fit& f = fit[i];
    const double det = f.S11 * f.S22 - f.S12 * f.S12;
    if (f.n <= 30 || !(det > 1e-12 * f.S11 * f.S22)) return;  // too little rolling: not observed
    g[i] = (f.S22 * f.b1 - f.S12 * f.b2) / det;
    const double kappa = (f.S11 * f.b2 - f.S12 * f.b1) / det;
    const double s2 = std::max(0.0, f.Syy - g[i] * f.b1 - kappa * f.b2) / (f.n - 2);
    sg[i] = std::sqrt(s2 * f.S22 / det);
    D += g[i];
    var_D += sg[i] * sg[i];
  }
  // D = mean eps(left) - mean eps(right), from every module's fit; each radius is corrected
  // by its share about the two sides' mean: eps_i - (mean eps(left) + mean eps(right)) / 2.
  D /= static_cast<double>(n_mod);
  var_D /= static_cast<double>(n_mod * n_mod);
  for (std::size_t i = 0; i < n_mod; ++i) {
    const double c = side[i] == 0 ? g[i] - 0.5 * D : -g[i] + 0.5 * D;
    const double sc = std::sqrt(sg[i] * sg[i] + 0.25 * var_D);
    const CalibratedValue rel = with_prior(0.0, opt.radius_prior_std, c, sc, opt.observed_ratio);
    const double m0 = cals[i]->module().wheel_radius;
    results[i].wheel_radius = CalibratedValue{m0 * (1.0 + rel.value), m0 * rel.std, rel.observed};
  }
}

}  // namespace wheelins
