// The two filter structures behind one interface: who owns the error covariances,
// when their time update runs, and how a Measurement (measurement.hpp) is fused.
//  - The distributed filter (the paper's, Section III): every subsystem keeps its own
//    21-state EKF; a measurement's own block H_own updates that subsystem alone.
//  - The centralized filter (Section VI-B-2, centralized.hpp): one joint covariance over
//    the stacked error states of all IMUs; every block of H enters one update, whose error
//    estimate is fed back into every subsystem.
// Both fuse through the one EKF update of filter/ekf_update.hpp.
#pragma once

#include <memory>

#include "wheelins/fusion/measurement.hpp"

namespace wheelins {

class FilterBackend {
 public:
  virtual ~FilterBackend() = default;
  /// The centralized filter: its sequential updates each see the state the previous one
  /// left (a joint correction moves every IMU's errors), so the shared quantities are taken
  /// again before every update; and it counts the point offset of a mean wheel speed as noise
  /// (velocity_measurement()).
  virtual bool joint() const = 0;
  /// Every subsystem is initialised: the covariances start from theirs.
  virtual void start() = 0;
  /// Subsystem i's nominal state advanced one epoch: its covariance time update when due
  /// (StrapdownEkf::covariance_due), the one place the navigator's time updates happen.
  virtual void propagated(int i) = 0;
  /// Every covariance brought to the current epoch (before a measurement uses it).
  virtual void flush() = 0;
  /// Subsystem i's covariance (its block of a joint covariance, copied into `scratch`), as of
  /// its last time update.
  virtual const Mat21& covariance(int i, Mat21& scratch) const = 0;
  /// Subsystem i's covariance to report (the output's sigmas): with the consider terms of
  /// its held states (StrapdownEkf::reported_covariance), at its last time update.
  virtual const Mat21& reported_covariance(int i) const = 0;
  /// Fuses `m` and feeds the error estimate back into the subsystem(s).
  virtual UpdateReport fuse(const Measurement& m) = 0;
  /// Subsystem i was re-initialised: its covariance is its own new one, uncorrelated.
  virtual void restarted(int i) = 0;
};

/// The distributed filter, or the centralized one over `subs` (more than one subsystem;
/// with one the two are the same filter and the distributed one is made).
std::unique_ptr<FilterBackend> make_filter_backend(Subsystems& subs, bool centralized);

}  // namespace wheelins
