// What every aid source of the navigator shares (PX4's habit: one folder per aid source,
// each owning its schedule, its inputs, its gating report, its noise hooks and its
// statistics):
//   wheel_velocity/       the wheel-speed velocity + NHC update (eq. 5, 6)
//   zero_motion/          zero velocity and angular rate while the vehicle stands
//   position_constraint/  the position constraint among the IMUs (eq. 7, 8, 11)
// The navigator reads as: propagate every sample -> each aid steps when due -> output.
// The fault policy decides (in_use / counted / tied, the speeds a step may use, a module's
// restart) and is told of each fusion's report; the aids and the navigator act on those
// decisions (AidContext::act_on_faults). The gate itself (the test ratio
// against the innovation gate) is the filter's (filter/ekf_update.hpp); an aid counts it.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>

#include "wheelins/filter/ekf_update.hpp"
#include "wheelins/fusion/fault_handler.hpp"
#include "wheelins/fusion/filter_backend.hpp"
#include "wheelins/fusion/measurement.hpp"
#include "wheelins/fusion/noise_adaptation.hpp"
#include "wheelins/fusion/options.hpp"
#include "wheelins/fusion/output.hpp"
#include "wheelins/fusion/subsystems.hpp"

namespace wheelins {

using ModuleMask = std::array<bool, kMaxModules>;

/// An aid's statistics: its steps, its fusions and what the innovation gate said of them,
/// and the time its steps took (the paper's Table 8).
struct AidStats {
  std::uint64_t steps = 0, updates = 0, rejected = 0;
  double max_test_ratio = 0.0;
  double step_seconds = 0.0;  ///< [s]
  void count(const UpdateReport& rep) {
    ++updates;
    if (!rep.accepted) ++rejected;
    max_test_ratio = std::max(max_test_ratio, rep.test_ratio);
  }
};

/// A fixed-interval schedule: due when every subsystem in use has reached the next epoch.
class AidSchedule {
 public:
  explicit AidSchedule(double interval) : interval_(interval) {}
  void start(double t0) { next_ = t0 + interval_; }
  bool due(double t_all) const { return t_all + 1e-9 >= next_; }
  /// Past t_all: the next epoch after it.
  void advance(double t_all) {
    while (next_ <= t_all + 1e-9) next_ += interval_;
  }
  double interval() const { return interval_; }

 private:
  double interval_;
  double next_ = 0.0;
};

/// The navigator's parts an aid reads and acts through (they outlive the aids), with the
/// queries of the fault policy's decisions every aid asks.
struct AidContext {
  const NavigatorOptions& opt;
  Subsystems& subs;
  FilterBackend& filter;
  FaultHandler& faults;
  OutputFusion& output;
  NoiseAdaptation& noise;
  SharedInputs& shared;  ///< scratch of the steps (no allocation per epoch)
  Measurement& meas;     ///< scratch of the steps

  /// Which modules navigate on their own data now.
  ModuleMask in_use() const {
    ModuleMask use{};
    for (int i = 0; i < subs.size(); ++i) use[i] = faults.in_use(i);
    return use;
  }
  /// Which modules make the reference of eq. (8) now: those counted, less the steered wheels
  /// that follow (Subsystems::follows) while a Wheel-IMU that does not steer is counted.
  ModuleMask reference_modules() const {
    ModuleMask use{};
    bool unsteered = false;
    for (int i = 0; i < subs.size(); ++i) {
      use[i] = faults.counted(i);
      unsteered = unsteered || (use[i] && subs.is_wheel(i) && !subs.wheel(i).steered());
    }
    if (unsteered)
      for (int i = 0; i < subs.size(); ++i) use[i] = use[i] && !subs.follows(i);
    return use;
  }
  /// Which modules the vehicle solution is made of now (the reference's, else those in use).
  ModuleMask vehicle_modules() const { return or_in_use(reference_modules()); }
  /// Which modules are in good health now (those counted, else those in use).
  ModuleMask counted_modules() const {
    ModuleMask use{};
    for (int i = 0; i < subs.size(); ++i) use[i] = faults.counted(i);
    return or_in_use(use);
  }
  /// `use`, or the modules in use when it holds none.
  ModuleMask or_in_use(const ModuleMask& use) const {
    for (int i = 0; i < subs.size(); ++i)
      if (use[i]) return use;
    return in_use();
  }
  /// Time of the subsystem in use that is furthest behind.
  double min_time() const {
    double t = std::numeric_limits<double>::infinity();
    for (int i = 0; i < subs.size(); ++i)
      if (faults.in_use(i)) t = std::min(t, subs[i].time());
    return t;
  }
  /// The Body-INS level is shared: sharing on and the Body-INS counted (a module on probation
  /// or out does not pass its attitude on; the wheels keep the last level they were given).
  bool level_shared() const {
    return subs.has_body() && opt.fusion.share_level && faults.counted(subs.body_index());
  }
  /// The Body-INS's current roll/pitch to every Wheel-INS (when shared).
  void share_level() const;
  /// Takes what the fault policy decided at its last hooks (FaultActions): a module's heading
  /// offset forgotten, a module restarted from the vehicle (its subsystem and its filter).
  /// Called after every hook that may decide.
  void act_on_faults() const;
};

}  // namespace wheelins
