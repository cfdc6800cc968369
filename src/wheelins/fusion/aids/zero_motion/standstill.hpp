// Zero-velocity detection while the vehicle stands (docs/faults.md, "Standing still"): at
// every velocity-update step the navigator asks whether the vehicle stood still over the
// step's window; while it stands, every subsystem fuses the zero-velocity and zero-angular-
// rate measurements of filter/zero_motion.hpp (built in measurement.cpp for both filter
// structures) instead of its wheel-speed update, and the fault detector is not fed (the
// innovations of a standing vehicle are not evidence against a module).
//
// Standing: every module the vehicle solution is made of was quiet over the whole window, for
// at least `min_time`: the means of its compensated angular rate over blocks of `block`
// seconds all below `max_rate` in magnitude (a Wheel-IMU's wheel does not turn: at 1 deg/s a
// 0.3 m wheel rolls 5 mm/s), and the block means of its specific force spread by at most
// `max_force_spread` on every axis (no acceleration, no rocking). Everything is fixed-size and
// updated per sample without allocation.
#pragma once

#include <array>

#include "wheelins/fusion/options.hpp"

namespace wheelins {

class StandstillDetector {
 public:
  void configure(const StandstillOptions& options) { opt_ = options; }
  /// One sample of module i in its b-frame, raw (the estimates are removed at the block ends
  /// with `errors`, the module's current ones).
  void add(int i, const ImuSample& b, const ImuErrors& errors);
  /// At a velocity-update step at time t: whether the modules in `vehicle` (those the vehicle
  /// solution is made of) were all quiet over the window since the last call, and the vehicle
  /// has stood for min_time. Starts the next window.
  bool evaluate(const std::array<bool, kMaxModules>& vehicle, int n, double t);
  /// Module i was quiet over the last window (evaluate()'s).
  bool quiet(int i) const { return last_[i].quiet; }
  /// Module i's mean raw b-frame angular rate over the last window [rad/s], and its length [s].
  const Vec3& mean_raw_rate(int i) const { return last_[i].mean_raw_rate; }
  double window(int i) const { return last_[i].duration; }
  bool standing() const { return standing_; }

 private:
  struct Window {
    Vec3 block_dtheta = Vec3::Zero(), block_dvel = Vec3::Zero();
    double block_t = 0.0;
    Vec3 sum_dtheta = Vec3::Zero();
    double sum_t = 0.0;
    Vec3 f_min = Vec3::Constant(1e300), f_max = Vec3::Constant(-1e300);
    double max_rate = 0.0;
    int blocks = 0;
  };
  struct Result {
    bool quiet = false;
    Vec3 mean_raw_rate = Vec3::Zero();
    double duration = 0.0;
  };
  StandstillOptions opt_;
  std::array<Window, kMaxModules> w_{};
  std::array<Result, kMaxModules> last_{};
  double last_t_ = -1e300, still_since_ = -1e300;
  bool standing_ = false;
};

}  // namespace wheelins
