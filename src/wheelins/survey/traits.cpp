// One module's traits and signals from its data alone (traits.hpp).
#include "wheelins/survey/traits.hpp"

#include <algorithm>
#include <cmath>

namespace wheelins::survey {
namespace {

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

/// Runs of true bins at least `min_len` seconds long.
std::vector<Interval> runs(const Series& s, const std::vector<std::uint8_t>& mask, double min_len) {
  std::vector<Interval> out;
  const std::size_t n = mask.size();
  std::size_t k = 0;
  while (k < n) {
    if (!mask[k]) {
      ++k;
      continue;
    }
    std::size_t j = k;
    while (j < n && mask[j]) ++j;
    const Interval iv{s.t0 + static_cast<double>(k) * s.dt, s.t0 + static_cast<double>(j) * s.dt};
    if (iv.length() >= min_len) out.push_back(iv);
    k = j;
  }
  return out;
}

/// Rest bins of a spinning module: its spin-axis rate, smoothed over 0.2 s, within
/// `rest_rate` of the rate it has when barely turning (its bias).
std::vector<std::uint8_t> wheel_rest(const Series& s, int axis, double rest_rate, double* bias) {
  const std::size_t n = s.size();
  std::vector<double> w(n);
  for (std::size_t k = 0; k < n; ++k) w[k] = s.gyro[k][axis];
  std::vector<double> slow;
  for (double x : w)
    if (std::abs(x) < 0.3) slow.push_back(x);
  *bias = slow.size() >= 100 ? percentile(slow, 0.5) : 0.0;
  const std::vector<double> m = moving_average(w, std::max(1, static_cast<int>(std::lround(0.2 / s.dt))));
  std::vector<std::uint8_t> rest(n, 0);
  for (std::size_t k = 0; k < n; ++k) rest[k] = std::abs(m[k] - *bias) < rest_rate;
  return rest;
}

/// Rest bins of a module that does not spin: the spreads of its rate and of its specific
/// force over 0.5 s both within `factor` times the quietest tenth of the recording's.
std::vector<std::uint8_t> body_rest(const Series& s, double factor) {
  const std::size_t n = s.size();
  const std::size_t w = std::max<std::size_t>(2, static_cast<std::size_t>(std::lround(0.5 / s.dt)));
  std::vector<double> spread_g(n, 1e300), spread_f(n, 1e300);
  std::vector<double> windows_g, windows_f;
  auto sd = [&](const std::vector<Vec3>& x, std::size_t k) {
    Vec3 mean = Vec3::Zero();
    for (std::size_t j = k; j < k + w; ++j) mean += x[j];
    mean /= static_cast<double>(w);
    double ss = 0.0;
    for (std::size_t j = k; j < k + w; ++j) ss += (x[j] - mean).squaredNorm();
    return std::sqrt(ss / static_cast<double>(w));
  };
  for (std::size_t k = 0; k + w <= n; k += w) {
    const double g = sd(s.gyro, k), f = sd(s.accel, k);
    for (std::size_t j = k; j < k + w; ++j) spread_g[j] = g, spread_f[j] = f;
    windows_g.push_back(g);
    windows_f.push_back(f);
  }
  for (std::size_t k = n - n % w; k < n && n >= w; ++k) {
    spread_g[k] = spread_g[n - n % w - 1];
    spread_f[k] = spread_f[n - n % w - 1];
  }
  const double quiet_g = percentile(windows_g, 0.1), quiet_f = percentile(windows_f, 0.1);
  std::vector<std::uint8_t> rest(n, 0);
  for (std::size_t k = 0; k < n; ++k) rest[k] = spread_g[k] <= factor * quiet_g && spread_f[k] <= factor * quiet_f;
  return rest;
}

}  // namespace

ModuleTraits analyse_module(const Series& s, const TraitOptions& o) {
  ModuleTraits t;
  t.module = s.module;
  const std::size_t n = s.size();
  if (n == 0) return t;
  // The candidate spin axis: the most rotation over the whole series.
  Vec3 energy = Vec3::Zero();
  for (const Vec3& g : s.gyro) energy += g.cwiseAbs2();
  energy.maxCoeff(&t.spin_axis);
  double bias_axis = 0.0;
  std::vector<std::uint8_t> rest = wheel_rest(s, t.spin_axis, o.rest_rate, &bias_axis);
  // In motion: the share of the spin axis, its rate, its direction.
  Vec3 e = Vec3::Zero();
  std::vector<double> moving;
  double sum = 0.0, sum_abs = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    if (rest[k]) continue;
    Vec3 g = s.gyro[k];
    g[t.spin_axis] -= bias_axis;
    e += g.cwiseAbs2();
    const double w = g[t.spin_axis];
    moving.push_back(std::abs(w));
    sum += w;
    sum_abs += std::abs(w);
  }
  if (!moving.empty() && e.sum() > 0.0) {
    t.spin_share = e[t.spin_axis] / e.sum();
    t.spin_p95 = percentile(moving, 0.95);
    t.spin_direction = sum_abs > 0.0 ? sum / sum_abs : 0.0;
  }
  t.spins = t.spin_p95 > o.min_spin_rate && t.spin_share > o.min_spin_share;
  if (!t.spins) rest = body_rest(s, o.body_rest_factor);
  std::size_t moving_bins = 0;
  for (auto r : rest) moving_bins += !r;
  t.motion_time = static_cast<double>(moving_bins) * s.dt;
  t.rest = runs(s, rest, o.min_rest);
  // Bias and up-axis from the rest intervals; without any, the whole series' mean.
  Vec3 gs = Vec3::Zero(), fs = Vec3::Zero();
  std::size_t m = 0;
  for (const Interval& iv : t.rest)
    for (std::size_t k = s.index(iv.start); k < s.size() && s.time(k) < iv.end; ++k) {
      gs += s.gyro[k];
      fs += s.accel[k];
      ++m;
    }
  t.rest_found = m > 0;
  if (!t.rest_found) {
    for (std::size_t k = 0; k < n; ++k) fs += s.accel[k];
    m = n;
  }
  t.gyro_bias = t.rest_found ? Vec3(gs / static_cast<double>(m)) : Vec3::Zero();
  if (fs.norm() > 0.0) t.up = fs.normalized();
  return t;
}

std::vector<double> spin_rate(const Series& s, const ModuleTraits& t) {
  std::vector<double> w(s.size());
  for (std::size_t k = 0; k < s.size(); ++k) w[k] = s.gyro[k][t.spin_axis] - t.gyro_bias[t.spin_axis];
  return w;
}

std::vector<std::uint8_t> rest_mask(const Series& s, const ModuleTraits& t) {
  std::vector<std::uint8_t> mask(s.size(), 0);
  for (const Interval& iv : t.rest)
    for (std::size_t k = s.index(iv.start); k < s.size() && s.time(k) < iv.end; ++k) mask[k] = 1;
  return mask;
}

std::vector<double> yaw_rate(const Series& s, const ModuleTraits& t) {
  const std::size_t n = s.size();
  std::vector<double> yaw(n, 0.0);
  if (!t.spins) {
    for (std::size_t k = 0; k < n; ++k) yaw[k] = (s.gyro[k] - t.gyro_bias).dot(t.up);
    return yaw;
  }
  const int a = t.spin_axis, p = (a + 1) % 3, q = (a + 2) % 3;
  const std::vector<double> w = spin_rate(s, t);
  std::vector<double> wdot(n, 0.0);
  for (std::size_t k = 1; k + 1 < n; ++k) wdot[k] = (w[k + 1] - w[k - 1]) / (2.0 * s.dt);
  // The in-plane rate without the spin that leaks into it: least squares on the spin rate.
  auto leak = [&](int axis) {
    double sxy = 0.0, sxx = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      sxy += (s.gyro[k][axis] - t.gyro_bias[axis]) * w[k];
      sxx += w[k] * w[k];
    }
    return sxx > 0.0 ? sxy / sxx : 0.0;
  };
  const double cp = leak(p), cq = leak(q);
  // The in-plane specific force without its centripetal and tangential parts (a sensor off
  // the hub): least squares on [1, w^2, dw/dt] per axis.
  auto clean_force = [&](int axis) {
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    Vec3 b = Vec3::Zero();
    for (std::size_t k = 0; k < n; ++k) {
      const Vec3 r(1.0, w[k] * w[k], wdot[k]);
      A += r * r.transpose();
      b += r * s.accel[k][axis];
    }
    const Vec3 c = A.ldlt().solve(b);
    std::vector<double> f(n);
    for (std::size_t k = 0; k < n; ++k)
      f[k] = s.accel[k][axis] - (c.allFinite() ? c.dot(Vec3(1.0, w[k] * w[k], wdot[k])) : 0.0);
    return f;
  };
  const int smooth = std::max(1, static_cast<int>(std::lround(0.05 / s.dt)));
  const std::vector<double> fp = moving_average(clean_force(p), smooth);
  const std::vector<double> fq = moving_average(clean_force(q), smooth);
  for (std::size_t k = 0; k < n; ++k) {
    const double norm = std::hypot(fp[k], fq[k]);
    if (!(norm > 1.0)) continue;  // no usable vertical (free fall, or a sensor far off the hub)
    const double gp = s.gyro[k][p] - t.gyro_bias[p] - cp * w[k];
    const double gq = s.gyro[k][q] - t.gyro_bias[q] - cq * w[k];
    yaw[k] = (gp * fp[k] + gq * fq[k]) / norm;
  }
  return yaw;
}

}  // namespace wheelins::survey
