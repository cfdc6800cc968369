// Sensor-fault handling as its own part of the fusion (docs/faults.md), behind a few
// hooks the navigator calls at fixed points of the paper's algorithm
// (Navigator::process()):
//   on_start            navigation starts
//   on_sample           every sample after the alignment: outages and gaps, re-levelling
//                       and the restart of a module that comes back, gyro saturation (the
//                       sample may be edited, or held back from navigation)
//   on_velocity_step    before a velocity-update step: snapshots of the sensor errors,
//                       probation passed, retries of isolated modules
//   screen_speeds       which wheel speeds the step may use (saturation, slip or lift)
//   on_velocity_update  each velocity update's report: the innovation-based detector
//   on_position_step    before a position-constraint step: the heading check (3+ modules)
//   finish              the end of the data
// and three queries the algorithm reads: in_use (navigating on its own data), counted
// (in the fused solution, the mean speed and the constraint's reference) and tied
// (receives the position constraint).
//
// NoFaultHandling, when fault handling is off, keeps every module in use and counted and
// decides nothing. FaultPolicy decides; it reads the subsystems, the filter back-end and the
// output fusion and changes none of them: what is to be done to a module (restart it from
// the others, forget its heading offset) is a FaultActions the navigator's parts take after
// each hook.
// FaultMonitor (fault_monitor.hpp) keeps the health state machine and the report.
#pragma once

#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "wheelins/fusion/fault_monitor.hpp"
#include "wheelins/fusion/output.hpp"

namespace wheelins {

/// What the fault policy decided be done to the modules. The policy changes nothing but its
/// own bookkeeping (the health states, the counters); the navigator's parts act on these
/// after each hook (AidContext::act_on_faults).
struct FaultActions {
  /// A module re-initialised from the vehicle: its sensor-error estimates set back to
  /// `errors` first when `revert_errors` (those learnt while a fault went undetected), then
  /// levelled by the specific force `f_now` and placed at `fix`.
  struct Restart {
    int module = -1;
    bool revert_errors = false;
    ImuErrors errors;
    Vec3 f_now = Vec3::Zero();
    VehicleFix fix;
  };
  std::optional<Restart> restart;
  /// The output fusion's heading offset of these modules is not to be trusted (it was tracked
  /// while a fault went undetected).
  std::array<bool, kMaxModules> forget_heading_offset{};
  bool any() const {
    if (restart) return true;
    for (bool f : forget_heading_offset)
      if (f) return true;
    return false;
  }
};

class FaultHandler {
 public:
  virtual ~FaultHandler() = default;
  FaultHandler(const FaultHandler&) = delete;
  FaultHandler& operator=(const FaultHandler&) = delete;

  bool in_use(int i) const { return monitor_.flowing(i); }
  bool counted(int i) const { return monitor_.counts(i); }
  bool tied(int i) const { return monitor_.tied(i); }
  /// Health, counters and the report of detected faults.
  const FaultMonitor& monitor() const { return monitor_; }
  /// What the hooks since the last call decided be done (then cleared).
  FaultActions take_actions() {
    FaultActions a = actions_;
    actions_ = FaultActions{};
    return a;
  }
  bool actions_pending() const { return actions_.any(); }

  /// Navigation starts at t0 (every subsystem aligned).
  virtual void on_start(double /*t0*/) {}
  /// Sample `raw` of module i, `b` the same in its b-frame (may be edited). False: the
  /// sample is not navigated.
  virtual bool on_sample(int /*i*/, const ImuSample& /*raw*/, ImuSample& /*b*/) { return true; }
  /// A velocity-update step begins at time t.
  virtual void on_velocity_step(double /*t*/) {}
  /// The wheel speeds of the step at time t: `sel.speed_ok` holds the wheels in use; the
  /// handler clears the unusable ones and marks those usable only as a lower bound
  /// (`sel.fallback`). `wheel`: each wheel's velocity input with its own speed.
  virtual void screen_speeds(double /*t*/,
                             const std::array<WheelVelocityInput, kMaxModules>& /*wheel*/,
                             SpeedSelection& /*sel*/) {}
  /// Module i's velocity update at time t was fused (or refused: rep.accepted false).
  virtual void on_velocity_update(int i, const UpdateReport& rep, double /*t*/) {
    if (!rep.accepted) ++monitor_.stats(i).velocity_rejected;
  }
  /// A position-constraint step begins at time t.
  virtual void on_position_step(double /*t*/) {}
  /// The data end at time t: the statistics closed, and the evidence against a wheel's
  /// geometry (below) reported as warnings.
  virtual void finish(double t);

  /// Evidence against the manifest's wheel geometry, gathered with or without fault handling
  /// (for a run whose data checks were off, or a lone wheel nothing can be compared with):
  /// Wheel-IMU i's navigated sample (b-frame): its rotation about the axle against all of it.
  void tally_rotation(int i, const ImuSample& b) {
    Evidence& e = evidence_[static_cast<std::size_t>(i)];
    e.about_axle += std::abs(b.dtheta.x());
    e.rotation += b.dtheta.norm();
  }
  /// Wheel i's own signed speed at a velocity-update step, held for dt: the distance it rolled
  /// forward and backward.
  void tally_speed(int i, double speed, double dt) {
    Evidence& e = evidence_[static_cast<std::size_t>(i)];
    (speed >= 0.0 ? e.forward : e.backward) += std::abs(speed) * dt;
  }
  /// The evidence is reported from this much rotation [rad] / distance [m] on.
  static constexpr double kEvidenceRotation = 60.0, kEvidenceDistance = 20.0;
  /// ... when the axle's share of the rotation is below this, or the backward share of the
  /// distance above this.
  static constexpr double kMinAxleShare = 0.5, kMaxBackwardShare = 0.7;

 protected:
  explicit FaultHandler(FaultMonitor monitor)
      : monitor_(std::move(monitor)), evidence_(static_cast<std::size_t>(monitor_.size())) {}
  FaultMonitor monitor_;
  FaultActions actions_;  ///< decided, not yet taken

 private:
  struct Evidence {
    double about_axle = 0.0, rotation = 0.0;  ///< [rad]
    double forward = 0.0, backward = 0.0;     ///< [m]
  };
  std::vector<Evidence> evidence_;
};

/// Fault handling off: every sample and module is used as it comes.
class NoFaultHandling final : public FaultHandler {
 public:
  NoFaultHandling(std::vector<std::string> module_names, const FaultOptions& options)
      : FaultHandler(FaultMonitor(std::move(module_names), options)) {}
};

/// The fault policy of docs/faults.md.
class FaultPolicy final : public FaultHandler {
 public:
  /// `subs`, `filter` and `output` are the navigator's (read, never changed: the policy's
  /// decisions are its FaultActions); they must outlive the policy.
  FaultPolicy(const FaultOptions& options, const Subsystems& subs, const FilterBackend& filter,
              const OutputFusion& output);

  void on_start(double t0) override;
  bool on_sample(int i, const ImuSample& raw, ImuSample& b) override;
  void on_velocity_step(double t) override;
  void screen_speeds(double t, const std::array<WheelVelocityInput, kMaxModules>& wheel,
                     SpeedSelection& sel) override;
  void on_velocity_update(int i, const UpdateReport& rep, double t) override;
  void on_position_step(double t) override;

  static constexpr double kSnapshotInterval = 10.0;  ///< [s]
  static constexpr double kSaturationFree = 1.0;     ///< [s] unsaturated before lending its speed

 private:
  struct Runtime {
    double last_t = 0.0;             ///< newest sample seen
    MotionAccumulator realign;       ///< while kRealign
    double saturated_until = -1e300; ///< the gyro was at full scale until this time + hold
    bool saturation_reported = false;
    bool speed_rejected = false;     ///< in a streak of rejected wheel speeds
    bool detector_fired = false;     ///< reported once for a lone module
    int heading_fails = 0;           ///< consecutive constraint epochs off the others' heading
    ImuErrors errors_new, errors_old;  ///< sensor-error estimates 0-10 s and 10-20 s ago
    double snapshot_t = -1e300;
    bool have_snapshot = false;
    bool revert_errors = false;      ///< restart from errors_old (after an isolation)
    double reverse_time = 0.0;       ///< [s] rolling against the vehicle's motion, in a row
    bool reversed = false;           ///< isolated for rolling against it: not retried
  };
  void watch_outages(int index, double t);
  void handle_saturation(int index, const ImuSample& raw, ImuSample& b);
  bool substitute_speed(int wheel_index, double* speed) const;
  void check_wheel_speeds(double t, const std::array<WheelVelocityInput, kMaxModules>& own,
                          std::array<bool, kMaxModules>& speed_ok);
  /// A wheel rolling against the vehicle's motion (a reversed axle_sign): isolated for the run.
  void check_directions(double t, const std::array<WheelVelocityInput, kMaxModules>& own,
                        std::array<bool, kMaxModules>& speed_ok);
  /// Wheel j's forward speed moved to wheel i's place with the yaw rate (v-frame y to the
  /// right): v_i = v_j - yaw_rate (y_i - y_j); a steered wheel's along itself times cos(steering).
  double speed_at(int i, int j, const std::array<WheelVelocityInput, kMaxModules>& own, double yaw_rate) const;
  void isolate(int i, double t, const std::string& what);
  void begin_realign(int i, double t, const std::string& what, const std::string& action);
  /// Where module i restarts at time t: the others' fused solution (or its own, alone).
  VehicleFix vehicle_fix(int i, double t) const;
  /// Module i restarts at time t (decided: actions_.restart; the health state changes now).
  void restart(int i, double t);

  FaultOptions opt_;
  const Subsystems& subs_;
  const FilterBackend& filter_;
  const OutputFusion& output_;
  std::vector<Runtime> rt_;
  bool degraded_ = false;  ///< every wheel saturated or recovering: nobody is blamed
  double direction_t_ = -1e300;  ///< the last direction check
  std::array<bool, kMaxModules> excused_{};  ///< saturated or recovering this step
};

/// FaultPolicy when options.enabled, else NoFaultHandling.
std::unique_ptr<FaultHandler> make_fault_handler(const FaultOptions& options, const Subsystems& subs,
                                                 const FilterBackend& filter, const OutputFusion& output);

}  // namespace wheelins
