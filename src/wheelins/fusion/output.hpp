// The output of the fusion (paper Section III): each subsystem's own solution for the
// vehicle reference point o with its 1-sigma figures, and the vehicle solution, the
// weighted mean of the subsystems that count (eq. 8) with the mean heading; and the
// records of one output epoch sent to the sink (stream 0 the vehicle, 1..N the
// subsystems).
#pragma once

#include <array>
#include <functional>

#include "wheelins/fusion/filter_backend.hpp"
#include "wheelins/nav/trajectory_record.hpp"

namespace wheelins {

class OutputFusion {
 public:
  /// Receives records: stream 0 is the vehicle (the fused solution), streams 1..N the
  /// subsystems' own solutions (only when N > 1).
  using Sink = std::function<void(int stream, const TrajectoryRecord&)>;
  using Use = std::array<bool, kMaxModules>;

  OutputFusion(const Subsystems& subs, const FilterBackend& filter, const earth::LocalFrame& frame,
               const NavigatorOptions& options, Sink sink);

  /// Subsystem i's own solution; without lat/lon/h (left NaN) when with_lla is false.
  TrajectoryRecord record(int i, bool with_lla = true) const;
  /// The weighted mean of the subsystems in `use` (the vehicle solution when `use` holds the
  /// modules that count). Its heading, when `use` lacks modules, is the mean heading of all
  /// of them as estimated from each one's offset (heading_offset()): continuous through an
  /// outage.
  TrajectoryRecord fused(const Use& use) const;
  /// Subsystem i's heading less the weighted mean heading of all subsystems, averaged over
  /// the last FusionOptions::heading_offset_window seconds in which all of them counted (frozen while not); false
  /// before it has been seen. A module that comes back after an outage restarts from the
  /// others' heading plus its offset (fault_handler.cpp).
  bool heading_offset(int i, double& offset) const;
  /// Subsystem i's offset is not known (it was isolated: a fault may have moved its heading
  /// before it was detected) until all subsystems count again.
  void forget_heading_offset(int i) { offset_valid_[i] = false; }
  /// One output epoch at time t: the vehicle record (the mean over `vehicle`) and, of a
  /// multi-IMU run with module records, each subsystem's in `in_use` that has new data.
  void write(double t, const Use& vehicle, const Use& in_use);

 private:
  using Records = std::array<TrajectoryRecord, kMaxModules>;
  /// recs[i] for every i in `use`, the first of `use`, and every i in `also` (may be null);
  /// geodetic coordinates only for a single subsystem (fuse() makes the fused one's).
  void collect(const Use& use, const Use* also, Records& recs) const;
  /// The mean from records already made (recs[i] valid where use[i], and recs[first]).
  TrajectoryRecord fuse(const Use& use, const Records& recs) const;
  /// With every subsystem that makes the vehicle in `vehicle` (the steered wheels that follow
  /// not), their offsets move toward their headings' at time t.
  void track_offsets(double t, const Use& vehicle, const Records& recs);

  const Subsystems& subs_;
  const FilterBackend& filter_;
  const earth::LocalFrame& frame_;
  bool share_level_, module_records_;
  double offset_window_;  ///< [s], e-folding
  Sink sink_;
  Records recs_{};                              ///< scratch of write() (no allocation per epoch)
  std::array<double, kMaxModules> last_record_t_;  ///< time of each subsystem's last record
  std::array<double, kMaxModules> offset_{};       ///< heading_offset() [rad]
  std::array<bool, kMaxModules> offset_valid_{};
  double offset_t_ = 0.0;                          ///< time of the last tracking step
};

}  // namespace wheelins
