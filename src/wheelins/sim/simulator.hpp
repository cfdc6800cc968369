// The multi-IMU simulator: exact IMU data for two Wheel-IMUs and a Body-IMU
// (four chips each) from a Scenario, with a seeded, switchable error model, and
// the dataset writer behind `wheelins simulate`.
//
// Physics (docs/simulator.md): every IMU point's position and attitude are
// analytic functions of time (sim/jet.hpp); each sample is the mean angular
// rate and mean specific force over (t - dt, t], by 4-point Gauss-Legendre:
//   gyro  = omega_nb^s + C_n^s omega_ie^n,
//   accel = C_n^s (a^n - g^n + 2 omega_ie^n x v^n),
// consistent with nav/mechanization.cpp (v' = C f - 2 omega_ie x v + g).
#pragma once

#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "wheelins/io/manifest.hpp"
#include "wheelins/nav/types.hpp"
#include "wheelins/sim/config.hpp"
#include "wheelins/sim/rng.hpp"
#include "wheelins/sim/scenario.hpp"

namespace wheelins::sim {

/// Band-limited vibration of a module: displacement (v-frame) and small rotation
/// (ZYX Euler angles, v-frame), each a sum of sinusoids with random frequencies in a
/// band, so its derivatives (the accelerations and rates it causes) are exact.
struct Vibration {
  struct Component {
    double amplitude = 0.0, omega = 0.0, phase = 0.0;
  };
  std::array<std::vector<Component>, 6> dof;  ///< x, y, z [m], roll, pitch, yaw [rad]
  std::array<std::vector<std::array<double, 8>>, 6> node_phasors;  ///< cos, sin of omega*offset_i
  std::array<std::vector<std::array<double, 4>>, 6> phase_state;   ///< sin, cos now; cos, sin of omega h
  double step_h = 0.0, last_mid = 0.0;
  int since_exact = -1;
  bool empty() const { return dof[0].empty(); }
  void eval(double t, JV& disp, JV& rot) const;
  /// The same at t_mid + offsets[i], i = 0..3, for offsets fixed by prepare() (one sine and
  /// cosine per component instead of four: the angle-sum identities do the rest).
  /// Consecutive calls h apart advance each component's phase by a rotation (recomputed
  /// exactly every 256 calls; the recurrence adds < 1e-13 relative error).
  void prepare(const double offsets[4], double h);
  void eval4(double t_mid, JV disp[4], JV rot[4]);
  static Vibration draw(Rng& rng, const Vec3& accel_rms, const Vec3& rate_rms, const double band[2],
                        int components = 24);
};

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

/// Error parameters drawn for one chip (SI units).
struct ChipModel {
  std::string name;  ///< e.g. "left-C1"
  Vec3 gyro_bias = Vec3::Zero(), accel_bias = Vec3::Zero();  ///< turn-on
  Vec3 gyro_gm0 = Vec3::Zero(), accel_gm0 = Vec3::Zero();    ///< initial Gauss-Markov state
  Mat3 gyro_T = Mat3::Identity(), accel_T = Mat3::Identity();  ///< I + scale factor + misalignment
  Vec3 gyro_tempco = Vec3::Zero(), accel_tempco = Vec3::Zero();  ///< per K
};

/// The true motion of one IMU (sensor axes) at an instant.
struct ImuTruth {
  Vec3 p_inN, v_inN, a_inN;
  Mat3 C_StoN;
  Vec3 omega_nb_inS;   ///< angular rate w.r.t. the n-frame
  Vec3 gyro_inS;       ///< + earth rate: what an ideal gyro reads
  Vec3 accel_inS;      ///< specific force (what an ideal accelerometer reads)
  double wheel_angle = 0.0, wheel_rate = 0.0;  ///< alpha, d alpha/dt (wheel modules)
  double wheel_centre_speed = 0.0;  ///< forward speed of the wheel centre (rigid motion) [m/s]
};

struct DatasetSummary {
  double duration = 0.0;   ///< [s]
  double distance = 0.0;   ///< travelled by o [m]
  std::uint64_t imu_rows = 0;  ///< per file
  std::uint64_t bytes = 0;     ///< all files written
  int files = 0;
  double seconds = 0.0;    ///< wall-clock time
  std::string scenario;
};

class Simulation {
 public:
  static constexpr int kGroups = 3;  ///< left-wheel, right-wheel, body

  /// Builds the scenario and draws every random parameter from cfg.seed.
  /// `base_dir` resolves relative scenario/speed paths.
  explicit Simulation(const SimConfig& cfg);

  const SimConfig& config() const { return cfg_; }
  const Scenario& scenario() const { return *scenario_; }
  double start_time() const { return scenario_->start_time(); }
  double end_time() const { return end_; }
  /// The length of the data [s]: the last IMU sample is stamped start_time() + data_duration()
  /// (fault times count from start_time(); sample k is at k / rate).
  double data_duration() const;
  double speed_scale() const { return speed_scale_; }
  const ModuleModel& module(int g) const { return modules_[g]; }
  const std::vector<ChipModel>& chips(int g) const { return chips_[g]; }
  double gravity() const { return gravity_; }
  Vec3 earth_rate() const { return omega_ie_; }

  /// The true motion of module g's sensor at true time t (wheel angle integrated
  /// from the start by Gauss-Legendre quadrature).
  ImuTruth truth(int g, double t) const;
  /// The wheel's rotation rate d alpha / dt at true time t (rolling rate with the slip effect
  /// and slip faults) [rad/s]; the wheel angle is its integral from start_time().
  double wheel_rate(int g, double t) const;
  /// The extra wheel angle of slip fault `e` of wheel g: integral of ratio * w(t) * v_wc / R
  /// over the event within the data [rad] (Gauss-Legendre on the sample grid).
  double slip_extra_angle(int g, const ModuleModel::SlipEvent& e) const;

  /// Error-free mean samples of module g over the sample grid, for k = 1..count
  /// (interval (t_{k-1}, t_k], t_k = start + k / rate), without the clock offset.
  std::vector<ImuSample> ideal_samples(int g, std::size_t count) const;

  /// The manifests of the dataset (paths relative to the dataset directory).
  Manifest manifest() const;
  Manifest ideal_manifest() const;
  /// The gyro full scale both manifests state [rad/s]: errors.gyro_range with the saturation
  /// effect on, else 0 (not stated).
  double gyro_range() const;

  /// Writes the dataset into `dir` (see docs/simulator.md). Refuses a non-empty `dir`
  /// unless `force`. Shows progress on a terminal when `progress`.
  DatasetSummary write(const std::filesystem::path& dir, bool force, bool progress) const;

  static const char* group_name(int g);
  static const char* group_dir(int g);

 private:
  friend class GroupStepper;
  std::string errors_yaml() const;

  SimConfig cfg_;
  std::unique_ptr<Scenario> scenario_;
  double end_ = 0.0;
  double speed_scale_ = 1.0;
  double gravity_ = 9.8;
  Vec3 omega_ie_ = Vec3::Zero();
  std::array<ModuleModel, kGroups> modules_;
  std::array<std::vector<ChipModel>, kGroups> chips_;
};

}  // namespace wheelins::sim
