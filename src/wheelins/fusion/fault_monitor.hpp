// Sensor-fault bookkeeping of the multi-IMU fusion (the paper's remark that the
// distributed design extends to a sensor-failure-resilient system, Section VII):
// the health of every module, the innovation-based fault detector, the
// counters, and the fault report (what was detected, when, what was done).
//
// The fault handler (fault_handler.hpp) decides and acts; this class only keeps
// the state machine and the record, so it can be tested on its own.
//
//   kOk ──(no data for stale_after)──> kOut ──(data again)──> kRealign
//   kOk ──(detector fires)──────────> kIsolated ──(retry_after)──> kRealign
//   kRealign ──(realign_time of data)──> kProbation ──(probation passed)──> kOk
//   kProbation ──(detector fires)──> kIsolated
//
// Only kOk modules enter the fused solution, the mean wheel speed and the
// reference of the position constraint; kProbation modules receive the
// constraint (they are tied back to the others) without influencing it.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "wheelins/nav/types.hpp"

namespace wheelins {

struct FaultOptions {
  bool enabled = true;
  double stale_after = 0.1;         ///< [s] a module whose data lag the newest by more is out
  double max_gap = 0.05;            ///< [s] a longer sample interval is a gap: not mechanized
  double realign_time = 0.5;        ///< [s] of data levelling a module that comes back
  double probation = 10.0;          ///< [s] a module that came back is tied to the others first
  double retry_after = 10.0;        ///< [s] an isolated module is re-initialised after this
  double speed_gate = 5.0;          ///< [sigma] a wheel speed disagreeing more is not used
  double wheel_mismatch = 0.15;     ///< [m/s] wheel speeds further apart (or 10 %) disagree
  double test_ratio = 10.0;         ///< velocity test ratio counted as failed by the detector
  int window = 20;                  ///< the detector's window of velocity tests (<= 64)
  int max_failed = 15;              ///< failed tests in the window that declare a fault
  double heading_gate = 5.0 * 3.14159265358979323846 / 180.0;  ///< [rad] vs the others' mean
  int heading_epochs = 5;           ///< constraint epochs in a row off by more: isolated
  double saturation_margin = 0.995; ///< |gyro| >= margin * full scale is saturated
  double saturation_hold = 0.1;     ///< [s] a saturated wheel's speed stays unused this long after
  /// [s] no data from any module for longer ends the run with an OutageError (with or without
  /// fault handling): the motion across it is unknown, and extrapolating it is no answer.
  double max_outage = 10.0;
  double reverse_speed = 0.3;       ///< [m/s] wheel speeds compared in sign from this speed on
  double reverse_time = 2.0;        ///< [s] a wheel rolling against the others this long is isolated

  /// Throws InputError naming the option if a value is out of range.
  void validate() const;
};

/// No data from any module for longer than FaultOptions::max_outage: the navigation cannot go
/// on. `module` (its index in the navigator) is the one whose sample came after the gap.
class OutageError : public InputError {
 public:
  OutageError(const std::string& what, int module, double t_before, double t_after)
      : InputError(what), module(module), t_before(t_before), t_after(t_after) {}
  int module;
  double t_before, t_after;
};

enum class Health { kOk, kOut, kRealign, kProbation, kIsolated };
const char* to_string(Health h);

/// One line of the fault report.
struct FaultEvent {
  double t = 0.0;      ///< [s], the data's time
  std::string module;  ///< module name
  std::string what;    ///< what was detected
  std::string action;  ///< what was done
};

struct ModuleFaultStats {
  std::uint64_t gaps = 0;               ///< data gaps and outages
  std::uint64_t saturated_samples = 0;  ///< gyro readings at full scale
  std::uint64_t speed_rejected = 0;     ///< wheel speeds left out of the mean (slip, lift, fault)
  std::uint64_t velocity_tests = 0;     ///< velocity/NHC updates tested
  std::uint64_t velocity_failed = 0;    ///< of which test ratio > FaultOptions::test_ratio
  std::uint64_t velocity_rejected = 0;  ///< refused by the velocity gate (filter option)
  std::uint64_t isolations = 0;         ///< times declared faulty
  std::uint64_t restarts = 0;           ///< re-initialisations from the others
  double seconds_unused = 0.0;          ///< time not in kOk after the start [s]
};

class FaultMonitor {
 public:
  static constexpr int kMaxWindow = 64;
  static constexpr std::size_t kMaxEvents = 10000;

  FaultMonitor() = default;
  FaultMonitor(std::vector<std::string> module_names, const FaultOptions& options);

  int size() const { return static_cast<int>(modules_.size()); }
  Health health(int i) const { return modules_[i].health; }
  const std::string& name(int i) const { return modules_[i].name; }
  /// In the fused solution, the mean speed and the constraint's reference.
  bool counts(int i) const { return modules_[i].health == Health::kOk; }
  /// Receives the position constraint.
  bool tied(int i) const {
    return modules_[i].health == Health::kOk || modules_[i].health == Health::kProbation;
  }
  /// Navigating on its own data (possibly isolated).
  bool flowing(int i) const {
    return tied(i) || modules_[i].health == Health::kIsolated;
  }
  int count_ok() const;
  /// When module i entered its current health.
  double since(int i) const { return modules_[i].since; }

  /// Moves module i to h at time t and records the event.
  void transition(int i, Health h, double t, const std::string& what, const std::string& action);
  /// Records an event without a change of health (e.g. saturation starts).
  void note(int i, double t, const std::string& what, const std::string& action);
  /// Records an event that the run also prints as a warning (warnings()).
  void warn(int i, double t, const std::string& what, const std::string& action);
  /// One line per warn(), naming the module.
  const std::vector<std::string>& warnings() const { return warnings_; }

  /// One velocity test of module i; true when the detector declares it faulty
  /// (max_failed of the last `window` tests over the threshold).
  bool velocity_test(int i, double test_ratio);
  /// Forgets module i's test history (after a restart).
  void clear_tests(int i);

  ModuleFaultStats& stats(int i) { return modules_[i].stats; }
  const ModuleFaultStats& stats(int i) const { return modules_[i].stats; }
  const std::vector<FaultEvent>& events() const { return events_; }
  std::uint64_t events_dropped() const { return dropped_; }
  /// Adds the time spent outside kOk up to t to the statistics (call once at the end).
  void finish(double t);
  const FaultOptions& options() const { return opt_; }

 private:
  struct Module {
    std::string name;
    Health health = Health::kOk;
    double since = 0.0;         ///< entered the current health
    double unused_since = 0.0;  ///< left kOk
    std::array<bool, kMaxWindow> failed{};
    int pos = 0, filled = 0, failures = 0;
    ModuleFaultStats stats;
  };
  FaultOptions opt_;
  std::vector<Module> modules_;
  std::vector<FaultEvent> events_;
  std::vector<std::string> warnings_;
  std::uint64_t dropped_ = 0;
};

/// The fault report as CSV (t, module, what, action) and as a readable summary.
std::string fault_report_csv(const FaultMonitor& m);
std::string fault_report_text(const FaultMonitor& m);

}  // namespace wheelins
