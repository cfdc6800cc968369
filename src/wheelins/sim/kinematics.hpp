// The kinematics of one simulated module (docs/simulator.md): the wheel's rolling
// rate with the slip effect and slip faults, the speed-dependent vibration gain, and
// the group stepper that turns the scenario's motion into one module's exact mean
// gyro and accelerometer readings over each sample interval (4-point Gauss-Legendre,
// sim/quadrature.hpp), on the module's own (possibly offset) clock.
#pragma once

#include <vector>

#include "wheelins/sim/config.hpp"
#include "wheelins/sim/scenario.hpp"
#include "wheelins/sim/vibration.hpp"

namespace wheelins::sim {

/// One physical module as simulated (the truth) and as the manifest states it.
struct ModuleModel {
  /// A wheel-slip fault event (sim/faults.hpp) in true (scenario) time: the rolling rate is
  /// multiplied by 1 + ratio * w(t), w = slip_window over [t0, t1] (t1 = +inf: open-ended).
  struct SlipEvent {
    double t0 = 0.0, t1 = 0.0, ratio = 0.0;
  };
  ModuleGeometry truth;        ///< geometry used to simulate
  ModuleGeometry manifest;     ///< geometry written to manifest.yaml (calibration residuals)
  double radius = 0.0;         ///< true effective rolling radius (wheel) [m]
  double radius_manifest = 0.0;
  double slip_coeff = 0.0;     ///< [s^2/m], 0 without the slip effect
  std::vector<SlipEvent> slip_events;  ///< slip faults of this wheel
  double time_offset = 0.0;    ///< true clock offset: a sample stamped t covers (t-dt+off, t+off]
  double temp_rise = 0.0;      ///< [K]
  Vibration vibration;
  /// The vibration scales with the speed v of o: gain = s(v) / s(v_cruise), s(v) = x / (1 + x),
  /// x = (v / (0.3 v_cruise))^2: zero at rest, 1 at the cruise speed (a smooth function of the
  /// motion, so the vibrating displacement still has exact derivatives).
  double vib_cruise_speed = 1.4;
};

/// The true motion of one IMU (sensor axes) at an instant.
struct ImuTruth {
  Vec3 p_inN, v_inN, a_inN;
  Mat3 C_StoN;
  Vec3 omega_nb_inS;   ///< angular rate w.r.t. the n-frame
  Vec3 gyro_inS;       ///< + earth rate: what an ideal gyro reads
  Vec3 accel_inS;      ///< specific force (what an ideal accelerometer reads)
  double wheel_angle = 0.0, wheel_rate = 0.0;  ///< alpha, d alpha/dt (wheel modules)
  /// Speed of the wheel centre along the wheel's heading (rigid motion) [m/s].
  double wheel_centre_speed = 0.0;
  /// Steered wheels: the steering angle delta (the wheel's heading minus the vehicle's,
  /// positive turned right) and its rate [rad, rad/s]; 0 for the others.
  double steering_angle = 0.0, steering_rate = 0.0;
};

/// What a stepper needs besides the motion: the sample grid and the environment.
struct StepperClock {
  double rate_hz = 200.0;
  double start_time = 0.0;  ///< the scenario start: wheel angle 0 [s]
  double gravity = 9.8;     ///< [m/s^2]
  Vec3 omega_ie = Vec3::Zero();  ///< earth rate in the n-frame (zero if not simulated)
};

/// The steering angle of a steered wheel as a jet: the exact Ackermann angle of its centre
/// (x_h, y_h) in the v-frame for the curvature kappa of the path of o (positive turning right),
///   delta = atan2(kappa x_h, 1 - kappa y_h),
/// positive = turned right (the wheel's heading minus the vehicle's). Zero for the others.
J steering_jet(const ModuleModel& m, const J& kappa);
/// The unit vector of a wheel's heading in the n-frame: C_v Rz(delta) e_x (C_v e_x when not
/// steered).
JV wheel_heading(const ModuleModel& m, const JM& C_v, const J& delta);
/// The forward rolling rate of a wheel, d alpha / dt, as a jet in t (with the slip effect
/// and the module's slip faults), given the v-frame jets of o at t and the steering angle
/// (steered wheels: the hub's velocity along the wheel's heading rolls it).
J wheel_rate_jet(const ModuleModel& m, double t, const JV& p_o, const JM& C_v, const J& delta = J(0.0));
/// Speed of a wheel centre along the wheel's heading (rigid motion, no slip) from the
/// v-frame jets and the steering angle [m/s].
double wheel_centre_speed_of(const ModuleModel& m, const JV& p_o, const JM& C_v, const J& delta = J(0.0));
/// The vibration gain at the speed of o [m/s] (see ModuleModel::vib_cruise_speed).
double vibration_gain(const ModuleModel& m, double speed);

/// Steps one module through the sample grid on its own (possibly offset) clock.
class GroupStepper {
 public:
  /// `offset`: the module's clock offset (a sample stamped t covers (t-dt+off, t+off]).
  GroupStepper(const Scenario& scenario, const ModuleModel& m, const StepperClock& clock,
               double offset);

  /// Mean gyro / accel (sensor axes) over the stamped interval (t1 - 1/rate, t1]. (The
  /// nominal interval length is used: stamps t0 + k/rate differ from it by rounding only.)
  void step(double t1, Vec3& gyro, Vec3& accel);

  /// The wheel's rolling rate at true time t.
  J rate_at(double t) const;
  /// The steering angle at true time t (steering_jet of the scenario's path curvature; zero
  /// unless the module is a steered wheel).
  J steering_at(double t) const;
  /// The angle jet from its value and the rate jet.
  static J integrate(double value, const J& rate);
  /// Position and attitude (sensor axes) jets of the IMU; `delta`: the steering angle
  /// (steering_at(t); used by steered wheels only).
  void imu_jets(double t, const JV& p_o, const JM& C_v, const J& alpha, const J& delta, JV& p,
                JM& C_s, const JV* vib_disp = nullptr, const JV* vib_rot = nullptr) const;

 private:
  struct NodeResult {
    Vec3 gyro, accel;
  };
  NodeResult node(double t, const JV& p_o, const JM& C_v, const J& alpha, const J& delta,
                  const JV* disp, const JV* rot) const;

  const Scenario& scenario_;
  StepperClock clock_;
  const ModuleModel& m_;
  double offset_;
  bool wheel_, steered_;
  Vibration vib_;  // a copy with the node phasors of this stepper
  double h_;
  double node_offset_[4];
  Mat3 C0_, C_sb_;
  double alpha_ = 0.0;
};

}  // namespace wheelins::sim
