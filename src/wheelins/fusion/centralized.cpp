// The centralized filter of centralized.hpp: the fixed-size joint covariance for 2..5
// IMUs (block time update, the update through ekf_update) and its back-end.
#include "wheelins/fusion/centralized.hpp"

#include <array>
#include <string>

#include "wheelins/nav/types.hpp"

namespace wheelins {
namespace {

template <int N>
class FixedJointCovariance final : public JointCovariance {
  static constexpr int D = kStateDim * N;
  static constexpr int C = StrapdownEkf::kMaxHeld * N;  ///< consider columns
  using MatD = Eigen::Matrix<double, D, D>;
  using H3D = Eigen::Matrix<double, 3, D>;

 public:
  FixedJointCovariance() {
    P_.setZero();
    S_.setZero();
    var_.setZero();
    dirty_.fill(true);
  }
  int size() const override { return N; }

  void set_block(int i, const Mat21& P) override {
    P_.template block<kStateDim, kStateDim>(kStateDim * i, kStateDim * i) = P;
    dirty_.fill(true);
  }
  void reset(int i, const Mat21& P) override {
    P_.template middleRows<kStateDim>(kStateDim * i).setZero();
    P_.template middleCols<kStateDim>(kStateDim * i).setZero();
    set_block(i, P);
  }
  void set_consider(int i, const StrapdownEkf& ekf) override {
    constexpr int H = StrapdownEkf::kMaxHeld;
    S_.template middleRows<kStateDim>(kStateDim * i).setZero();
    S_.template middleCols<H>(H * i).setZero();
    S_.template block<kStateDim, H>(kStateDim * i, H * i) = ekf.held_sensitivity();
    var_.template segment<H>(H * i) = ekf.held_variance();
    dirty_.fill(true);
  }
  const Mat21& reported_block(int i) const override {
    if (dirty_[i]) {
      const auto Si = S_.template middleRows<kStateDim>(kStateDim * i);
      const Eigen::Matrix<double, kStateDim, C> SV = Si * var_.asDiagonal();
      Mat21 out = block(i) + SV.lazyProduct(Si.transpose());
      reported_[i] = 0.5 * (out + out.transpose());
      dirty_[i] = false;
    }
    return reported_[i];
  }
  Mat21 block(int i) const override {
    return P_.template block<kStateDim, kStateDim>(kStateDim * i, kStateDim * i);
  }

  void propagate(int i, const ErrorDynamics& d, const ProcessNoise& q, double dt) override {
    // Phi_big = diag(I, .., Phi_i, .., I): row block i <- Phi_i * row block i, then
    // column block i <- column block i * Phi_i^T, plus Qd_i on the diagonal block.
    const int o = kStateDim * i;
    Eigen::Matrix<double, kStateDim, D> rows = P_.template middleRows<kStateDim>(o);
    apply_transition<D>(d, dt, rows);
    P_.template middleRows<kStateDim>(o) = rows;
    rows = P_.template middleCols<kStateDim>(o).transpose();
    apply_transition<D>(d, dt, rows);
    P_.template middleCols<kStateDim>(o) = rows.transpose();
    // The held states' sensitivities of this IMU move with its Phi (consider analysis).
    Eigen::Matrix<double, kStateDim, C> srows = S_.template middleRows<kStateDim>(o);
    apply_transition<C>(d, dt, srows);
    S_.template middleRows<kStateDim>(o) = srows;
    dirty_[i] = true;
    auto Pii = P_.template block<kStateDim, kStateDim>(o, o);
    Pii.diagonal() += discrete_noise_diagonal(q, dt);
    const Mat21 sym = 0.5 * (Mat21(Pii) + Mat21(Pii).transpose());
    Pii = sym;
  }

  void condition(const std::array<Eigen::Matrix<double, 1, kStateDim>, kMaxCentralized>& h) override {
    Eigen::Matrix<double, 1, D> hb;
    for (int j = 0; j < N; ++j) hb.template segment<kStateDim>(kStateDim * j) = h[j];
    const Eigen::Matrix<double, D, 1> Ph = P_.lazyProduct(hb.transpose());
    const double s = hb.dot(Ph);
    constexpr double r = 1e-10;  // (10 ppm)^2: what is left of the combination's variance
    if (!(s > r)) return;
    P_ -= Ph.lazyProduct(Ph.transpose()) / (s + r);
    P_ = 0.5 * (P_ + P_.transpose()).eval();
    dirty_.fill(true);
  }

  UpdateReport update(const std::array<const H3*, kMaxCentralized>& H, const Vec3& dz,
                      const Mat3& R, double gate, std::array<Vec21, kMaxCentralized>& dx,
                      const std::array<const Vec21*, kMaxCentralized>* gain_mask) override {
    H3D Hb = H3D::Zero();
    for (int j = 0; j < N; ++j)
      if (H[j]) Hb.template middleCols<kStateDim>(kStateDim * j) = *H[j];
    Eigen::Matrix<double, D, 1> mask;
    if (gain_mask)
      for (int j = 0; j < N; ++j) mask.template segment<kStateDim>(kStateDim * j) = *(*gain_mask)[j];
    // The one EKF update (filter/ekf_update.hpp) over the stacked error state; the error
    // estimate starts at zero (every subsystem is fed back after each update).
    Eigen::Matrix<double, D, 1> dxb = Eigen::Matrix<double, D, 1>::Zero();
    Eigen::Matrix<double, D, 3> K;
    const UpdateReport rep = ekf_update<3, D>(P_, dxb, Hb, dz, R, gate, &K, gain_mask ? &mask : nullptr);
    if (rep.accepted) {
      S_ -= K * (Hb * S_);
      dirty_.fill(true);
    }
    for (int j = 0; j < N; ++j) dx[j] = dxb.template segment<kStateDim>(kStateDim * j);
    return rep;
  }

 private:
  MatD P_;
  Eigen::Matrix<double, D, C> S_;    ///< held states' sensitivities (consider analysis)
  Eigen::Matrix<double, C, 1> var_;  ///< their prior variances
  mutable std::array<Mat21, N> reported_;
  mutable std::array<bool, N> dirty_{};
};

}  // namespace

std::unique_ptr<JointCovariance> make_joint_covariance(int n) {
  switch (n) {
    case 2: return std::make_unique<FixedJointCovariance<2>>();
    case 3: return std::make_unique<FixedJointCovariance<3>>();
    case 4: return std::make_unique<FixedJointCovariance<4>>();
    case 5: return std::make_unique<FixedJointCovariance<5>>();
    default:
      throw InputError("the centralized filter takes 2 to " + std::to_string(kMaxCentralized) +
                       " IMUs, " + std::to_string(n) + " were selected");
  }
}

CentralizedFilter::CentralizedFilter(Subsystems& subs)
    : subs_(subs), joint_(make_joint_covariance(subs.size())) {}

void CentralizedFilter::start() {
  for (int i = 0; i < subs_.size(); ++i) {
    joint_->set_block(i, subs_[i].ekf().covariance());
    joint_->set_consider(i, subs_[i].ekf());
  }
  // The common yaw-rate scale factor that the velocity updates hold (docs/filter.md 13.4):
  // the mean over the subsystems of each one's yaw-rate scale factor (the mean of its states
  // estimated from the constraint), weighted by the inverse of its prior variance. Nothing
  // observes it, so every heading ends up turning with its true value: of all weighted means,
  // this one has the least variance (a Wheel-IMU's, the mean of two axes, half a Body-IMU's
  // single axis with equal figures).
  std::array<double, kMaxCentralized> var{};
  for (int j = 0; j < subs_.size(); ++j) {
    const Subsystem& s = subs_[j];
    if (s.yaw_scale_factor_mode() == YawScaleFactors::kFromConstraint)
      var[j] = s.yaw_scale_factor_variance(s.ekf().covariance());
  }
  const std::array<double, kMaxCentralized> w = inverse_variance_weights(var, subs_.size());
  holds_common_yaw_ = false;
  for (int j = 0; j < subs_.size(); ++j) {
    common_yaw_[j].setZero();
    const Subsystem& s = subs_[j];
    for (int k = 0; k < s.yaw_scale_factor_state_count() && w[j] > 0.0; ++k)
      common_yaw_[j](s.yaw_scale_factor_states()[k]) = w[j] / s.yaw_scale_factor_state_count();
    holds_common_yaw_ = holds_common_yaw_ || w[j] > 0.0;
  }
}

std::array<double, kMaxCentralized> inverse_variance_weights(const std::array<double, kMaxCentralized>& var, int n) {
  std::array<double, kMaxCentralized> w{};
  double total = 0.0;
  for (int j = 0; j < n; ++j)
    if (var[j] > 0.0) total += (w[j] = 1.0 / var[j]);
  if (total > 0.0)
    for (int j = 0; j < n; ++j) w[j] /= total;
  return w;
}

void CentralizedFilter::propagate_joint(int i) {
  StrapdownEkf& ekf = subs_[i].ekf();
  if (ekf.pending_dt() <= 0.0) return;
  joint_->propagate(i, ekf.pending_dynamics(), ekf.noise(), ekf.pending_dt());
  ekf.clear_pending();
}

void CentralizedFilter::propagated(int i) {
  if (subs_[i].ekf().covariance_due()) propagate_joint(i);
}

void CentralizedFilter::flush() {
  for (int i = 0; i < subs_.size(); ++i) propagate_joint(i);
}

const Mat21& CentralizedFilter::covariance(int i, Mat21& scratch) const {
  scratch = joint_->block(i);
  return scratch;
}

UpdateReport CentralizedFilter::fuse(const Measurement& m) {
  std::array<const H3*, kMaxCentralized> blocks{};
  for (int j = 0; j < m.n; ++j) blocks[j] = &m.H[j];
  std::array<Vec21, kMaxCentralized> dx;
  if (m.velocity) hold_common_yaw_scale_factor();
  // A velocity update leaves every subsystem's consider states (velocity_gain) alone.
  std::array<const Vec21*, kMaxCentralized> masks{};
  bool consider = false;
  for (int j = 0; j < subs_.size(); ++j) {
    masks[j] = &subs_[j].process_noise().velocity_gain;
    consider = consider || subs_[j].process_noise().velocity_consider();
  }
  const UpdateReport rep =
      joint_->update(blocks, m.dz, m.R, m.gate, dx, m.velocity && consider ? &masks : nullptr);
  if (rep.accepted)
    for (int j = 0; j < subs_.size(); ++j) subs_[j].ekf().feedback(dx[j]);
  return rep;
}

void CentralizedFilter::hold_common_yaw_scale_factor() {
  // The common yaw-rate scale factor of start(), what the vehicle heading's own scale factor
  // is: nothing observes it, and in the joint covariance its variance lets the velocity
  // updates of every stop and start turn all headings together (docs/filter.md 13.4).
  // Conditioned out before each velocity update (its Gauss-Markov driving noise brings a
  // little back in between); the differences between the subsystems stay.
  if (holds_common_yaw_) joint_->condition(common_yaw_);
}

void CentralizedFilter::restarted(int i) {
  joint_->reset(i, subs_[i].ekf().covariance());
  joint_->set_consider(i, subs_[i].ekf());
}

}  // namespace wheelins
