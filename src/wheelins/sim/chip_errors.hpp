// The error model of one simulated chip (docs/simulator.md): its drawn parameters
// (ChipModel, drawn by sim/draws.hpp), the per-sample corruption of the true mean
// rates (ChipErrors: turn-on biases, Gauss-Markov drift, temperature, scale factor
// and misalignment, white noise, wheel noise, saturation, quantization) and the
// sensor-fault events applied to its output (ChipFaults: bias jumps, stuck axes,
// dropouts).
#pragma once

#include <string>
#include <vector>

#include "wheelins/sim/config.hpp"
#include "wheelins/sim/rng.hpp"

namespace wheelins::sim {

/// Error parameters drawn for one chip (SI units).
struct ChipModel {
  std::string name;  ///< e.g. "left-C1"
  Vec3 gyro_bias = Vec3::Zero(), accel_bias = Vec3::Zero();  ///< turn-on
  Vec3 gyro_gm0 = Vec3::Zero(), accel_gm0 = Vec3::Zero();    ///< initial Gauss-Markov state
  Mat3 gyro_T = Mat3::Identity(), accel_T = Mat3::Identity();  ///< I + scale factor + misalignment
  Vec3 gyro_tempco = Vec3::Zero(), accel_tempco = Vec3::Zero();  ///< per K
};

/// The per-sample error model of one chip (state: Gauss-Markov biases and noise streams,
/// seeded from cfg.seed and the chip's name). `cfg` and `m` must outlive it.
class ChipErrors {
 public:
  ChipErrors(const SimConfig& cfg, const ChipModel& m);
  /// Advances the processes by one sample and corrupts the true mean rates w, f (sensor
  /// axes) into the readings wm, fm. `dT`: the temperature rise now [K]. `wheel_sigma`: the
  /// per-sample sigma of the wheel_noise effect now (0: none). `gyro_step` / `accel_step`
  /// (may be null): bias-jump faults added to the bias.
  void apply(double dT, const Vec3& w, const Vec3& f, Vec3& wm, Vec3& fm, double wheel_sigma,
             const Vec3* gyro_step = nullptr, const Vec3* accel_step = nullptr);
  /// The total bias of the last sample (turn-on + Gauss-Markov + temperature + steps).
  const Vec3& gyro_bias() const { return bg_; }
  const Vec3& accel_bias() const { return ba_; }

 private:
  const ErrorParams& e_;
  const ChipModel& m_;
  Rng gm_g_, gm_a_, arw_, vrw_, wheel_noise_;
  Vec3 bg_gm_, ba_gm_, bg_ = Vec3::Zero(), ba_ = Vec3::Zero();
  bool on_gm_g_, on_gm_a_, on_arw_, on_vrw_, on_sat_, on_q_;
  double phi_g_, q_g_, phi_a_, q_a_, s_arw_, s_vrw_;
};

/// The sensor-fault events of one chip, applied to its output samples. `faults` must
/// outlive it.
class ChipFaults {
 public:
  ChipFaults(const std::vector<FaultEvent>& faults, const std::string& group, const std::string& chip);
  /// The bias steps active at `tau` (seconds since the start of the data); false if none.
  bool steps(double tau, Vec3& gyro, Vec3& accel) const;
  /// Stuck axes: during the event the axis repeats the last output before its start (the
  /// first output if the event starts before the first sample).
  void hold(double tau, Vec3& wm, Vec3& fm);
  /// True if no sample is written at `tau`.
  bool dropped(double tau) const;

 private:
  struct Stuck {
    const FaultEvent* f;
    double value;
    bool have;
  };
  std::vector<const FaultEvent*> dropouts_, jumps_;
  std::vector<Stuck> stuck_;
};

}  // namespace wheelins::sim
