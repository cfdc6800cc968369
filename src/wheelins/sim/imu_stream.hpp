// A Simulation's IMU samples in memory: the io ImuStream that ImuMerger takes, yielding
// exactly what ImuFileReader yields from the files Simulation::write() would hold
// (the same samples, stamps and intervals, and the dropouts' gaps), without writing
// them. Tests and studies navigate a simulation this way (Navigator::process on an
// ImuMerger over simulated_streams()).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "wheelins/io/imu_file.hpp"
#include "wheelins/sim/sampler.hpp"

namespace wheelins::sim {

class SimulatedImuStream final : public ImuStream {
 public:
  /// Module `name` of sim.manifest() (a chip, e.g. "left-C1") or of sim.ideal_manifest()
  /// (the error-free stream of a group, e.g. "left-ideal"). `sim` must outlive the stream.
  /// Throws InputError naming the module if there is no such module.
  SimulatedImuStream(const Simulation& sim, const std::string& name);
  bool next(ImuSample& out) override;

 private:
  const Simulation& sim_;
  std::uint64_t k_ = 0, count_;
  ModuleSampler sampler_;
  std::unique_ptr<ChipSampler> chip_;     ///< null for an error-free stream
  std::unique_ptr<GroupStepper> ideal_;   ///< the error-free stream of a module with a clock offset
  double prev_t_ = 0.0;
  bool started_ = false;
};

/// One stream per name, in order (the owning ImuMerger constructor takes them).
std::vector<std::unique_ptr<ImuStream>> simulated_streams(const Simulation& sim,
                                                          const std::vector<std::string>& modules);

}  // namespace wheelins::sim
