// The centralized filter (paper Section VI-B-2): one EKF whose error state stacks
// the 21 states of all N IMUs, so the cross-correlations the distributed filter
// ignores are carried by the joint covariance. The nominal states stay in the
// subsystems; JointCovariance holds the (21N x 21N) covariance, fixed-size
// (N = 2..5), and applies the same process and measurement models; CentralizedFilter
// is the fusion's back-end over it (filter_backend.hpp).
#pragma once

#include <array>
#include <memory>

#include "wheelins/filter/ekf_update.hpp"
#include "wheelins/filter/error_model.hpp"
#include "wheelins/filter/strapdown_ekf.hpp"
#include "wheelins/fusion/filter_backend.hpp"

namespace wheelins {

constexpr int kMaxCentralized = 5;

class JointCovariance {
 public:
  virtual ~JointCovariance() = default;
  virtual int size() const = 0;
  /// Block-diagonal start from the subsystems' own initial covariances.
  virtual void set_block(int i, const Mat21& P) = 0;
  virtual Mat21 block(int i) const = 0;
  /// Subsystem i restarted with covariance P: its cross-covariances with the others are 0.
  virtual void reset(int i, const Mat21& P) = 0;
  /// Subsystem i's held states (StrapdownEkf::held_states): their sensitivities start as the
  /// subsystem's (its rows only) and their prior variances are taken (consider analysis).
  virtual void set_consider(int i, const StrapdownEkf& ekf) = 0;
  /// Block i with the held states' consider terms: P_ii + S_i V S_i^T (cached between the
  /// time and measurement updates that change it).
  virtual const Mat21& reported_block(int i) const = 0;
  /// Subsystem i advanced by one epoch (F_i over dt); the others did not move.
  virtual void propagate(int i, const ErrorDynamics& d, const ProcessNoise& q, double dt) = 0;
  /// Conditions P on a known linear combination c = sum_j h_j dx_j (no change to the
  /// estimate): P <- P - P h^T (h P h^T + r)^-1 h P with r = (1e-5)^2, leaving c a variance
  /// of about r (10 ppm for a scale factor); nothing if h P h^T is already below r.
  virtual void condition(const std::array<Eigen::Matrix<double, 1, kStateDim>, kMaxCentralized>& h) = 0;
  /// Fuses dz = sum_j H_j dx_j + e (H[j] == nullptr: no dependence on subsystem j),
  /// writing each subsystem's error estimate into dx[j]. With `gain_mask`, subsystem j's
  /// states whose (*gain_mask)[j] entry is 0 are consider states of this update.
  virtual UpdateReport update(const std::array<const H3*, kMaxCentralized>& H, const Vec3& dz,
                              const Mat3& R, double gate, std::array<Vec21, kMaxCentralized>& dx,
                              const std::array<const Vec21*, kMaxCentralized>* gain_mask) = 0;
};

/// The weights of a mean of n quantities of variances var[j] with the least variance:
/// 1 / var[j], normalised to a sum of 1 (a quantity with no positive variance gets 0; all zero
/// if none has one). The common yaw-rate scale factor of the centralized filter (docs/filter.md
/// 13.4).
std::array<double, kMaxCentralized> inverse_variance_weights(const std::array<double, kMaxCentralized>& var, int n);

/// A joint covariance for n subsystems (2 <= n <= kMaxCentralized); InputError otherwise.
std::unique_ptr<JointCovariance> make_joint_covariance(int n);

/// The back-end: the subsystems' time updates go into the joint covariance, and every
/// measurement is fused with all its blocks.
class CentralizedFilter final : public FilterBackend {
 public:
  /// InputError unless 2 <= subs.size() <= kMaxCentralized.
  explicit CentralizedFilter(Subsystems& subs);
  bool joint() const override { return true; }
  void start() override;
  void propagated(int i) override;
  void flush() override;
  const Mat21& covariance(int i, Mat21& scratch) const override;
  const Mat21& reported_covariance(int i) const override { return joint_->reported_block(i); }
  UpdateReport fuse(const Measurement& m) override;
  void restarted(int i) override;

 private:
  /// Moves subsystem i's accumulated dynamics into the joint covariance.
  void propagate_joint(int i);
  /// Conditions the joint covariance on the weighted mean of the yaw-rate scale factors
  /// that are estimated from the constraint (none: nothing done).
  void hold_common_yaw_scale_factor();
  Subsystems& subs_;
  std::unique_ptr<JointCovariance> joint_;
  /// That mean, set at start() from the subsystems' prior covariances (docs/filter.md 13.4).
  std::array<Eigen::Matrix<double, 1, kStateDim>, kMaxCentralized> common_yaw_{};
  bool holds_common_yaw_ = false;
};

}  // namespace wheelins
