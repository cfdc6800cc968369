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
// The navigator holds the parts and calls them in that order (process()):
//   Subsystems     the Wheel-INSs and the Body-INS            (subsystems.hpp)
//   measurements   built once for both filter structures      (measurement.hpp)
//   FilterBackend  distributed (the paper) or centralized     (filter_backend.hpp)
//   OutputFusion   the vehicle solution and the records       (output.hpp)
//   FaultHandler   sensor faults, behind a few hooks          (fault_handler.hpp)
//   NoiseAdaptation the noise model learned from the data     (noise_adaptation.hpp)
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "wheelins/fusion/fault_handler.hpp"
#include "wheelins/fusion/filter_backend.hpp"
#include "wheelins/fusion/measurement.hpp"
#include "wheelins/fusion/noise_adaptation.hpp"
#include "wheelins/fusion/options.hpp"
#include "wheelins/fusion/output.hpp"
#include "wheelins/fusion/reference_weights.hpp"
#include "wheelins/fusion/standstill.hpp"
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
  const FaultMonitor& faults() const { return faults_->monitor(); }
  /// Closes the fault statistics at the end of the data.
  void finish();
  /// What the noise identification found for subsystem i, with the consistency figures and
  /// the warnings (noise_adaptation.hpp).
  ModuleNoiseReport noise_report(int i) const { return noise_.report(i); }
  /// The reference weights of eq. (8) at every constraint epoch (reference_weights.hpp).
  const std::vector<WeightRecord>& weight_history() const { return weights_.history(); }

 private:
  using Use = std::array<bool, kMaxModules>;
  void start_navigation(double t0);
  /// The velocity + NHC updates of every module in use, and the position constraint of
  /// every module tied to the others. Both expect every covariance at the current epoch
  /// (process() flushes them first).
  void velocity_step();
  void position_step();
  /// The velocity step of a standing vehicle: every quiet subsystem in use fuses zero velocity
  /// and zero angular rate (standstill.hpp) instead of its wheel-speed update.
  void zero_motion_step();
  /// The Body-INS level is shared: sharing on and the Body-INS counted.
  bool level_shared() const;
  /// The vehicle's heading from a counted subsystem that does not steer, other than `except`
  /// (a steered wheel's start); SteeringObserver::kNoHeading with none.
  double unsteered_heading(int except) const;
  /// The Body-INS's current roll/pitch to every Wheel-INS (when shared).
  void share_level();
  /// The wheel speeds of this velocity step: the paper's mean over the wheels, less what
  /// the fault handling screens out.
  void select_speeds(double t);
  /// The shared quantities of the velocity step (speeds_ selection) and of the position step
  /// (sh.k weights), at the current state; `level_now`: see SharedInputs::level_now.
  void take_speeds(SharedInputs& sh, bool level_now) const;
  void take_reference(SharedInputs& sh, bool level_now) const;
  /// The reference weights k (eq. 8) renormalised over the counted modules (0 for the
  /// others); false when no module counts.
  bool reference_weights(std::array<double, kMaxModules>& k, int& n_ref, int& n_tied) const;
  /// ReferenceWeighting::kCovariance: every subsystem's o variance into the weights, which
  /// become the subsystems' k_i (Subsystems::set_weights) for this epoch on.
  void update_weights();
  void count_velocity_update(int i, const UpdateReport& rep, double t);
  /// Covariance health of every subsystem in use (Cholesky test, asymmetry).
  void check_covariances();
  /// Time of the subsystem in use that is furthest behind.
  double min_time() const;
  /// The first module in use: it drives the output epochs (-1 if none).
  int output_driver() const;
  Use in_use_mask() const;
  /// Which modules the vehicle solution is made of now.
  Use vehicle_modules() const;

  NavigatorOptions opt_;
  earth::LocalFrame frame_;
  std::string source_;  ///< where the setup came from (messages)
  double static_start_, static_end_, initial_heading_;
  Subsystems subs_;
  std::unique_ptr<FilterBackend> filter_;
  OutputFusion output_;
  std::unique_ptr<FaultHandler> faults_;
  NoiseAdaptation noise_;
  ReferenceWeights weights_;
  StandstillDetector standstill_;
  double last_sample_t_ = -1e300;  ///< the newest sample of any module (outage rule)
  std::vector<StaticAccumulator> static_;
  SharedInputs shared_;    ///< scratch of the update steps (no allocation per epoch)
  Measurement meas_;       ///< scratch of the update steps
  SpeedSelection speeds_;  ///< the wheel speeds usable at the last update epoch
  bool navigating_ = false;
  double last_output_t_ = -1e300;
  double next_output_t_ = 0.0, next_velocity_t_ = 0.0, next_position_t_ = 0.0;
  NavigatorStats stats_;
};

}  // namespace wheelins
