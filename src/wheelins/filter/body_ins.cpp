// The Body-INS subsystem (body_ins.hpp): alignment and restart, its reference point o
// (eq. 7 through C_b^v), the velocity of o, and the eq. (6) model at a rear-axle point.
#include "wheelins/filter/body_ins.hpp"

#include "wheelins/filter/wheel_velocity.hpp"

namespace wheelins {

BodyIns::BodyIns(const ImuModule& module, const BodyInsOptions& opt,
                 const MechanizationOptions& mech)
    : Subsystem(module, mech), opt_(opt), C_BtoV_(dcm_from_euler(module.mounting_rpy)) {
  // The scale factor of the gyro axis nearest the vehicle's yaw axis is a yaw-rate scale
  // factor: unobservable without a heading reference, so held or estimated from the
  // position constraint alone (docs/filter.md 13.4).
  int axis = 0;
  C_BtoV_.row(2).cwiseAbs().maxCoeff(&axis);
  set_yaw_scale_factor_mode(opt.yaw_scale_factors, {SG + axis});
}

void BodyIns::start(const StaticAccumulator& stat, double vehicle_heading, double t0) {
  NavState s;
  s.t = t0;
  const Mat3 C = align_attitude(stat.mean_f(), vehicle_heading, C_BtoV_);
  s.q_ItoW = Quat(C).normalized();
  s.p_IinW = C * C_BtoV_.transpose() * module_.p_inV;  // o at the origin
  ImuErrors e;
  e.bg = stat.mean_omega() - C.transpose() * mech_.omega_ie_inW;
  ekf_.initialize(s, e, noise_, opt_.init, mech_);
}

void BodyIns::restart(const Vec3& mean_f_inB, const VehicleFix& fix) {
  NavState s;
  s.t = fix.t;
  const Mat3 C = align_attitude(mean_f_inB, fix.heading, C_BtoV_);
  s.q_ItoW = Quat(C).normalized();
  s.p_IinW = fix.p_OinW + C * C_BtoV_.transpose() * module_.p_inV;
  s.v_IinW = fix.v_OinW;
  ekf_.initialize(s, ekf_.errors(), noise_, fix.uncertainty(), mech_);
}

Eigen::RowVector3d BodyIns::heading_sensitivity() const {
  // The vehicle x-axis C_v^w e1 moves like any vector attached to the b-frame.
  return wheel_heading_sensitivity(C_VtoW());
}

ReferencePointInput BodyIns::reference_point_input() const {
  ReferencePointInput in;
  in.wheel = false;
  in.C_BtoW = ekf_.state().C_ItoW();
  in.p_IinW = ekf_.state().p_IinW;
  in.p_inV = module_.p_inV;
  in.C_BtoV = C_BtoV_;
  return in;
}

Vec3 BodyIns::reference_velocity_inW() const {
  const NavState& s = ekf_.state();
  const Mat3 C = s.C_ItoW();
  const Vec3 omega_nb = ekf_.omega_ib_b() - C.transpose() * mech_.omega_ie_inW;
  const Vec3 l_o = C_BtoV_.transpose() * (-module_.p_inV);
  return s.v_IinW + C * omega_nb.cross(l_o);
}

BodyVelocityModel BodyIns::velocity_model(double speed, const Vec3& point_inV) const {
  BodyVelocityInput in;
  in.C_BtoW = ekf_.state().C_ItoW();
  in.v_IinW = ekf_.state().v_IinW;
  in.omega_ib_b = ekf_.omega_ib_b();
  in.omega_ie_inW = mech_.omega_ie_inW;
  in.C_BtoV = C_BtoV_;
  in.lever_arm_inB = C_BtoV_.transpose() * (point_inV - module_.p_inV);
  in.measured_speed = speed;
  return body_velocity_model(in);
}

}  // namespace wheelins
