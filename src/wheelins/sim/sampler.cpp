// The module and chip samplers of sampler.hpp.
#include "wheelins/sim/sampler.hpp"

#include <cmath>

namespace wheelins::sim {

ModuleSampler::ModuleSampler(const Simulation& sim, int g)
    : sim_(sim),
      m_(sim.module(g)),
      stepper_(sim.stepper(g, sim.module(g).time_offset)),
      wheel_noise_(m_.truth.wheel && sim.config().on("wheel_noise")) {}

void ModuleSampler::step(std::uint64_t k) {
  const SimConfig& cfg = sim_.config();
  const double rate = cfg.rate_hz, t0 = sim_.start_time();
  t_ = sim_.stamp(k);
  stepper_.step(t_, w_, f_);
  dT_ = m_.temp_rise * (1.0 - std::exp(-(t_ + m_.time_offset - t0) / cfg.errors.temp_tau));
  tau_ = static_cast<double>(k) / rate;
  // Wheel white noise from rolling: its density follows the vibration gain of the speed.
  wheel_sigma_ = 0.0;
  if (wheel_noise_) {
    const double v = sim_.scenario().state(t_ + m_.time_offset - 0.5 / rate).v_inN.norm();
    const double rest = cfg.errors.wheel_accel_noise_rest;
    wheel_sigma_ = cfg.errors.wheel_accel_noise * std::sqrt(rate) *
                   (rest + (1.0 - rest) * vibration_gain(m_, v));
  }
}

ChipSampler::ChipSampler(const Simulation& sim, int g, const ChipModel& chip)
    : errs_(sim.config(), chip), faults_(sim.config().faults, Simulation::group_name(g), chip.name) {}

bool ChipSampler::read(const ModuleSampler& s, Vec3& wm, Vec3& fm) {
  Vec3 step_g, step_a;
  if (faults_.steps(s.tau(), step_g, step_a))
    errs_.apply(s.temperature_rise(), s.gyro(), s.accel(), wm, fm, s.wheel_sigma(), &step_g, &step_a);
  else
    errs_.apply(s.temperature_rise(), s.gyro(), s.accel(), wm, fm, s.wheel_sigma());
  faults_.hold(s.tau(), wm, fm);
  return !faults_.dropped(s.tau());
}

}  // namespace wheelins::sim
