// The noise model learned from the data, one place for both filter structures
// (docs/filter.md section 13). The figures a run is given (the manifest's, or the
// defaults) are priors:
//  - at the end of the static period, the white noise measured at rest replaces the
//    gyro's angle random walk and is the floor of the velocity random walk, and the
//    gyro bias starts with the alignment's own uncertainty (white noise / sqrt(T));
//  - in motion, every velocity update's innovations feed Mehra's correlation method
//    (VelocityNoiseMatcher): the velocity random walk of the module (what a vibrating
//    wheel adds) and the measurement noise of each axis, used from then on by both the
//    distributed and the centralized filter (the back-ends read a subsystem's
//    ProcessNoise and the Measurement's R);
//  - a Wheel-IMU's gyro bias instability follows the corrections its updates make
//    (BiasInstabilityMatcher), between a floor and the prior.
// It also keeps the consistency figures of every measurement type (mean NIS, share
// over the 99.9 % test, rejected) and notes every estimate that leaves 3 sigma of
// its prior. NoiseAdaptationOptions::enabled = false holds the given figures fixed
// and only reports.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "wheelins/filter/noise_identification.hpp"
#include "wheelins/fusion/measurement.hpp"

namespace wheelins {

/// How one measurement type of one module agreed with its noise model.
struct MeasurementConsistency {
  std::uint64_t updates = 0;   ///< fused or rejected
  std::uint64_t rejected = 0;  ///< by the innovation gate
  std::uint64_t over = 0;      ///< test ratio > 1 (NIS beyond its 99.9 % quantile)
  double sum_nis = 0.0;
  int dim = 3;
  double mean_nis() const { return updates ? sum_nis / static_cast<double>(updates) : 0.0; }
};

/// An error-state estimate that left 3 sigma of its prior (the first time, per state).
struct PriorExcursion {
  int state = -1;        ///< error-state index (BG.., BA.., SG.., SA..)
  double t = 0.0;        ///< [s]
  double value = 0.0;    ///< the estimate's change from its start (SI)
  double prior_sigma = 0.0;
};

/// What was identified for one module, for the run's report and noise.yaml.
struct ModuleNoiseReport {
  std::string module;
  bool wheel = true;
  ImuNoise given;                     ///< the figures the run was given
  SensorNoiseEstimate gyro_rest, accel_rest;  ///< the static period's Allan variance
  double vrw_start = 0.0;             ///< the velocity random walk the estimate started from
  double vrw = 0.0;                   ///< in use at the end [m/s/sqrt(s)]
  double arw = 0.0;                   ///< in use at the end [rad/sqrt(s)]
  double gyro_bias_instability = 0.0; ///< in use at the end [rad/s]
  double gyro_bias_start_sigma = 0.0; ///< the bias uncertainty after the alignment [rad/s]
  bool adapted = false;               ///< the in-motion estimates were in use
  Vec3 velocity_std = Vec3::Zero();   ///< measurement noise in use at the end [m/s]
  Vec3 velocity_std_given = Vec3::Zero();
  Vec3 nis_axes = Vec3::Ones();       ///< mean dz_i^2 / S_i over the last window
  MeasurementConsistency velocity, position;
  std::vector<int> held;              ///< error states not estimated
  std::vector<int> constraint_only;   ///< estimated from the position constraint alone
  std::vector<PriorExcursion> excursions;
  std::vector<std::string> warnings;  ///< the noise model and the data disagree: what to change
};

class NoiseAdaptation {
 public:
  NoiseAdaptation(const NoiseAdaptationOptions& opt, Subsystems& subs, double update_interval);

  /// At the end of the static period, before the filters take the subsystems' covariances.
  void on_start(int i, const StaticAccumulator& stat, double t0);
  /// Before subsystem i's velocity update: the measurement noise as identified.
  void prepare_velocity(int i, Measurement& m);
  /// After it: the innovation statistics, the bias instability, the prior excursions.
  /// `bias_before`: subsystem i's gyro-bias estimate before the update.
  void after_velocity(int i, const Measurement& m, const UpdateReport& rep,
                      const Vec3& bias_before, double t);
  void after_position(int i, const UpdateReport& rep);

  /// The report of subsystem i (with the warnings) as of now.
  ModuleNoiseReport report(int i) const;
  const NoiseAdaptationOptions& options() const { return opt_; }

 private:
  struct State {
    VelocityNoiseMatcher matcher;
    BiasInstabilityMatcher bias;
    ImuNoise given;
    Vec3 r_given = Vec3::Zero();
    SensorNoiseEstimate gyro_rest, accel_rest;
    double vrw_start = 0.0, bias_start_sigma = 0.0;
    double t_start = 0.0;
    int starts = 0;             ///< the subsystem's filter starts seen (a restart resets the window)
    bool matcher_ready = false;
    MeasurementConsistency velocity, position;
    ImuErrors errors_start;     ///< sensor-error estimates at the start
    std::array<bool, kStateDim> excursion_seen{};
    std::vector<PriorExcursion> excursions;
  };
  void check_restart(int i, double t);
  void check_excursions(int i, double t);

  NoiseAdaptationOptions opt_;
  Subsystems& subs_;
  double dt_;
  std::vector<State> st_;
};

}  // namespace wheelins
