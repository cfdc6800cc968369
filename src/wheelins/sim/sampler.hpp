// One module's samples on the data's grid (sample k stamped start + k / rate), as the
// dataset writer (dataset_writer.cpp) and the in-memory stream (imu_stream.hpp) both
// make them: the true mean rates of its sensor on its own clock, the temperature rise
// and the wheel-noise level at each sample, and each chip's reading through its
// error model and sensor faults. One code path for both, so a simulation navigated in
// memory and from its files sees the same numbers.
#pragma once

#include <cstdint>

#include "wheelins/sim/simulator.hpp"

namespace wheelins::sim {

class ModuleSampler {
 public:
  /// Module g of `sim` (which must outlive the sampler).
  ModuleSampler(const Simulation& sim, int g);
  /// Advances to sample k (1 .. sim.sample_count(), in order).
  void step(std::uint64_t k);
  double t() const { return t_; }            ///< stamp of the current sample [s]
  double tau() const { return tau_; }        ///< since the start of the data (fault times) [s]
  /// True mean rate and specific force over the sample, sensor axes, on the module's clock.
  const Vec3& gyro() const { return w_; }
  const Vec3& accel() const { return f_; }
  double temperature_rise() const { return dT_; }  ///< [K]
  double wheel_sigma() const { return wheel_sigma_; }  ///< per-sample wheel_noise sigma [m/s^2]

 private:
  const Simulation& sim_;
  const ModuleModel& m_;
  GroupStepper stepper_;
  bool wheel_noise_;
  double t_ = 0.0, tau_ = 0.0, dT_ = 0.0, wheel_sigma_ = 0.0;
  Vec3 w_ = Vec3::Zero(), f_ = Vec3::Zero();
};

class ChipSampler {
 public:
  /// `chip` of module g of `sim` (both must outlive the sampler).
  ChipSampler(const Simulation& sim, int g, const ChipModel& chip);
  /// The chip's reading of the current sample of `s`. The error model runs on every sample
  /// (a dropout or a stuck axis draws the same random numbers, so the data after a sensor
  /// fault equal the fault-free run's); false when a dropout leaves the sample out.
  bool read(const ModuleSampler& s, Vec3& wm, Vec3& fm);
  /// The total bias of the last sample read.
  const ChipErrors& errors() const { return errs_; }

 private:
  ChipErrors errs_;
  ChipFaults faults_;
};

}  // namespace wheelins::sim
