// The centralized filter of centralized.hpp: the fixed-size joint covariance for 2..5
// IMUs (block time update, the update through ekf_update) and its back-end.
#include "wheelins/fusion/centralized.hpp"

#include <string>

#include "wheelins/nav/types.hpp"

namespace wheelins {
namespace {

template <int N>
class FixedJointCovariance final : public JointCovariance {
  static constexpr int D = kStateDim * N;
  using MatD = Eigen::Matrix<double, D, D>;
  using H3D = Eigen::Matrix<double, 3, D>;

 public:
  FixedJointCovariance() { P_.setZero(); }
  int size() const override { return N; }

  void set_block(int i, const Mat21& P) override {
    P_.template block<kStateDim, kStateDim>(kStateDim * i, kStateDim * i) = P;
  }
  void reset(int i, const Mat21& P) override {
    P_.template middleRows<kStateDim>(kStateDim * i).setZero();
    P_.template middleCols<kStateDim>(kStateDim * i).setZero();
    set_block(i, P);
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
    auto Pii = P_.template block<kStateDim, kStateDim>(o, o);
    Pii.diagonal() += discrete_noise_diagonal(q, dt);
    const Mat21 sym = 0.5 * (Mat21(Pii) + Mat21(Pii).transpose());
    Pii = sym;
  }

  UpdateReport update(const std::array<const H3*, kMaxCentralized>& H, const Vec3& dz,
                      const Mat3& R, double gate,
                      std::array<Vec21, kMaxCentralized>& dx) override {
    H3D Hb = H3D::Zero();
    for (int j = 0; j < N; ++j)
      if (H[j]) Hb.template middleCols<kStateDim>(kStateDim * j) = *H[j];
    // The one EKF update (filter/ekf_update.hpp) over the stacked error state; the error
    // estimate starts at zero (every subsystem is fed back after each update).
    Eigen::Matrix<double, D, 1> dxb = Eigen::Matrix<double, D, 1>::Zero();
    const UpdateReport rep = ekf_update<3, D>(P_, dxb, Hb, dz, R, gate);
    for (int j = 0; j < N; ++j) dx[j] = dxb.template segment<kStateDim>(kStateDim * j);
    return rep;
  }

 private:
  MatD P_;
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
  for (int i = 0; i < subs_.size(); ++i) joint_->set_block(i, subs_[i].ekf().covariance());
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
  const UpdateReport rep = joint_->update(blocks, m.dz, m.R, m.gate, dx);
  if (rep.accepted)
    for (int j = 0; j < subs_.size(); ++j) subs_[j].ekf().feedback(dx[j]);
  return rep;
}

void CentralizedFilter::restarted(int i) { joint_->reset(i, subs_[i].ekf().covariance()); }

}  // namespace wheelins
