// The navigator: turns a time-ordered stream of IMU samples of the selected modules
// into a vehicle trajectory, the paper's algorithm (Sections III and V) end to end.
// Data flow (one way):
//   samples -> static alignment -> subsystems (Wheel-INS, Body-INS) -> fusion -> records.
// Phases: samples before the static period are skipped, samples inside it are
// accumulated for the initial alignment, navigation starts at its end.
//
// Every sample is mechanized by its subsystem. At the velocity-update rate the
// subsystems share the Body-INS roll/pitch and the wheel speed (the mean over the
// Wheel-INSs, or each wheel's own) and every subsystem fuses its velocity + NHC
// (eq. 5, 6); at the position-constraint rate the weighted mean of the subsystems'
// reference points (eq. 7, 8) is a position measurement for each of them (eq. 11).
// The navigator holds the parts and reads as: propagate -> each aid steps -> output
// (process()):
//   Subsystems     the Wheel-INSs and the Body-INS            (subsystems.hpp)
//   FilterBackend  distributed (the paper) or centralized     (filter_backend.hpp)
//   the aids       one folder each: wheel velocity, zero motion, position constraint
//                  (aids/, aid.hpp), their measurements built once for both filter
//                  structures (measurement.hpp)
//   OutputFusion   the vehicle solution and the records       (output.hpp)
//   FaultHandler   the fault policy: decides which modules the aids use, behind a few hooks
//                                                             (fault_handler.hpp)
//   NoiseAdaptation the noise model learned from the data     (noise_adaptation.hpp)
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "wheelins/fusion/aids/aid.hpp"
#include "wheelins/fusion/aids/position_constraint/position_constraint_aid.hpp"
#include "wheelins/fusion/aids/wheel_velocity/wheel_velocity_aid.hpp"
#include "wheelins/fusion/aids/zero_motion/zero_motion_aid.hpp"
#include "wheelins/fusion/fault_handler.hpp"
#include "wheelins/fusion/filter_backend.hpp"
#include "wheelins/fusion/measurement.hpp"
#include "wheelins/fusion/noise_adaptation.hpp"
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
  /// Throws InputError if a name is unknown, the set has no Wheel-IMU or an option is out of
  /// range. (A Manifest converts to its VehicleSetup: Navigator(manifest, modules, ...).)
  Navigator(const VehicleSetup& setup, const std::vector<std::string>& modules,
            const NavigatorOptions& options, Sink sink);
  ~Navigator();
  Navigator(const Navigator&) = delete;
  Navigator& operator=(const Navigator&) = delete;

  /// One raw sample (sensor axes, increments) of module `index` (position in `modules`).
  /// Samples must come in time order across modules.
  void process(int index, const ImuSample& raw);

  bool navigating() const { return navigating_; }
  /// The counters, the aids' included.
  const NavigatorStats& stats() const;
  /// When navigation started [s] (stats().t_start without composing the aids' counters:
  /// for the per-sample checks).
  double start_time() const { return stats_.t_start; }
  int subsystem_count() const { return subs_.size(); }
  /// Subsystem i is a steered wheel that follows the others (Subsystems::follows).
  bool follows(int i) const { return subs_.follows(i); }
  const Subsystem& subsystem(int i) const { return subs_.at(i); }
  Subsystem& subsystem(int i) { return subs_.at(i); }
  /// The measurements of subsystem i as this navigator's filter would fuse them now, at the
  /// current state (the Body-INS level as it is now), H with a block for every IMU
  /// (measurement.hpp): the velocity + NHC update (eq. 5/6) and the position constraint
  /// (eq. 11). With fault handling, only the modules that count enter the mean wheel speed
  /// and the reference (the velocity measurement uses the speed selection of the last
  /// update epoch).
  void velocity_measurement(int i, Measurement& m) const { velocity_.measurement(i, m); }
  void position_measurement(int i, Measurement& m) const { position_.measurement(i, m); }
  /// The fused vehicle solution now.
  TrajectoryRecord vehicle_record() const;
  /// Health, counters and the report of detected faults.
  const FaultMonitor& faults() const { return faults_->monitor(); }
  /// Closes the fault statistics at the end of the data.
  void finish();
  /// What the noise identification found for subsystem i, with the consistency figures and
  /// the warnings (noise_adaptation.hpp).
  ModuleNoiseReport noise_report(int i) const { return noise_.report(i); }
  /// The reference weights of eq. (8) at every constraint epoch (aids/position_constraint/reference_weights.hpp).
  const std::vector<WeightRecord>& weight_history() const { return position_.weight_history(); }

 private:
  void start_navigation(double t0);
  /// The velocity-update epoch at time t: the zero-motion aid's updates while the vehicle
  /// stands, else the wheel-velocity aid's. Expects every covariance at t.
  void velocity_epoch(double t);
  /// The vehicle's heading from a counted subsystem that does not steer, other than `except`
  /// (a steered wheel's start); SteeringObserver::kNoHeading with none.
  double unsteered_heading(int except) const;
  /// Covariance health of every subsystem in use (Cholesky test, asymmetry).
  void check_covariances();
  /// The first module in use: it drives the output epochs (-1 if none).
  int output_driver() const;

  NavigatorOptions opt_;
  earth::LocalFrame frame_;
  std::string source_;  ///< where the setup came from (messages)
  double static_start_, static_end_, initial_heading_;
  Subsystems subs_;
  std::unique_ptr<FilterBackend> filter_;
  OutputFusion output_;
  std::unique_ptr<FaultHandler> faults_;
  NoiseAdaptation noise_;
  SharedInputs shared_;    ///< scratch of the aids (no allocation per epoch)
  Measurement meas_;       ///< scratch of the aids
  AidContext ctx_;         ///< the parts above, as the aids see them
  // The aid sources (aids/), each with its schedule and statistics.
  WheelVelocityAid velocity_;
  ZeroMotionAid zero_motion_;
  PositionConstraintAid position_;
  double last_sample_t_ = -1e300;  ///< the newest sample of any module (outage rule)
  std::vector<StaticAccumulator> static_;
  bool navigating_ = false;
  double last_output_t_ = -1e300;
  double next_output_t_ = 0.0;
  /// The counters of the navigator; the aids' are copied in by stats().
  mutable NavigatorStats stats_;
};

}  // namespace wheelins
