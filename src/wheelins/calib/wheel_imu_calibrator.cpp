// A Wheel-IMU's axle and lever arm (docs/filter.md section 15): whole-turn,
// angle-weighted means of the rate and specific force, the axle from their rotation
// vectors, the lever arm by a chunk-centred least-squares fit, each with a prior.
#include "wheelins/calib/wheel_imu_calibrator.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "wheelins/calib/prior.hpp"

namespace wheelins {

namespace {

constexpr double kTurn = 2.0 * kPi;

}  // namespace

using calib_detail::kMaxGap;
using calib_detail::rate_bin_index;
using calib_detail::reserve_bins;
using calib_detail::std_of_mean;
using calib_detail::with_prior;

WheelImuCalibrator::WheelImuCalibrator(const ImuModule& module, double static_start,
                                       double static_end, const InstallationCalibrationOptions& opt,
                                       double expected_end)
    : module_(module),
      opt_(opt),
      C_StoB_(wheel_sensor_to_body(module)),
      static_{static_start, static_end} {
  reserve_bins(bins_, static_end, expected_end, opt_.rate_bin_s);
  reserve_bins(axle_bins_, static_end, expected_end, opt_.yaw_bin_s);
}

void WheelImuCalibrator::add(const ImuSample& s) {
  if (!(s.dt > 0.0)) return;
  t_ = s.t;
  if (static_.take(s)) return;
  const Vec3 bias = static_.gyro_bias();
  const Vec3 w = C_StoB_ * (s.dtheta / s.dt - bias);
  const Vec3 f = C_StoB_ * (s.dvel / s.dt);
  const double wx = w.x();
  wheel_angle_ = std::fmod(wheel_angle_ + wx * s.dt, kTurn);
  if (s.dt <= kMaxGap) {
    const std::ptrdiff_t j = rate_bin_index(s, static_.end, opt_.yaw_bin_s);
    if (j >= 0) {  // the series of estimate_body_yaw()
      AxleBin& a = axle_bins_.at(static_cast<std::size_t>(j));
      a.dt += s.dt;
      a.f += f * s.dt;
    }
    // The rate series (RateBin::yaw_rate()).
    const std::ptrdiff_t k = rate_bin_index(s, static_.end, opt_.rate_bin_s);
    if (k >= 0) {
      RateBin& b = bins_.at(static_cast<std::size_t>(k));
      b.dt += s.dt;
      b.spin += -module_.axle_sign * wx * s.dt;
      b.wf += (w.y() * f.y() + w.z() * f.z()) * s.dt;
      b.w_y += w.y() * s.dt;
      b.w_z += w.z() * s.dt;
      b.f_y += f.y() * s.dt;
      b.f_z += f.z() * s.dt;
      const double a_mid = wheel_angle_ + 0.5 * wx * s.dt;
      b.cos_a += std::cos(a_mid) * s.dt;
      b.sin_a += std::sin(a_mid) * s.dt;
    }
  }
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
      dir_sq_ += d.cwiseProduct(d);
    }
    ++turns_;
  }
  turn_[phase] = TurnSums{};
  if (t_ - chunk_start_ >= opt_.chunk_s) close_chunk();
}

void WheelImuCalibrator::close_chunk() {
  closed_.add(chunk_);
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
    const double arw_static = static_.gyro_bias_noise(module_.noise.gyro_arw);
    const double bias_term = std::hypot(module_.noise.gyro_bias_std, arw_static) * rolling_time_ / spin_angle_;
    sy = std_of_mean(dir_sum_.z(), dir_sq_.z(), n, bias_term);  // delta_y is a_z
    sz = std_of_mean(dir_sum_.y(), dir_sq_.y(), n, bias_term);
  }
  r.axle_tilt_y = with_prior(0.0, opt_.mounting_prior_std, dy, sy, opt_.observed_ratio);
  r.axle_tilt_z = with_prior(0.0, opt_.mounting_prior_std, dz, sz, opt_.observed_ratio);
  const Mat3 R = dcm_from_rotvec(Vec3(0.0, r.axle_tilt_y.value, r.axle_tilt_z.value));
  r.mounting_rpy = euler_from_dcm(R * C_StoB_ * axle_axis_permutation(module_.axle_axis).transpose());

  // Lever arm, in the corrected frame: the chunk-centred sums (the open chunk included)
  // rotated by R; the normal matrix of (l_y, l_z) is (cc + ss) I.
  CentredSums all = closed_;
  all.add(chunk_);
  const Vec3 cm = R * all.cm, sm = R * all.sm;
  const Mat3 mm = R * all.mm * R.transpose();
  const double D = all.cc + all.ss;
  const double dof = all.rows - 2.0 * all.chunks - 2.0;
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
  r.manifest_wheel_radius = module_.wheel_radius;
  r.wheel_radius = CalibratedValue{module_.wheel_radius, opt_.radius_prior_std * module_.wheel_radius, false};
  return r;
}

}  // namespace wheelins
