// The measurement builders of measurement.hpp: the shared inputs taken at one evaluation
// point, and the velocity (eq. 5, 6) and position-constraint (eq. 11) measurements.
#include "wheelins/fusion/measurement.hpp"

#include <algorithm>
#include <cmath>

namespace wheelins {

namespace {

/// Adds, to the Body-INS block, the dependence of a Wheel-INS model on the shared level:
/// H_level * d(roll, pitch)/d(phi_body), scaled by `c`.
void add_level_block(const Subsystems& subs, const SharedInputs& sh,
                     const Eigen::Matrix<double, 3, 2>& H_level, double c, Measurement& m) {
  if (!sh.level_shared || c == 0.0) return;
  m.H[subs.body_index()].block<3, 3>(0, PHI) += c * H_level * sh.level_sensitivity;
}

}  // namespace

void take_level(const Subsystems& subs, bool shared, bool now, SharedInputs& sh) {
  sh.level_shared = shared;
  sh.level_now = shared && now;
  if (!shared) return;
  sh.level_sensitivity = vehicle_level_sensitivity(subs.body().C_VtoW());
  if (now) sh.level_rpy = subs.body().vehicle_rpy();
}

void take_wheel_inputs(const Subsystems& subs, const std::array<bool, kMaxModules>& in_use,
                       SharedInputs& sh) {
  for (int i = 0; i < subs.size(); ++i) {
    sh.turn_valid[i] = false;
    if (!subs.is_wheel(i) || !in_use[i]) continue;
    WheelVelocityInput& in = sh.wheel[i] = subs.wheel(i).own_velocity_input();
    if (sh.level_now) {
      in.vehicle_roll = sh.level_rpy.x();
      in.vehicle_pitch = sh.level_rpy.y();
    }
    sh.turn_valid[i] = subs.wheel(i).turn_averaged(in, sh.turn[i], sh.turn_speed[i]);
  }
}

void take_mean_speed(const Subsystems& subs, const SpeedSelection& sel, SharedInputs& sh) {
  sh.speeds = sel;
  sh.mean_speed = 0.0;
  sh.mean_point.setZero();
  // A steered wheel's speed along the wheel is the vehicle's forward speed over
  // cos(steering), which is the speed of the point on the rear axle's line beside it.
  for (int j = 0; j < subs.size(); ++j)
    if (sel.in_mean[j]) {
      const WheelIns& w = subs.wheel(j);
      sh.mean_speed += sh.wheel[j].measured_speed * std::cos(sh.wheel[j].steering);
      sh.mean_point += w.speed_point_inV();
    }
  if (sel.n_mean) {
    sh.mean_speed /= sel.n_mean;
    sh.mean_point /= sel.n_mean;
  }
  sh.turn_mean_ok = sel.n_mean > 0;
  sh.turn_mean_speed = 0.0;
  for (int j = 0; j < subs.size(); ++j)
    if (sel.in_mean[j]) {
      sh.turn_mean_ok = sh.turn_mean_ok && sh.turn_valid[j];
      sh.turn_mean_speed += sh.turn_speed[j].measured_speed;
    }
  if (sh.turn_mean_ok) sh.turn_mean_speed /= sel.n_mean;
}

void take_reference(const Subsystems& subs, SharedInputs& sh) {
  sh.fused.setZero();
  for (int j = 0; j < subs.size(); ++j) {
    ReferencePointInput in = subs[j].reference_point_input();
    if (sh.level_now && in.wheel) {
      in.vehicle_roll = sh.level_rpy.x();
      in.vehicle_pitch = sh.level_rpy.y();
    }
    sh.ref[j] = reference_point_model(in);
    sh.fused += sh.k[j] * sh.ref[j].r_o;
  }
}

void velocity_measurement(const Subsystems& subs, const SharedInputs& sh, const FusionOptions& o,
                          int i, bool mean_offset_noise, Measurement& m) {
  m.reset(i, subs.size());
  m.velocity = true;
  const SpeedSelection& sel = sh.speeds;
  const int n_mean = sel.n_mean;
  bool mean = false;  // the measured speed is the mean: its sensitivities are added below
  bool turn = false;  // ... of the whole-turn speeds
  if (subs.is_wheel(i)) {
    const WheelIns& w = subs.wheel(i);
    WheelVelocityInput in = sh.wheel[i];
    m.R = w.velocity_noise();
    if (sel.speed_ok[i]) {
      // Its own speed (in.dspeed_* stay this IMU's), or the mean it is part of.
      mean = o.speed == SpeedSharing::kMean && n_mean > 1 && sel.in_mean[i];
    } else if (n_mean > 0) {
      mean = true;  // its own speed is unusable: the mean of the others'
    } else {
      // No speed at all: the NHC rows only.
      in.dspeed_dbgx = in.dspeed_dsgx = 0.0;
      m.R(0, 0) = kNoSpeedVar;
    }
    if (mean) {
      in.measured_speed = sh.mean_speed / std::cos(in.steering);  // along this wheel
      in.dspeed_dbgx = in.dspeed_dsgx = 0.0;
    }
    // Over whole turns when this wheel averages and every speed it uses has the same mean.
    const bool no_speed = !sel.speed_ok[i] && n_mean == 0;
    turn = sh.turn_valid[i] && (no_speed || !mean || sh.turn_mean_ok);
    WheelVelocityModel wm;
    if (turn) {
      wm = sh.turn[i].model;
      const WheelVelocityInput& own = sh.turn_speed[i];
      if (no_speed) set_measured_speed(wm, in.measured_speed, 0.0, 0.0);
      else if (mean) set_measured_speed(wm, sh.turn_mean_speed, 0.0, 0.0);
      else set_measured_speed(wm, own.measured_speed, own.dspeed_dbgx, own.dspeed_dsgx);
    } else {
      wm = wheel_velocity_model(in);
    }
    m.H[i] = wm.H;
    add_level_block(subs, sh, wm.H_level, 1.0, m);
    m.dz = wm.innovation();
    if (mean && mean_offset_noise) {
      // The mean of the wheel speeds is the speed of the mean of the wheel centres (o for a
      // left/right pair), not of this wheel's centre, which eq. (5) predicts: in a turn it is
      // off by yaw rate x (offset of this wheel from that point), +-omega_z track / 2, up to
      // five times the forward sigma. The paper's distributed filter ignores it; the joint
      // filter must not, or its position constraint turns the opposite left/right speed
      // errors into a common heading error of every IMU (0.67 deg heading RMSE on error-free
      // data). Counted as forward noise at the Wheel-IMU's current yaw rate (its rate without
      // the spin about its axle c1 = C e_x), so H stays eq. (5)'s.
      const Mat3 C = w.ekf().state().C_ItoW();
      const Vec3 wv = C * w.ekf().omega_ib_b();
      const double yaw_rate = (wv - wv.dot(C.col(0)) * C.col(0)).z();  // without the spin
      const double e = yaw_rate * (sh.mean_point - w.module().p_inV).norm();
      m.R(0, 0) += e * e;
    }
    m.gate = w.velocity_gate();
  } else {
    // The mean speed of the wheels is the speed of the mean of their centres (o for a
    // symmetric pair; the wheel centre itself for one wheel).
    const BodyIns& b = subs.body();
    m.R = b.velocity_noise();
    double speed = sh.mean_speed;
    Vec3 point = sh.mean_point;
    mean = n_mean > 0;
    if (!mean) {
      speed = b.ins_speed();
      m.R(0, 0) = kNoSpeedVar;
      point.setZero();
    }
    const BodyVelocityModel bm = b.velocity_model(speed, point);
    m.H[i] = bm.H;
    m.dz = bm.innovation();
    m.gate = b.velocity_gate();
  }
  if (mean)
    for (int j = 0; j < subs.size(); ++j) {
      if (!sel.in_mean[j]) continue;
      const WheelVelocityInput& sp = turn ? sh.turn_speed[j] : sh.wheel[j];
      m.H[j](0, BG) -= sp.dspeed_dbgx / n_mean;
      m.H[j](0, SG) -= sp.dspeed_dsgx / n_mean;
    }
  // The own block: this IMU's share of a mean speed is its own gyro, so it is in both.
  m.H_own = m.H[i];
}

void position_measurement(const Subsystems& subs, const SharedInputs& sh, const FusionOptions& o,
                          int i, Measurement& m) {
  m.reset(i, subs.size());
  for (int j = 0; j < subs.size(); ++j) {
    const double c = (j == i ? 1.0 : 0.0) - sh.k[j];
    if (c == 0.0 && sh.k[j] == 0.0) continue;  // neither this module nor in the reference
    const ReferencePointModel& r = sh.ref[j];
    m.H[j] += c * r.H;
    if (subs.is_wheel(j)) add_level_block(subs, sh, r.H_level, c, m);
  }
  m.dz = sh.ref[i].r_o - sh.fused;
  const double sd = o.position_std;
  m.R = Mat3::Identity() * sd * sd;
  m.gate = o.position_gate;
  m.H_own = sh.ref[i].H;
}

namespace {
ZeroMotionInput zero_motion_input(const Subsystem& s, const Vec3& mean_raw_rate) {
  const StrapdownEkf& ekf = s.ekf();
  ZeroMotionInput in;
  in.C_BtoW = ekf.state().C_ItoW();
  in.v_IinW = ekf.state().v_IinW;
  const ImuErrors& e = ekf.errors();
  in.omega_ib_b = (mean_raw_rate - e.bg).cwiseQuotient(Vec3::Ones() + e.sg);  // as compensate()
  in.omega_ie_inW = ekf.mechanization().omega_ie_inW;
  return in;
}
}  // namespace

void zero_velocity_measurement(const Subsystems& subs, int i, double velocity_std, Measurement& m) {
  m.reset(i, subs.size());
  m.velocity = true;
  const ZeroMotionModel z = zero_velocity_model(zero_motion_input(subs[i], Vec3::Zero()));
  m.H[i] = z.H;
  m.H_own = z.H;
  m.dz = z.innovation();
  m.R = Mat3::Identity() * velocity_std * velocity_std;
  m.gate = 0.0;
}

void zero_rate_measurement(const Subsystems& subs, int i, const Vec3& mean_raw_rate, double window,
                           double rate_std, Measurement& m) {
  m.reset(i, subs.size());
  m.velocity = true;
  const ZeroMotionModel z = zero_rate_model(zero_motion_input(subs[i], mean_raw_rate));
  m.H[i] = z.H;
  m.H_own = z.H;
  m.dz = z.innovation();
  const double arw = subs[i].process_noise().gyro_arw;
  m.R = Mat3::Identity() * (arw * arw / std::max(window, 1e-3) + rate_std * rate_std);
  m.gate = 0.0;
}

}  // namespace wheelins
