// The in-memory IMU stream of imu_stream.hpp.
#include "wheelins/sim/imu_stream.hpp"

namespace wheelins::sim {

namespace {

/// The group and chip of module `name` of the simulation's manifests; chip -1: the group's
/// error-free stream.
std::pair<int, int> find_module(const Simulation& sim, const std::string& name) {
  for (int g = 0; g < sim.groups(); ++g) {
    const std::vector<ChipModel>& chips = sim.chips(g);
    for (std::size_t c = 0; c < chips.size(); ++c)
      if (chips[c].name == name) return {g, static_cast<int>(c)};
    const std::string ideal = std::string(Simulation::chip_prefix(g)) + "-ideal";
    if (name == ideal) return {g, -1};
  }
  std::string known, ideal;
  for (int g = 0; g < sim.groups(); ++g) {
    for (const ChipModel& c : sim.chips(g)) known += (known.empty() ? "" : ", ") + c.name;
    ideal += (ideal.empty() ? "" : ", ") + std::string(Simulation::chip_prefix(g)) + "-ideal";
  }
  throw InputError("simulation: no module named '" + name + "' (modules: " + known + ", and " + ideal + ")");
}

}  // namespace

SimulatedImuStream::SimulatedImuStream(const Simulation& sim, const std::string& name)
    : sim_(sim), count_(sim.sample_count()), sampler_(sim, find_module(sim, name).first) {
  const auto [g, c] = find_module(sim, name);
  if (c >= 0) {
    chip_ = std::make_unique<ChipSampler>(sim, g, sim.chips(g)[static_cast<std::size_t>(c)]);
  } else if (sim.module(g).time_offset != 0.0) {
    ideal_ = std::make_unique<GroupStepper>(sim.stepper(g, 0.0));
  }
}

bool SimulatedImuStream::next(ImuSample& out) {
  Vec3 w, f;
  for (;;) {
    if (k_ >= count_) return false;
    sampler_.step(++k_);
    if (!chip_) {
      w = sampler_.gyro();
      f = sampler_.accel();
      if (ideal_) ideal_->step(sampler_.t(), w, f);  // no clock offset
      break;
    }
    if (chip_->read(sampler_, w, f)) break;  // else a dropout: no sample
  }
  // As ImuFileReader reads a rate file: the first interval is the nominal one, then the
  // difference of the stamps (across a dropout, the gap).
  const double t = sampler_.t();
  const double dt = started_ ? t - prev_t_ : 1.0 / sim_.config().rate_hz;
  started_ = true;
  prev_t_ = t;
  out.t = t;
  out.dt = dt;
  out.dtheta = w * dt;
  out.dvel = f * dt;
  return true;
}

std::vector<std::unique_ptr<ImuStream>> simulated_streams(const Simulation& sim,
                                                          const std::vector<std::string>& modules) {
  std::vector<std::unique_ptr<ImuStream>> out;
  for (const auto& name : modules) out.push_back(std::make_unique<SimulatedImuStream>(sim, name));
  return out;
}

}  // namespace wheelins::sim
