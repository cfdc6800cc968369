// The multi-IMU simulator's facade: exact IMU data for two Wheel-IMUs and a
// Body-IMU (four chips each; preset car-steered: two more Wheel-IMUs on the steered
// front wheels) from a Scenario, with a seeded, switchable error
// model, and the dataset writer behind `wheelins simulate`.
//
// Physics (docs/simulator.md): every IMU point's position and attitude are
// analytic functions of time (sim/jet.hpp); each sample is the mean angular
// rate and mean specific force over (t - dt, t], by 4-point Gauss-Legendre:
//   gyro  = omega_nb^s + C_n^s omega_ie^n,
//   accel = C_n^s (a^n - g^n + 2 omega_ie^n x v^n),
// consistent with nav/mechanization.cpp (v' = C f - 2 omega_ie x v + g).
//
// The parts: sim/kinematics (wheel rolling and slip, vibration gain, the group
// stepper), sim/vibration, sim/chip_errors (the per-sample error model and sensor
// faults), sim/draws (every random parameter), and, as members of Simulation,
// simulator.cpp (building the scenario and the draws), truth_queries.cpp (the true
// motion, error-free samples) and dataset_writer.cpp (the files, the manifests and
// errors.yaml, one writer thread per module). sim/imu_stream.hpp streams the
// samples of a Simulation in memory (no files).
#pragma once

#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "wheelins/io/manifest.hpp"
#include "wheelins/nav/types.hpp"
#include "wheelins/sim/chip_errors.hpp"
#include "wheelins/sim/config.hpp"
#include "wheelins/sim/kinematics.hpp"
#include "wheelins/sim/scenario.hpp"

namespace wheelins::sim {

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
  /// left-wheel, right-wheel, body: the groups of every preset (groups 0..2).
  static constexpr int kGroups = 3;
  /// With the steered front wheels of preset car-steered: front-left-wheel (3) and
  /// front-right-wheel (4).
  static constexpr int kMaxGroups = 5;

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
  /// The number K of samples per module file, and the stamp of sample k = 1..K [s].
  std::uint64_t sample_count() const;
  double stamp(std::uint64_t k) const { return start_time() + static_cast<double>(k) / cfg_.rate_hz; }
  double speed_scale() const { return speed_scale_; }
  /// The number of module groups of this vehicle: kGroups, or kMaxGroups with steered wheels.
  int groups() const { return static_cast<int>(modules_.size()); }
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

  static const char* group_name(int g);   ///< "left-wheel", ..., "front-right-wheel"
  static const char* group_dir(int g);    ///< "left-wheel-imu", ...
  static const char* chip_prefix(int g);  ///< "left" (chips left-C1.., stream left-ideal), ...
  /// The group of that name in this simulation, or -1.
  int group_index(const std::string& name) const;

  /// The sample grid and the environment of the group steppers.
  StepperClock clock() const;
  /// A stepper of module g on its clock offset by `offset` [s].
  GroupStepper stepper(int g, double offset) const;

 private:
  std::string errors_yaml() const;

  SimConfig cfg_;
  std::unique_ptr<Scenario> scenario_;
  double end_ = 0.0;
  double speed_scale_ = 1.0;
  double gravity_ = 9.8;
  Vec3 omega_ie_ = Vec3::Zero();
  std::vector<ModuleModel> modules_;             ///< per group; never resized after construction
  std::vector<std::vector<ChipModel>> chips_;
};

}  // namespace wheelins::sim
