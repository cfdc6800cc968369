// The Wheel-IMU installation calibrator of installation_calibration.hpp: whole-turn,
// angle-weighted means of the rate and specific force, the axle from their rotation
// vectors, the lever arm by a chunk-centred least-squares fit, each with a prior.
#include "wheelins/filter/installation_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace wheelins {

namespace {

constexpr double kTurn = 2.0 * kPi;
/// A sample interval longer than this is a gap in the data (a dropout, a removed stretch).
constexpr double kMaxGap = 0.1;

/// A data estimate (value, sigma; sigma = inf: no data) combined with a zero-mean-offset
/// Gaussian prior around `prior`.
CalibratedValue with_prior(double prior, double prior_std, double data, double data_std,
                           double observed_ratio) {
  CalibratedValue v;
  if (!(data_std < 1e300) || !std::isfinite(data)) {
    v.value = prior;
    v.std = prior_std;
    return v;
  }
  const double wp = 1.0 / (prior_std * prior_std), wd = 1.0 / (data_std * data_std);
  v.value = (wp * prior + wd * data) / (wp + wd);
  v.std = std::sqrt(1.0 / (wp + wd));
  v.observed = v.std < observed_ratio * prior_std;
  return v;
}

}  // namespace

WheelImuCalibrator::WheelImuCalibrator(const ImuModule& module, double static_start,
                                       double static_end, const InstallationCalibrationOptions& opt)
    : module_(module),
      opt_(opt),
      C_StoB_(dcm_from_euler(module.mounting_rpy)),
      static_start_(static_start),
      static_end_(static_end) {}

void WheelImuCalibrator::add(const ImuSample& s) {
  if (!(s.dt > 0.0)) return;
  t_ = s.t;
  if (s.t <= static_end_) {
    if (s.t > static_start_) {
      static_sum_ += s.dtheta;
      static_dt_ += s.dt;
    }
    return;
  }
  const Vec3 bias = static_dt_ > 0.0 ? Vec3(static_sum_ / static_dt_) : Vec3::Zero();
  const Vec3 w = C_StoB_ * (s.dtheta / s.dt - bias);
  const Vec3 f = C_StoB_ * (s.dvel / s.dt);
  const double wx = w.x();
  const double alpha = have_prev_ ? (wx - prev_wx_) / s.dt : 0.0;
  prev_wx_ = wx;
  have_prev_ = true;
  const int sign = wx > 0.0 ? 1 : -1;
  if (std::abs(wx) < opt_.min_spin_rate || (spin_sign_ != 0 && sign != spin_sign_) ||
      s.dt > kMaxGap) {
    // Stopped, reversing, or a gap in the data: the partial turn is dropped (its rotating
    // terms do not cancel).
    reset_turns();
    spin_sign_ = std::abs(wx) < opt_.min_spin_rate ? 0 : sign;
    return;
  }
  spin_sign_ = sign;
  rolling_time_ += s.dt;
  const double angle = std::abs(wx) * s.dt;
  spin_angle_ += angle;
  // Each of the kPhases accumulators starts its turns at its own phase of the rolling
  // sequence and splits the sample at its turn boundaries, so each turn spans exactly 2 pi.
  const double a0 = sequence_angle_, a1 = a0 + angle;
  for (int k = 0; k < kPhases; ++k) {
    TurnSums& turn = turn_[k];
    double pos = std::max(a0, k * kTurn / kPhases);
    while (pos < a1) {
      const double take = std::min(a1 - pos, kTurn - turn.angle);
      const double frac = take / angle;
      turn.angle += take;
      turn.dt += frac * s.dt;
      turn.c += wx * wx * take;
      turn.s += alpha * take;
      turn.f += f * take;
      turn.rot += (sign * frac * s.dt) * w;
      pos += take;
      if (turn.angle >= kTurn * (1.0 - 1e-12)) close_turn(k);
    }
  }
  sequence_angle_ = a1;
}

void WheelImuCalibrator::close_turn(int phase) {
  const TurnSums& turn = turn_[phase];
  const double c = turn.c / kTurn, sa = turn.s / kTurn;
  const Vec3 m = turn.f / kTurn;
  RegressionSums& k = chunk_;
  k.n += 1.0;
  k.c += c;
  k.s += sa;
  k.cc += c * c;
  k.ss += sa * sa;
  k.m += m;
  k.cm += c * m;
  k.sm += sa * m;
  k.mm += m * m.transpose();
  if (phase == 0) {
    axle_sum_ += turn.rot;
    const double len = turn.rot.norm();
    if (len > 0.0) {
      const Vec3 d = turn.rot / len;
      dir_sum_ += d;
      dir_sq_ += d * d.transpose();
    }
    ++turns_;
  }
  turn_[phase] = TurnSums{};
  if (t_ - chunk_start_ >= opt_.chunk_s) close_chunk();
}

void WheelImuCalibrator::close_chunk() {
  const RegressionSums& k = chunk_;
  if (k.n >= 2.0) {
    Scc_ += k.cc - k.c * k.c / k.n;
    Sss_ += k.ss - k.s * k.s / k.n;
    Scm_ += k.cm - k.c * k.m / k.n;
    Ssm_ += k.sm - k.s * k.m / k.n;
    Smm_ += k.mm - k.m * k.m.transpose() / k.n;
    chunks_ += 1.0;
    rows_ += 2.0 * k.n;
  }
  chunk_ = RegressionSums{};
  chunk_start_ = t_;
}

WheelImuCalibration WheelImuCalibrator::result() const {
  WheelImuCalibration r;
  r.module = module_.name;
  r.turns = turns_;
  r.spin_angle = spin_angle_;
  r.manifest_mounting_rpy = module_.mounting_rpy;
  r.manifest_lever_arm = module_.lever_arm_inB;
  const double inf = std::numeric_limits<double>::infinity();
  const bool enough = turns_ >= opt_.min_turns;

  // Axle: the direction of the summed rotation vectors, and the small rotation
  // delta = a x e_x that carries it onto b x. Its sigma: the scatter of the per-turn
  // directions over sqrt(turns), and a residual gyro bias over the rolling time.
  double dy = 0.0, dz = 0.0, sy = inf, sz = inf;
  if (enough && axle_sum_.norm() > 0.0) {
    const Vec3 a = axle_sum_.normalized();
    dy = a.z();
    dz = -a.y();
    const double n = turns_;
    const Vec3 mean = dir_sum_ / n;
    const double vy = std::max(0.0, (dir_sq_(1, 1) / n - mean.y() * mean.y()) * n / (n - 1.0));
    const double vz = std::max(0.0, (dir_sq_(2, 2) / n - mean.z() * mean.z()) * n / (n - 1.0));
    const double arw_static = static_dt_ > 0.0 ? module_.noise.gyro_arw / std::sqrt(static_dt_) : 0.0;
    const double bias_term = std::hypot(module_.noise.gyro_bias_std, arw_static) * rolling_time_ / spin_angle_;
    sy = std::sqrt(vz / n + bias_term * bias_term);  // delta_y is a_z
    sz = std::sqrt(vy / n + bias_term * bias_term);
  }
  r.axle_tilt_y = with_prior(0.0, opt_.mounting_prior_std, dy, sy, opt_.observed_ratio);
  r.axle_tilt_z = with_prior(0.0, opt_.mounting_prior_std, dz, sz, opt_.observed_ratio);
  const Mat3 R = dcm_from_rotvec(Vec3(0.0, r.axle_tilt_y.value, r.axle_tilt_z.value));
  r.mounting_rpy = euler_from_dcm(R * C_StoB_);

  // Lever arm, in the corrected frame: the chunk-centred sums (the open chunk included)
  // rotated by R; the normal matrix of (l_y, l_z) is (Scc + Sss) I.
  double Scc = Scc_, Sss = Sss_, rows = rows_, chunks = chunks_;
  Vec3 Scm = Scm_, Ssm = Ssm_;
  Mat3 Smm = Smm_;
  const RegressionSums& k = chunk_;
  if (k.n >= 2.0) {
    Scc += k.cc - k.c * k.c / k.n;
    Sss += k.ss - k.s * k.s / k.n;
    Scm += k.cm - k.c * k.m / k.n;
    Ssm += k.sm - k.s * k.m / k.n;
    Smm += k.mm - k.m * k.m.transpose() / k.n;
    chunks += 1.0;
    rows += 2.0 * k.n;
  }
  const Vec3 cm = R * Scm, sm = R * Ssm;
  const Mat3 mm = R * Smm * R.transpose();
  const double D = Scc + Sss;
  const double dof = rows - 2.0 * chunks - 2.0;
  double ly = 0.0, lz = 0.0, sl = inf;
  if (enough && D > 0.0 && dof > 0.0) {
    const double ry = cm.y() - sm.z(), rz = sm.y() + cm.z();
    ly = ry / D;
    lz = rz / D;
    const double rss = std::max(0.0, mm(1, 1) + mm(2, 2) - (ly * ry + lz * rz));
    const double s2 = rss / dof;
    r.accel_residual_rms = std::sqrt(s2);
    // The phases' turns overlap: kPhases times fewer independent rows. The accelerometer's
    // scale factor scales the centripetal term, and so the lever arm: a floor.
    const double sf = module_.noise.acc_sf_std * module_.lever_arm_inB.tail<2>().norm();
    sl = std::sqrt(kPhases * s2 / D + sf * sf);
  }
  const Vec3 prior = R * module_.lever_arm_inB;
  r.lever_arm[0] = CalibratedValue{prior.x(), opt_.lever_arm_prior_std, false};
  r.lever_arm[1] = with_prior(prior.y(), opt_.lever_arm_prior_std, ly, sl, opt_.observed_ratio);
  r.lever_arm[2] = with_prior(prior.z(), opt_.lever_arm_prior_std, lz, sl, opt_.observed_ratio);
  return r;
}

}  // namespace wheelins
