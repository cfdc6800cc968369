// The kinematics of kinematics.hpp: rolling rate and slip, vibration gain, and the group
// stepper's quadrature of the exact rates over each sample.
#include "wheelins/sim/kinematics.hpp"

#include <cmath>

#include "wheelins/sim/faults.hpp"
#include "wheelins/sim/quadrature.hpp"

namespace wheelins::sim {

namespace {

/// The ideal wheel b-frame in the v-frame at wheel angle 0: b_x -> v_y, b_y -> -v_x, b_z -> v_z.
Mat3 wheel_c0() {
  Mat3 C;
  C << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  return C;
}

/// Vibration gain from the speed of o (see ModuleModel::vib_cruise_speed).
J vibration_gain(const ModuleModel& m, const JV& p_o) {
  const JV v = p_o.dot();
  const double v0 = 0.3 * m.vib_cruise_speed;
  const J x = dot(v, v) / (v0 * v0);
  const double xc = 1.0 / 0.09;  // x at the cruise speed
  return x / (1.0 + x) * ((1.0 + xc) / xc);
}

void scale(JV& a, const J& g) {
  for (int i = 0; i < 3; ++i) a[i] = a[i] * g;
}

}  // namespace

/// Forward rolling rate of a wheel, d alpha / dt at time t, as a jet in t:
///   alpha_dot = v_wc (1 + slip_coeff a_wc + sum_i s_i w_i(t)) / R,
/// v_wc the forward speed of the wheel centre, a_wc its derivative (valid to order kOrder - 2
/// with the slip effect: the top coefficient of a_wc is lost), s_i and w_i the ratio and the
/// C-infinity window of each slip fault (exact jets in t, sim/faults.hpp).
J wheel_rate_jet(const ModuleModel& m, double t, const JV& p_o, const JM& C_v, const J& delta) {
  const JV pwc = p_o + C_v * m.truth.p_inV;
  const J vf = dot(wheel_heading(m, C_v, delta), pwc.dot());
  // The windows vanish with all derivatives outside (t0, t1): there the fault-free
  // expressions below are used, so the data outside the events are bit for bit unchanged.
  J fault(0.0);
  bool any = false;
  for (const auto& e : m.slip_events)
    if (t > e.t0 && t < e.t1) {
      fault += e.ratio * slip_window<kOrder>(t, e.t0, e.t1);
      any = true;
    }
  if (any) {
    const J slip = m.slip_coeff == 0.0 ? J(0.0) : m.slip_coeff * vf.dot();
    return vf * (1.0 + slip + fault) / m.radius;
  }
  if (m.slip_coeff == 0.0) return vf / m.radius;
  const J af = vf.dot();
  return vf * (1.0 + m.slip_coeff * af) / m.radius;
}

/// Speed of a wheel centre along its heading (rigid motion, no slip), from the v-frame jets.
double wheel_centre_speed_of(const ModuleModel& m, const JV& p_o, const JM& C_v, const J& delta) {
  const JV pwc = p_o + C_v * m.truth.p_inV;
  return dot(wheel_heading(m, C_v, delta), pwc.dot()).value();
}

J steering_jet(const ModuleModel& m, const J& kappa) {
  if (!m.truth.steered) return J(0.0);
  // Ackermann: the wheel's axle points at the centre of the turn, (0, 1/kappa) from o in the
  // v-frame; its heading is perpendicular to the line from that centre to the hub.
  const Vec3& h = m.truth.p_inV;
  return atan2(kappa * h.x(), 1.0 - kappa * h.y());
}

JV wheel_heading(const ModuleModel& m, const JM& C_v, const J& delta) {
  if (!m.truth.steered) return C_v.col(0);
  J s, c;
  sincos(delta, s, c);
  const JV x = C_v.col(0), y = C_v.col(1);  // Rz(delta) e_x = (cos, sin, 0) in the v-frame
  return x * c + y * s;
}

/// The same gain as a plain number, from the speed of o [m/s].
double vibration_gain(const ModuleModel& m, double speed) {
  const double v0 = 0.3 * m.vib_cruise_speed;
  const double x = speed * speed / (v0 * v0);
  const double xc = 1.0 / 0.09;
  return x / (1.0 + x) * ((1.0 + xc) / xc);
}

GroupStepper::GroupStepper(const Scenario& scenario, const ModuleModel& m,
                           const StepperClock& clock, double offset)
    : scenario_(scenario), clock_(clock), m_(m), offset_(offset), wheel_(m_.truth.wheel),
      steered_(m_.truth.wheel && m_.truth.steered), vib_(m_.vibration), h_(1.0 / clock.rate_hz) {
  C0_ = wheel_c0();
  C_sb_ = dcm_from_euler(m_.truth.mounting_rpy);
  for (int i = 0; i < 4; ++i) node_offset_[i] = 0.5 * h_ * kGlX[i];
  if (!vib_.empty()) vib_.prepare(node_offset_, h_);
  if (wheel_ && offset != 0.0) {
    // alpha is zero at the scenario start; integrate to the offset start.
    const double a = clock.start_time, b = a + offset;
    for (int i = 0; i < 4; ++i) {
      const double t = 0.5 * (a + b) + 0.5 * (b - a) * kGlX[i];
      alpha_ += 0.5 * (b - a) * kGlW[i] * rate_at(t).value();
    }
  }
}

void GroupStepper::step(double t1, Vec3& gyro, Vec3& accel) {
  const double h = h_;
  const double mid = t1 + offset_ - 0.5 * h;
  JV p_o[4];
  JM C_v[4];
  J rate[4], delta[4];
  double t[4];
  JV disp[4], rot[4];
  if (!vib_.empty()) vib_.eval4(mid, disp, rot);
  for (int i = 0; i < 4; ++i) {
    t[i] = mid + node_offset_[i];
    scenario_.evaluate(t[i], p_o[i], C_v[i]);
    if (steered_) delta[i] = steering_at(t[i]);
    if (wheel_) rate[i] = wheel_rate_jet(m_, t[i], p_o[i], C_v[i], delta[i]);
    if (!vib_.empty()) {
      const J gain = vibration_gain(m_, p_o[i]);
      scale(disp[i], gain);
      scale(rot[i], gain);
    }
  }
  gyro.setZero();
  accel.setZero();
  for (int i = 0; i < 4; ++i) {
    J alpha(0.0);
    if (wheel_) {
      double ai = alpha_;
      for (int j = 0; j < 4; ++j) ai += 0.5 * h * kLagrange.A[i][j] * rate[j].value();
      alpha = integrate(ai, rate[i]);
    }
    const NodeResult r = node(t[i], p_o[i], C_v[i], alpha, delta[i], vib_.empty() ? nullptr : &disp[i],
                              vib_.empty() ? nullptr : &rot[i]);
    gyro += 0.5 * kGlW[i] * r.gyro;
    accel += 0.5 * kGlW[i] * r.accel;
  }
  if (wheel_)
    for (int j = 0; j < 4; ++j) alpha_ += 0.5 * h * kGlW[j] * rate[j].value();
}

J GroupStepper::rate_at(double t) const {
  JV p;
  JM C;
  scenario_.evaluate(t, p, C);
  return wheel_rate_jet(m_, t, p, C, steering_at(t));
}

J GroupStepper::steering_at(double t) const {
  if (!steered_) return J(0.0);
  return steering_jet(m_, scenario_.path_curvature(t));
}

J GroupStepper::integrate(double value, const J& rate) {
  J a(value);
  for (int k = 1; k <= kOrder; ++k) a.c[k] = rate.c[k - 1] / k;
  return a;
}

void GroupStepper::imu_jets(double t, const JV& p_o, const JM& C_v, const J& alpha, const J& delta,
                            JV& p, JM& C_s, const JV* vib_disp, const JV* vib_rot) const {
  JV disp(Vec3::Zero()), rot(Vec3::Zero());
  if (vib_disp) {
    disp = *vib_disp;
    rot = *vib_rot;
  } else if (!m_.vibration.empty()) {
    m_.vibration.eval(t, disp, rot);
    const J gain = vibration_gain(m_, p_o);
    scale(disp, gain);
    scale(rot, gain);
  }
  const JV offset_v = JV(m_.truth.p_inV) + disp;
  if (wheel_) {
    const bool vib = vib_disp || !m_.vibration.empty();
    // A steered wheel turns by delta about the v-frame's z through its centre: C_v Rz(delta) C0
    // Rx(-alpha) (the vibration's small rotation, in v-frame axes, comes before the steering).
    const JM C_wheel = steered_ ? jrot_z(delta) * (C0_ * jrot_x(-alpha)) : C0_ * jrot_x(-alpha);
    const JM C_b = vib ? C_v * (jdcm_from_euler(rot[0], rot[1], rot[2]) * C_wheel)
                       : C_v * C_wheel;  // ideal wheel b-frame
    C_s = C_b * C_sb_;
    p = p_o + C_v * offset_v - C_b * m_.truth.lever_arm_inB;
  } else {
    if (vib_disp || !m_.vibration.empty()) {
      C_s = C_v * (jdcm_from_euler(rot[0], rot[1], rot[2]) * C_sb_);
    } else {
      C_s = C_v * C_sb_;
    }
    p = p_o + C_v * offset_v;
  }
}

GroupStepper::NodeResult GroupStepper::node(double t, const JV& p_o, const JM& C_v, const J& alpha,
                                            const J& delta, const JV* disp, const JV* rot) const {
  JV p;
  JM C_s;
  imu_jets(t, p_o, C_v, alpha, delta, p, C_s, disp, rot);
  const Mat3 C = C_s.value();
  const Vec3 v = p.deriv(1), acc = p.deriv(2);
  const Vec3 w = clock_.omega_ie;
  NodeResult r;
  r.gyro = body_rate(C_s) + C.transpose() * w;
  r.accel = C.transpose() * (acc - Vec3(0, 0, clock_.gravity) + 2.0 * w.cross(v));
  return r;
}

}  // namespace wheelins::sim
