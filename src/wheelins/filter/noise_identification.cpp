#include "wheelins/filter/noise_identification.hpp"

#include <algorithm>
#include <cmath>

namespace wheelins {

void AllanAccumulator::add(const Vec3& y, double dt) {
  ++samples_;
  sum_dt_ += dt;
  push(0, y);
}

void AllanAccumulator::push(int level, const Vec3& cluster_mean) {
  // A finished cluster of this level: its difference to the previous one, and half of a
  // cluster of the next level (two consecutive clusters make one of twice the size).
  Level& l = lv_[level];
  if (l.has_prev) {
    l.sum_sq += (cluster_mean - l.prev_mean).cwiseAbs2();
    ++l.n_diff;
  }
  l.prev_mean = cluster_mean;
  l.has_prev = true;
  if (level + 1 >= kLevels) return;
  Level& up = lv_[level + 1];
  up.sum += cluster_mean;
  if (++up.count == 2) {
    const Vec3 mean = 0.5 * up.sum;
    up.sum.setZero();
    up.count = 0;
    push(level + 1, mean);
  }
}

Vec3 AllanAccumulator::variance(int level) const {
  const Level& l = lv_[level];
  if (l.n_diff == 0) return Vec3::Zero();
  return l.sum_sq / (2.0 * static_cast<double>(l.n_diff));
}

SensorNoiseEstimate estimate_sensor_noise(const AllanAccumulator& a) {
  SensorNoiseEstimate e;
  if (a.samples() < 200) return e;
  e.valid = true;
  e.duration = a.mean_dt() * static_cast<double>(a.samples());
  // The white noise: on its line sigma_A^2 tau is the same at every tau. A vibration (the
  // engine's 22 Hz on the real car, standing with it running) has a sigma_A^2 falling as
  // tau^-2: at the sample interval it reads as an angle random walk several times the
  // chip's, although it does not integrate into the heading. A bias instability or a random
  // walk makes sigma_A^2 tau rise. So N is read at the shortest cluster time l such that no
  // longer cluster time's sigma_A^2 tau is below l's by more than 3 of their scatters (a
  // relative scatter of 1 / sqrt(M) for M differences).
  const auto usable = [&](int l) {
    return l == 0 || (a.differences(l) >= kWhiteMinDifferences && a.tau(l) <= kWhiteTauMax);
  };
  const auto density = [&](int l) { return a.variance(l).mean() * a.tau(l); };
  const auto inv_m = [&](int l) {
    return 1.0 / static_cast<double>(std::max<std::uint64_t>(a.differences(l), 1));
  };
  int wl = 0;
  for (int l = 0; l < AllanAccumulator::kLevels; ++l) {
    if (!usable(l)) continue;
    bool below = false;
    for (int j = l + 1; j < AllanAccumulator::kLevels && !below; ++j)
      below = usable(j) && density(j) < density(l) * (1.0 - 3.0 * std::sqrt(inv_m(l) + inv_m(j)));
    if (!below) {
      wl = l;
      break;
    }
  }
  const double tw = a.tau(wl);
  const Vec3 vw = a.variance(wl);
  e.white_axes = (vw * tw).cwiseSqrt();
  e.white = std::sqrt(vw.mean() * tw);
  e.white_tau = tw;
  // Bias instability: the minimum of sigma_A (RMS over the axes) over the levels with at
  // least 8 differences; at the last such level the floor is not known to be reached.
  int last = 0;
  for (int l = 0; l < AllanAccumulator::kLevels; ++l)
    if (a.differences(l) >= 8) last = l;
  double best = INFINITY;
  int best_level = 0;
  for (int l = 0; l <= last; ++l) {
    const double s = std::sqrt(a.variance(l).mean());
    if (s < best) {
      best = s;
      best_level = l;
    }
  }
  e.bias_instability = best / 0.664;
  e.bias_tau = a.tau(best_level);
  e.floor_reached = best_level < last;
  return e;
}

void VelocityNoiseMatcher::reset(const Options& opt, double vrw_prior, double vrw_floor,
                                 const Vec3& r_nominal) {
  *this = VelocityNoiseMatcher();
  opt_ = opt;
  q_floor_ = vrw_floor * vrw_floor;
  q_ = std::clamp(vrw_prior * vrw_prior, q_floor_, opt.vrw_max * opt.vrw_max);
  r0_ = r_nominal;
  r_ = r_nominal;
}

void VelocityNoiseMatcher::add(const Vec3& dz, const Vec3& S_diag, double dt) {
  const double lam = 1.0 - 1.0 / opt_.window;
  const Vec3 K = (S_diag - r_).cwiseQuotient(S_diag);
  c0_ = lam * c0_ + dz.cwiseAbs2();
  s_ = lam * s_ + S_diag;
  k_ = lam * k_ + K;
  dt_ = lam * dt_ + dt;
  w_ = lam * w_ + 1.0;
  if (have_prev_) {
    c1_ = lam * c1_ + dz.cwiseProduct(prev_);
    w1_ = lam * w1_ + 1.0;
  }
  prev_ = dz;
  have_prev_ = true;
  if (!adapted()) return;
  const Vec3 C0 = c0_ / w_, C1 = c1_ / w1_, Km = k_ / w_;
  const double step = dt_ / w_;
  const Vec3 floor = opt_.r_floor_fraction * opt_.r_floor_fraction * r0_;
  Vec3 qdt;
  for (int i = 0; i < 3; ++i) {
    const double P = C1(i) + Km(i) * C0(i);
    const double R = (1.0 - Km(i)) * C0(i) - C1(i);
    r_(i) = std::max(floor(i), R);
    qdt(i) = Km(i) * (2.0 - Km(i)) * P - Km(i) * Km(i) * R;
  }
  q_ = std::clamp(0.5 * (qdt(1) + qdt(2)) / step, q_floor_, opt_.vrw_max * opt_.vrw_max);
}

Vec3 VelocityNoiseMatcher::nis_axes() const {
  if (w_ <= 0.0) return Vec3::Ones();
  return c0_.cwiseQuotient(s_);
}

void BiasInstabilityMatcher::reset(double window, double sigma_prior, double sigma_floor,
                                   double tau) {
  window_ = window;
  prior_ = sigma_prior;
  floor_ = std::min(sigma_floor, sigma_prior);
  tau_ = tau;
  sigma_ = sigma_prior;
  sum_ = w_ = 0.0;
}

void BiasInstabilityMatcher::add(const Vec3& correction, double dt) {
  const double lam = 1.0 - 1.0 / window_;
  sum_ = lam * sum_ + correction.cwiseAbs2().maxCoeff() / dt;
  w_ = lam * w_ + 1.0;
  if (w_ < 0.3 * window_) return;
  // q = 2 sigma^2 / tau (the Gauss-Markov driving noise of eq. 2's bias states).
  const double q = sum_ / w_;
  sigma_ = std::clamp(std::sqrt(q * tau_ / 2.0), floor_, prior_);
}

}  // namespace wheelins
