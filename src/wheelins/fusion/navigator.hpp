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
#include "wheelins/io/trajectory.hpp"

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
  /// Output interval [s]; 0 = every epoch of the first module.
  double output_interval = 0.0;
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
  /// Receives records: stream 0 is the vehicle (the fused solution), streams 1..N the
  /// subsystems' own solutions (only when N > 1).
  using Sink = std::function<void(int stream, const TrajectoryRecord&)>;

  /// `modules`: names from the manifest; the first one drives the output epochs.
  /// Throws InputError if a name is unknown or the set has no Wheel-IMU.
  Navigator(const Manifest& manifest, const std::vector<std::string>& modules,
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
  void velocity_measurement(int i, JointMeasurement& m) const;
  void position_measurement(int i, JointMeasurement& m) const;
  /// The fused vehicle solution now.
  TrajectoryRecord vehicle_record() const;

 private:
  void start_navigation(double t0);
  void velocity_updates();
  /// The centralized filter's velocity updates: H also carries the other IMUs' blocks.
  void velocity_updates_centralized();
  /// The Body-INS's current roll/pitch to every Wheel-INS (when shared).
  void share_level();
  /// Adds, to the Body-INS block of a joint H, the dependence of a Wheel-INS measurement on
  /// the shared level: H_level * d(roll, pitch)/d(phi_body), scaled by `c`.
  void add_level_block(const Eigen::Matrix<double, 3, 2>& H_level, double c,
                       std::array<H3, kMaxCentralized>& h) const;
  /// Fuses a joint measurement into the joint covariance and feeds every subsystem back.
  UpdateReport fuse_joint(const JointMeasurement& m);
  void position_update();
  /// Fuses dz = H dx_i + e into subsystem i (distributed) or the joint state (centralized).
  UpdateReport fuse(int i, const H3& H, const Vec3& dz, const Mat3& R, double gate);
  Mat21 covariance(int i) const;
  TrajectoryRecord subsystem_record(int i) const;
  double min_time() const;

  Manifest manifest_;
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
  bool navigating_ = false;
  double next_output_t_ = 0.0, next_velocity_t_ = 0.0, next_position_t_ = 0.0;
  NavigatorStats stats_;
};

}  // namespace wheelins
