// The Wheel-INS subsystem (wheel_ins.hpp): alignment and restart of a spinning Wheel-IMU,
// the wheel speed from its gyro-x window (eq. 3), its velocity input (eq. 5) and its o.
#include "wheelins/filter/wheel_ins.hpp"

#include <algorithm>
#include <cmath>

namespace wheelins {

WheelIns::WheelIns(const ImuModule& module, const WheelInsOptions& opt,
                   const MechanizationOptions& mech)
    : Subsystem(module, mech),
      opt_(opt),
      C_StoB_(wheel_sensor_to_body(module)),
      G_StoB_(Vec3(1.0, 1.0 / (1.0 + module.yaw_scale), 1.0 / (1.0 + module.yaw_scale)).asDiagonal() * C_StoB_),
      axle_sign_(module.axle_sign) {
  // A steered wheel's speed and geometry change with the steering over a turn: no whole-turn
  // averages for it.
  if (module.steered) {
    opt_.turn_average = false;
    steer_ = SteeringObserver(module.p_inV.x(), module.wheel_radius, opt.steering);
  }
  // Its b x-axis is the axle: the attitude update splits the spin off (nav/mechanization.hpp).
  mech_.spin_about_x = true;
  window_len_ = std::clamp(static_cast<int>(std::lround(opt.speed_window * module.rate_hz)), 1,
                           kMaxWindow);
  // The gyro axes in the wheel plane see the vehicle's yaw rate in turn as the wheel rolls:
  // their scale factors together are a yaw-rate scale factor, which nothing but a heading
  // reference could show; estimated from the velocity updates they run away with the
  // innovations' unmodelled errors. Held, or estimated from the position constraint alone
  // (docs/filter.md 13.4). The axle's (x) is estimated: the wheel angle it integrates is
  // checked against gravity at every update.
  set_yaw_scale_factor_mode(opt.yaw_scale_factors, {SG + 1, SG + 2});
  // The accelerometer along the axle sees the lateral specific force only: its scale factor
  // and its bias differ only where the course turns both ways (held as well).
  if (!opt.estimate_axle_accel_scale_factor) noise_.estimated(SA + 0) = 0.0;
  if (opt_.turn_average)
    turns_.reserve(std::clamp(static_cast<int>(std::ceil(opt.turn_window * module.rate_hz)) + 1, 2,
                              kMaxTurnEpochs));
}

ImuSample WheelIns::to_body(const ImuSample& s) const {
  ImuSample b = s;
  b.dtheta = G_StoB_ * s.dtheta;
  b.dvel = C_StoB_ * s.dvel;
  return b;
}

void WheelIns::start(const StaticAccumulator& stat, double vehicle_heading, double t0) {
  // Roll (the wheel angle) and pitch from the mean specific force; the b x-axis points
  // along the axle, so the IMU yaw is the vehicle heading + axle_sign * 90 deg.
  Vec3 rpy = level_from_specific_force(stat.mean_f());
  steer_.arm(0.0);  // a steered wheel's delta_0 is measured as it starts to roll
  rpy.z() = wrap_pi(vehicle_heading + steering() + axle_sign_ * 0.5 * kPi);
  NavState s;
  s.t = t0;
  s.q_ItoW = Quat(dcm_from_euler(rpy)).normalized();
  const Mat3 C = s.C_ItoW();
  const Mat3 C_VtoW0 = rot_z(vehicle_heading);
  s.p_IinW = C_VtoW0 * module_.p_inV - C * module_.lever_arm_inB;
  ImuErrors e;
  e.bg = stat.mean_omega() - C.transpose() * mech_.omega_ie_inW;
  begin(s, e, opt_.init);
}

void WheelIns::begin(const NavState& s, const ImuErrors& e, const InitialUncertainty& init) {
  ekf_.initialize(s, e, noise_, init, mech_);
  window_count_ = window_pos_ = 0;
  window_sum_ = 0.0;
}

void WheelIns::restart(const Vec3& mean_f_inB, const VehicleFix& fix) {
  // As start(), in motion: the wheel angle and axle tilt from the averaged specific force,
  // the axle direction from the vehicle heading, the IMU placed from o by eq. (7).
  Vec3 rpy = level_from_specific_force(mean_f_inB);
  steer_.arm(steer_.angle());  // measured again over the first metres
  rpy.z() = wrap_pi(fix.heading + steering() + axle_sign_ * 0.5 * kPi);
  NavState s;
  s.t = fix.t;
  s.q_ItoW = Quat(dcm_from_euler(rpy)).normalized();
  const Mat3 C = s.C_ItoW();
  s.p_IinW = fix.p_OinW + rot_z(fix.heading) * module_.p_inV - C * module_.lever_arm_inB;
  s.v_IinW = fix.v_OinW;
  begin(s, ekf_.errors(), fix.uncertainty());
}

double WheelIns::yaw_rate() const {
  const Mat3 C = ekf_.state().C_ItoW();
  const Vec3 omega_inW = C * (ekf_.omega_ib_b() - C.transpose() * mech_.omega_ie_inW);
  const Vec3 axle = C.col(0);
  return (omega_inW - omega_inW.dot(axle) * axle).z();
}

double WheelIns::ins_speed() const {
  const NavState& s = ekf_.state();
  const Mat3 C = s.C_ItoW();
  const Vec3 omega_nb = ekf_.omega_ib_b() - C.transpose() * mech_.omega_ie_inW;
  const Vec3 v_wc = s.v_IinW + C * omega_nb.cross(module_.lever_arm_inB);
  return ((C_VtoW() * rot_z(steering())).transpose() * v_wc).x();  // along the wheel
}

void WheelIns::propagate(const ImuSample& body_sample) {
  ekf_.propagate_nominal(body_sample);
  // The window keeps the uncompensated rate; mean_omega_x() compensates it with the current
  // estimates, so the speed stays consistent with the error state after every feedback
  // (a centralized filter corrects this IMU's b_g,x / s_g,x between two updates of one epoch).
  const double wx = body_sample.dtheta.x() / body_sample.dt;
  if (window_count_ == window_len_) window_sum_ -= window_[window_pos_];
  else ++window_count_;
  window_[window_pos_] = wx;
  window_sum_ += wx;
  window_pos_ = (window_pos_ + 1) % window_len_;
  if (module_.steered) {
    // This sample's speed (the window's mean lags by half the window: 4 % of the distance
    // rolled while a car starts to roll, which the start's steering would take for a turn).
    const double speed = -axle_sign_ * module_.wheel_radius * compensated_omega_x(wx);
    const SteeringObserver::Step st =
        steer_.step(yaw_rate(), speed, body_sample.dt,
                    wheel_vehicle_heading(ekf_.state().C_ItoW(), axle_sign_), reference_heading_);
    if (st.rolling_began) roll_pivot_ = ekf_.state().p_IinW;
    if (st.turn != 0.0) ekf_.rotate_about_vertical(st.turn, roll_pivot_);
  }
  if (opt_.turn_average) {
    // Models kept from before a restart or replaced estimates are not comparable.
    if (ekf_.revision() != turns_revision_) {
      turns_.clear();
      turns_revision_ = ekf_.revision();
    }
    WheelVelocityInput in = own_velocity_input();
    in.measured_speed = in.dspeed_dbgx = in.dspeed_dsgx = 0.0;
    turns_.add(wheel_velocity_model(in), ekf_.feedback_total(),
               Eigen::Vector2d(vehicle_roll_, vehicle_pitch_), wx, body_sample.dt);
  }
}

bool WheelIns::turn_averaged(const WheelVelocityInput& now, TurnAverage& out,
                             WheelVelocityInput& speed) const {
  if (!opt_.turn_average || ekf_.revision() != turns_revision_) return false;
  if (!turns_.average(ekf_.feedback_total(), Eigen::Vector2d(now.vehicle_roll, now.vehicle_pitch),
                      out))
    return false;
  const ImuErrors& e = ekf_.errors();
  speed.axle_sign = axle_sign_;
  set_own_wheel_speed(speed, module_.wheel_radius, (out.mean_omega_x - e.bg.x()) / (1.0 + e.sg.x()));
  return true;
}

double WheelIns::compensated_omega_x(double raw) const {
  const ImuErrors& e = ekf_.errors();
  return (raw - e.bg.x()) / (1.0 + e.sg.x());
}

double WheelIns::mean_omega_x() const {
  return window_count_ ? compensated_omega_x(window_sum_ / window_count_) : 0.0;
}

WheelIns::SpeedSensitivity WheelIns::speed_sensitivity() const {
  WheelVelocityInput in;
  in.axle_sign = axle_sign_;
  set_own_wheel_speed(in, module_.wheel_radius, mean_omega_x());
  return {in.dspeed_dbgx, in.dspeed_dsgx};
}

double WheelIns::wheel_speed() const { return -axle_sign_ * module_.wheel_radius * mean_omega_x(); }

WheelVelocityInput WheelIns::own_velocity_input() const {
  WheelVelocityInput in;
  in.C_BtoW = ekf_.state().C_ItoW();
  in.v_IinW = ekf_.state().v_IinW;
  in.omega_ib_b = ekf_.omega_ib_b();
  in.omega_ie_inW = mech_.omega_ie_inW;
  in.lever_arm_inB = module_.lever_arm_inB;
  in.vehicle_roll = vehicle_roll_;
  in.vehicle_pitch = vehicle_pitch_;
  in.steering = steering();
  in.axle_sign = axle_sign_;
  set_own_wheel_speed(in, module_.wheel_radius, mean_omega_x());
  return in;
}

Mat3 WheelIns::C_VtoW() const {
  return rot_z(vehicle_heading()) * rot_y(vehicle_pitch_) * rot_x(vehicle_roll_);
}

Vec3 WheelIns::wheel_centre_inW() const {
  const NavState& s = ekf_.state();
  return s.p_IinW + s.C_ItoW() * module_.lever_arm_inB;
}

ReferencePointInput WheelIns::reference_point_input() const {
  ReferencePointInput in;
  in.wheel = true;
  in.C_BtoW = ekf_.state().C_ItoW();
  in.p_IinW = ekf_.state().p_IinW;
  in.lever_arm_inB = module_.lever_arm_inB;
  in.p_inV = module_.p_inV;
  in.axle_sign = axle_sign_;
  in.steering = steering();
  in.vehicle_roll = vehicle_roll_;
  in.vehicle_pitch = vehicle_pitch_;
  return in;
}

Eigen::RowVector3d WheelIns::heading_sensitivity() const {
  return wheel_heading_sensitivity(ekf_.state().C_ItoW());
}

Vec3 WheelIns::reference_velocity_inW() const {
  const NavState& s = ekf_.state();
  const Mat3 C = s.C_ItoW();
  const Vec3 omega_nb = ekf_.omega_ib_b() - C.transpose() * mech_.omega_ie_inW;
  const Vec3 v_wc = s.v_IinW + C * omega_nb.cross(module_.lever_arm_inB);
  // The vehicle turns with the wheel's angular rate less its spin about the axle (and less
  // the steering rate about the vehicle's vertical).
  const Vec3 omega_inW = C * omega_nb;
  const Vec3 axle = C.col(0);
  const Mat3 C_v = C_VtoW();
  const Vec3 omega_vehicle = omega_inW - omega_inW.dot(axle) * axle - steering_rate() * C_v.col(2);
  return v_wc - omega_vehicle.cross(C_v * module_.p_inV);
}

}  // namespace wheelins
