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

#include "wheelins/filter/body_ins.hpp"
#include "wheelins/filter/wheel_ins.hpp"
#include "wheelins/fusion/centralized.hpp"
#include "wheelins/fusion/fault_monitor.hpp"
#include "wheelins/nav/trajectory_record.hpp"
#include "wheelins/nav/vehicle.hpp"

namespace wheelins {

/// How the Wheel-INSs get their forward speed.
enum class SpeedSharing {
  kMean,  ///< the paper: the mean of all Wheel-IMU speeds, for every subsystem
  kOwn,   ///< each Wheel-INS its own wheel's speed; a Body-INS the mean, at the mean wheel point
};

struct FusionOptions {
  SpeedSharing speed = SpeedSharing::kMean;
  bool share_level = true;                ///< Body-INS roll/pitch to the Wheel-INSs
  bool position_constraint = true;
  double position_update_interval = 1.0;  ///< [s]; the paper's 1 Hz
  double position_std = 0.2;              ///< [m] (Table 9)
  double position_gate = 0.0;             ///< test-ratio gate; 0 = off
  std::vector<double> weights;            ///< k_i of eq. (9); empty = equal
  /// One joint covariance over all IMUs (Section VI-B-2) instead of one per subsystem.
  bool centralized = false;
};

struct NavigatorOptions {
  WheelInsOptions wheel;
  BodyInsOptions body;
  FusionOptions fusion;
  MechanizationOptions::Method mechanization = MechanizationOptions::Method::kRotationExact;
  /// Compensate the earth rotation (the manifest says whether the data contain it).
  bool earth_rotation = true;
  /// Sensor-fault handling: outages, saturation, slip, isolation of faulty IMUs.
  FaultOptions faults;
  /// Output interval [s]; 0 = every epoch of the first module.
  double output_interval = 0.0;
  /// Also send each subsystem's own solution to the sink (streams 1..N) of a multi-IMU run.
  bool module_records = true;
  /// Covariance time update every this many seconds, F integrated over the epochs in
  /// between (StrapdownEkf::set_covariance_interval); 0 = every IMU epoch. Measurement
  /// updates always see P propagated to their epoch.
  double covariance_interval = 0.05;
  /// The options in human units (OpenVINS style), one per line.
  std::string describe() const;
};

/// Counters and timing of a run.
struct NavigatorStats {
  std::uint64_t samples = 0;            ///< samples given to process()
  std::uint64_t epochs = 0;             ///< navigation epochs of the first module
  std::uint64_t velocity_updates = 0;   ///< per subsystem, summed
  std::uint64_t velocity_rejected = 0;  ///< refused by the innovation gate
  std::uint64_t position_updates = 0;
  std::uint64_t position_rejected = 0;
  std::uint64_t records = 0;
  double t_start = 0.0, t_end = 0.0;    ///< navigation interval [s]
  double max_velocity_test_ratio = 0.0;
  double max_position_test_ratio = 0.0;
  /// Time spent in the velocity-update and position-constraint steps (all subsystems) and
  /// their number of occurrences, for the paper's Table 8 [s].
  double velocity_step_seconds = 0.0, position_step_seconds = 0.0;
  std::uint64_t velocity_steps = 0, position_steps = 0;
  /// Covariance health, checked at every velocity-update step for every subsystem in use:
  /// checks, failures of the Cholesky test (not positive definite), and the largest
  /// asymmetry max|P - P^T| / max|P| seen.
  std::uint64_t covariance_checks = 0, covariance_not_pd = 0;
  double max_covariance_asymmetry = 0.0;
};

/// One measurement of the centralized filter: dz = sum_j H[j] dx_j + e, e ~ N(0, R).
struct JointMeasurement {
  std::array<H3, kMaxCentralized> H;
  Vec3 dz = Vec3::Zero();
  Mat3 R = Mat3::Identity();
  double gate = 0.0;
};

class Navigator {
 public:
  static constexpr int kMaxModules = 16;
  /// Receives records: stream 0 is the vehicle (the fused solution), streams 1..N the
  /// subsystems' own solutions (only when N > 1).
  using Sink = std::function<void(int stream, const TrajectoryRecord&)>;

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
  int subsystem_count() const { return static_cast<int>(subs_.size()); }
  const Subsystem& subsystem(int i) const { return *subs_.at(i); }
  Subsystem& subsystem(int i) { return *subs_.at(i); }
  /// The centralized filter's measurements of subsystem i at the current state (also
  /// usable without a joint covariance, for checking them): the velocity + NHC update
  /// (eq. 5/6) and the position constraint (eq. 12), H with a block for every IMU.
  /// With fault handling, only the modules that count enter the mean wheel speed and the
  /// reference (the velocity measurement uses the speed selection of the last update epoch).
  void velocity_measurement(int i, JointMeasurement& m) const;
  void position_measurement(int i, JointMeasurement& m) const;
  /// The fused vehicle solution now.
  TrajectoryRecord vehicle_record() const;
  /// Health, counters and the report of detected faults.
  const FaultMonitor& faults() const { return faults_; }
  /// Closes the fault statistics at the end of the data.
  void finish();

 private:
  void start_navigation(double t0);
  /// Forward variance of a velocity row that carries no speed [m^2/s^2].
  static constexpr double kNoSpeedVar = 1e4;
  /// The wheel speeds an update epoch uses: speed_ok (in use, not saturated, agreeing with
  /// its own INS) and in_mean (also counted: the wheels whose speeds make the mean).
  struct SpeedSelection {
    std::array<bool, kMaxModules> speed_ok{}, in_mean{};
    int n_mean = 0;
  };
  /// Velocity updates of every module in use; in the centralized filter H also carries the
  /// other IMUs' blocks (velocity_measurement()). Like position_update(), it expects every
  /// covariance at the current epoch (process() calls flush_covariances() first).
  void velocity_updates();
  void count_velocity_update(int i, const UpdateReport& rep, double t_now);
  /// The Body-INS level is shared: sharing on and the Body-INS counted.
  bool level_shared() const;
  /// The Body-INS's current roll/pitch to every Wheel-INS (when shared).
  void share_level();
  /// The reference weights k (eq. 9) renormalised over the counted modules (0 for the
  /// others); false when no module counts.
  bool reference_weights(std::array<double, kMaxModules>& k, int& n_ref, int& n_tied) const;
  void position_measurement(int i, const std::array<double, kMaxModules>& k,
                            JointMeasurement& m) const;
  /// Adds, to the Body-INS block of a joint H, the dependence of a Wheel-INS measurement on
  /// the shared level: H_level * d(roll, pitch)/d(phi_body), scaled by `c`.
  void add_level_block(const Eigen::Matrix<double, 3, 2>& H_level, double c,
                       std::array<H3, kMaxCentralized>& h) const;
  /// Fuses a joint measurement into the joint covariance and feeds every subsystem back.
  UpdateReport fuse_joint(const JointMeasurement& m);
  /// Moves subsystem i's accumulated dynamics into the joint covariance.
  void propagate_joint(int i);
  /// Every covariance (own or joint) propagated to the current epoch.
  void flush_covariances();
  void position_update();
  /// Fuses dz = H dx_i + e into subsystem i (distributed) or the joint state (centralized).
  UpdateReport fuse(int i, const H3& H, const Vec3& dz, const Mat3& R, double gate);
  Mat21 covariance(int i) const;
  /// Subsystem i's own solution; without lat/lon/h (left NaN) when with_lla is false.
  TrajectoryRecord subsystem_record(int i, bool with_lla = true) const;
  /// Weighted mean of the subsystems in `use` (the paper's output, eq. 9).
  TrajectoryRecord fused_record(const std::array<bool, kMaxModules>& use) const;
  using Records = std::array<TrajectoryRecord, kMaxModules>;
  /// The same from records already made (recs[i] valid where use[i], and recs[first]).
  TrajectoryRecord fuse_records(const std::array<bool, kMaxModules>& use,
                                const Records& recs) const;
  /// Which modules the vehicle solution is made of now.
  std::array<bool, kMaxModules> vehicle_modules() const;
  /// The first module in `use` (0 if none).
  static int first_used(const std::array<bool, kMaxModules>& use);
  /// Output of one epoch: the vehicle record and each module's, each made once.
  void write_records(double t);
  Records out_recs_{};  ///< scratch of write_records (no allocation per epoch)
  double min_time() const;

  // Fault handling (fault_monitor.hpp).
  struct Runtime {
    double last_t = 0.0;             ///< newest sample seen
    double last_record_t = -1e300;   ///< time of the last subsystem record written
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

  VehicleSetup setup_;
  std::vector<std::string> sources_;  ///< per subsystem: where its samples come from
  NavigatorOptions opt_;
  Sink sink_;
  earth::LocalFrame frame_;
  std::vector<std::unique_ptr<Subsystem>> subs_;
  std::vector<WheelIns*> wheels_;
  BodyIns* body_ = nullptr;
  int body_index_ = -1;  ///< position of the Body-INS in subs_
  std::vector<double> weights_;
  std::vector<StaticAccumulator> static_;
  std::vector<ReferencePointModel> rp_models_;  ///< scratch of position_update(), sized once
  std::unique_ptr<JointCovariance> joint_;
  JointMeasurement joint_scratch_;  ///< of the centralized updates
  SpeedSelection speeds_;           ///< the wheel speeds usable at the last update epoch
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
