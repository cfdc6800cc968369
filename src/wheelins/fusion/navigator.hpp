// The navigator: turns a time-ordered stream of IMU samples from the modules of
// a manifest into a vehicle trajectory. Data flow (one way):
//   samples -> static alignment -> subsystems (Wheel-INS, Body-INS) -> fusion -> records.
// Phases: samples before the static period are skipped, samples inside it are
// accumulated for the initial alignment, navigation starts at its end.
//
// Fusion (paper Section III and V-B, the distributed filter): every subsystem keeps
// its own 21-state EKF. At the velocity-update rate the wheel speed is shared (the
// mean over the Wheel-INSs, or each wheel's own speed), the Body-INS's roll/pitch is
// given to the Wheel-INSs, and every subsystem fuses its velocity + NHC. At the
// position-constraint rate, the weighted mean of the subsystems' reference points
// (eq. 9) is a position measurement for each of them (eq. 12).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "wheelins/fusion/fault_monitor.hpp"
#include "wheelins/fusion/filter_backend.hpp"
#include "wheelins/fusion/measurement.hpp"
#include "wheelins/fusion/options.hpp"
#include "wheelins/fusion/output.hpp"
#include "wheelins/fusion/subsystems.hpp"
#include "wheelins/nav/trajectory_record.hpp"
#include "wheelins/nav/vehicle.hpp"

namespace wheelins {

class Navigator {
 public:
  static constexpr int kMaxModules = wheelins::kMaxModules;
  /// Receives records: stream 0 is the vehicle (the fused solution), streams 1..N the
  /// subsystems' own solutions (only when N > 1).
  using Sink = OutputFusion::Sink;

  /// `modules`: names of modules of `setup`; the first one drives the output epochs.
  /// Throws InputError if a name is unknown or the set has no Wheel-IMU. (A Manifest
  /// converts to its VehicleSetup: Navigator(manifest, modules, options, sink).)
  Navigator(const VehicleSetup& setup, const std::vector<std::string>& modules,
            const NavigatorOptions& options, Sink sink);
  ~Navigator();

  /// One raw sample (sensor axes, increments) of module `index` (position in `modules`).
  /// Samples must come in time order across modules.
  void process(int index, const ImuSample& raw);

  bool navigating() const { return navigating_; }
  const NavigatorStats& stats() const { return stats_; }
  int subsystem_count() const { return subs_.size(); }
  const Subsystem& subsystem(int i) const { return subs_.at(i); }
  Subsystem& subsystem(int i) { return subs_.at(i); }
  /// The measurements of subsystem i as this navigator's filter would fuse them now, at the
  /// current state (the Body-INS level as it is now), H with a block for every IMU
  /// (measurement.hpp): the velocity + NHC update (eq. 5/6) and the position constraint
  /// (eq. 11). With fault handling, only the modules that count enter the mean wheel speed
  /// and the reference (the velocity measurement uses the speed selection of the last
  /// update epoch).
  void velocity_measurement(int i, Measurement& m) const;
  void position_measurement(int i, Measurement& m) const;
  /// The fused vehicle solution now.
  TrajectoryRecord vehicle_record() const;
  /// Health, counters and the report of detected faults.
  const FaultMonitor& faults() const { return faults_; }
  /// Closes the fault statistics at the end of the data.
  void finish();

 private:
  void start_navigation(double t0);
  /// Velocity updates of every module in use (the measurements of measurement.hpp, fused by
  /// the filter back-end). Like position_update(), it expects every covariance at the
  /// current epoch (process() flushes them first).
  void velocity_updates();
  void count_velocity_update(int i, const UpdateReport& rep, double t_now);
  /// The Body-INS level is shared: sharing on and the Body-INS counted.
  bool level_shared() const;
  /// The Body-INS's current roll/pitch to every Wheel-INS (when shared).
  void share_level();
  std::array<bool, kMaxModules> in_use_mask() const;
  /// The shared quantities of the velocity step (speeds_ selection) and of the position step
  /// (sh.k weights), at the current state; `level_now`: see SharedInputs::level_now.
  void take_speeds(SharedInputs& sh, bool level_now) const;
  void take_reference(SharedInputs& sh, bool level_now) const;
  /// The reference weights k (eq. 8) renormalised over the counted modules (0 for the
  /// others); false when no module counts.
  bool reference_weights(std::array<double, kMaxModules>& k, int& n_ref, int& n_tied) const;
  void position_update();
  Mat21 covariance(int i) const;
  /// Which modules the vehicle solution is made of now.
  std::array<bool, kMaxModules> vehicle_modules() const;
  double min_time() const;

  // Fault handling (fault_monitor.hpp).
  struct Runtime {
    double last_t = 0.0;             ///< newest sample seen
    MotionAccumulator realign;       ///< while kRealign
    double saturated_until = -1e300; ///< the gyro was at full scale until this time + hold
    bool saturation_reported = false;
    bool speed_rejected = false;     ///< in a streak of rejected wheel speeds
    bool detector_fired = false;     ///< reported once for a lone module
    int heading_fails = 0;           ///< consecutive constraint epochs off the others' heading
    ImuErrors errors_new, errors_old;  ///< sensor-error estimates 0-10 s and 10-20 s ago
    double snapshot_t = -1e300;
    bool have_snapshot = false;
    bool revert_errors = false;      ///< restart from errors_old (after an isolation)
  };
  static constexpr double kSnapshotInterval = 10.0;  ///< [s]
  static constexpr double kSaturationFree = 1.0;     ///< [s] unsaturated before lending its speed
  void isolate(int i, double t, const std::string& what);
  void check_headings(double t);
  void check_covariances();
  void check_wheel_speeds(double t, const std::array<WheelVelocityInput, kMaxModules>& own,
                          std::array<bool, kMaxModules>& speed_ok);
  bool in_use(int i) const { return !opt_.faults.enabled || faults_.flowing(i); }
  bool counted(int i) const { return !opt_.faults.enabled || faults_.counts(i); }
  int output_driver() const;
  void watch_outages(int index, double t);
  void handle_saturation(int index, const ImuSample& raw, ImuSample& b);
  bool substitute_speed(int wheel_index, double* speed) const;
  void begin_realign(int i, double t, const std::string& what, const std::string& action);
  void restart(int i, double t);
  VehicleFix vehicle_fix(int i, double t) const;
  void fault_housekeeping(double t);

  NavigatorOptions opt_;
  earth::LocalFrame frame_;
  std::string source_;  ///< where the setup came from (messages)
  double static_start_, static_end_, initial_heading_;
  Subsystems subs_;
  std::unique_ptr<FilterBackend> filter_;
  OutputFusion output_;
  std::vector<StaticAccumulator> static_;
  SharedInputs shared_;    ///< scratch of the update steps (no allocation per epoch)
  Measurement meas_;       ///< scratch of the update steps
  SpeedSelection speeds_;  ///< the wheel speeds usable at the last update epoch
  FaultMonitor faults_;
  bool degraded_ = false;  ///< every wheel saturated or recovering: nobody is blamed
  std::array<bool, kMaxModules> excused_{};  ///< saturated or recovering this epoch
  std::vector<Runtime> rt_;
  bool navigating_ = false;
  double last_output_t_ = -1e300;
  double next_output_t_ = 0.0, next_velocity_t_ = 0.0, next_position_t_ = 0.0;
  NavigatorStats stats_;
};

}  // namespace wheelins
