// The navigator: turns a time-ordered stream of IMU samples from the modules of
// a manifest into a vehicle trajectory. Data flow (one way):
//   samples -> static alignment -> subsystems (Wheel-INS, ...) -> fusion -> records.
// Phases: samples before the static period are skipped, samples inside it are
// accumulated for the initial alignment, navigation starts at its end.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "wheelins/filter/wheel_ins.hpp"
#include "wheelins/io/trajectory.hpp"

namespace wheelins {

struct NavigatorOptions {
  WheelInsOptions wheel;
  MechanizationOptions::Method mechanization = MechanizationOptions::Method::kRotationExact;
  /// Compensate the earth rotation (the manifest says whether the data contain it).
  bool earth_rotation = true;
  /// Output interval [s]; 0 = every epoch of the first module.
  double output_interval = 0.0;
  /// Print the options in human units (OpenVINS style), one per line.
  std::string describe() const;
};

/// Counters and timing of a run.
struct NavigatorStats {
  std::uint64_t samples = 0;            ///< samples given to process()
  std::uint64_t epochs = 0;             ///< navigation epochs (after alignment)
  std::uint64_t velocity_updates = 0;
  std::uint64_t velocity_rejected = 0;  ///< refused by the innovation gate
  std::uint64_t records = 0;
  double t_start = 0.0, t_end = 0.0;    ///< navigation interval [s]
  double max_velocity_test_ratio = 0.0;
};

class Navigator {
 public:
  using Sink = std::function<void(const TrajectoryRecord&)>;

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
  const WheelIns& wheel(int i) const { return *wheels_.at(i); }
  int module_count() const { return static_cast<int>(wheels_.size()); }

 private:
  void start_navigation(double t0);
  TrajectoryRecord make_record() const;

  Manifest manifest_;
  NavigatorOptions opt_;
  Sink sink_;
  earth::LocalFrame frame_;
  std::vector<std::unique_ptr<WheelIns>> wheels_;
  std::vector<StaticAccumulator> static_;
  bool navigating_ = false;
  double next_output_t_ = 0.0;
  NavigatorStats stats_;
};

}  // namespace wheelins
