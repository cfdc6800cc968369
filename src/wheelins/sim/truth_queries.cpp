// The truth queries of a Simulation (members declared in simulator.hpp): the true
// motion of a module's sensor at any time, the wheel's rotation rate, the extra angle
// of a slip fault, and error-free mean samples over the sample grid.
#include "wheelins/sim/simulator.hpp"

#include <algorithm>

#include "wheelins/sim/faults.hpp"
#include "wheelins/sim/quadrature.hpp"

namespace wheelins::sim {

double Simulation::wheel_rate(int g, double t) const {
  if (!modules_[g].truth.wheel) return 0.0;
  return stepper(g, 0.0).rate_at(t).value();
}

double Simulation::slip_extra_angle(int g, const ModuleModel::SlipEvent& e) const {
  // alpha_dot - (fault-free alpha_dot) = ratio * w(t) * v_wc(t) / R (see wheel_rate_jet);
  // 4-point Gauss-Legendre over steps of one sample interval from t0 (w is C-infinity).
  const ModuleModel& m = modules_[g];
  const GroupStepper st = stepper(g, 0.0);
  const double h = 1.0 / cfg_.rate_hz, b_end = std::min(e.t1, end_);
  double sum = 0.0;
  for (double a = e.t0; a < b_end; a += h) {
    const double b = std::min(a + h, b_end);
    for (int i = 0; i < 4; ++i) {
      const double t = 0.5 * (a + b) + 0.5 * (b - a) * kGlX[i];
      JV p_o;
      JM C_v;
      scenario_->evaluate(t, p_o, C_v);
      sum += 0.5 * (b - a) * kGlW[i] * e.ratio * slip_window<kOrder>(t, e.t0, e.t1).value() *
             wheel_centre_speed_of(m, p_o, C_v, st.steering_at(t)) / m.radius;
    }
  }
  return sum;
}

ImuTruth Simulation::truth(int g, double t) const {
  const GroupStepper st = stepper(g, 0.0);
  const ModuleModel& m = modules_[g];
  double alpha = 0.0;
  if (m.truth.wheel) {
    const double t0 = start_time();
    const double h = 1.0 / cfg_.rate_hz;
    double a = t0;
    while (a < t) {
      const double b = std::min(t, a + h);
      for (int i = 0; i < 4; ++i)
        alpha += 0.5 * (b - a) * kGlW[i] * st.rate_at(0.5 * (a + b) + 0.5 * (b - a) * kGlX[i]).value();
      a = b;
    }
  }
  JV p_o, p;
  JM C_v, C_s;
  scenario_->evaluate(t, p_o, C_v);
  ImuTruth r;
  J alpha_jet(0.0);
  const J delta = st.steering_at(t);
  if (m.truth.wheel) {
    const J rate = wheel_rate_jet(m, t, p_o, C_v, delta);
    alpha_jet = GroupStepper::integrate(alpha, rate);
    r.wheel_angle = alpha;
    r.wheel_rate = rate.value();
    r.wheel_centre_speed = wheel_centre_speed_of(m, p_o, C_v, delta);
    r.steering_angle = delta.value();
    r.steering_rate = delta.deriv(1);
  }
  st.imu_jets(t, p_o, C_v, alpha_jet, delta, p, C_s);
  r.p_inN = p.deriv(0);
  r.v_inN = p.deriv(1);
  r.a_inN = p.deriv(2);
  r.C_StoN = C_s.value();
  r.omega_nb_inS = body_rate(C_s);
  r.gyro_inS = r.omega_nb_inS + r.C_StoN.transpose() * omega_ie_;
  r.accel_inS = r.C_StoN.transpose() * (r.a_inN - Vec3(0, 0, gravity_) + 2.0 * omega_ie_.cross(r.v_inN));
  return r;
}

std::vector<ImuSample> Simulation::ideal_samples(int g, std::size_t count) const {
  GroupStepper st = stepper(g, 0.0);
  std::vector<ImuSample> out;
  out.reserve(count);
  const double t0 = start_time();
  for (std::size_t k = 1; k <= count; ++k) {
    const double b = t0 + static_cast<double>(k) / cfg_.rate_hz;
    Vec3 gy, ac;
    st.step(b, gy, ac);
    ImuSample s;
    s.t = b;
    s.dt = 1.0 / cfg_.rate_hz;
    s.dtheta = gy * s.dt;
    s.dvel = ac * s.dt;
    out.push_back(s);
  }
  return out;
}

}  // namespace wheelins::sim
