// The error-state dynamics of eq. (2) (error_model.hpp): F and its blocks, the discrete
// process noise, and the covariance time update, dense and block-sparse.
#include "wheelins/filter/error_model.hpp"

namespace wheelins {

Mat21 error_dynamics(const Mat3& C, const Vec3& omega_b, const Vec3& f_b, const Vec3& omega_ie,
                     const ProcessNoise& q) {
  Mat21 F = Mat21::Zero();
  const Mat3 I = Mat3::Identity();
  F.block<3, 3>(P, V) = I;
  F.block<3, 3>(V, V) = -2.0 * skew(omega_ie);
  F.block<3, 3>(V, PHI) = skew(C * f_b);
  F.block<3, 3>(V, BA) = C;
  F.block<3, 3>(V, SA) = C * f_b.asDiagonal();
  F.block<3, 3>(PHI, PHI) = -skew(omega_ie);
  F.block<3, 3>(PHI, BG) = -C;
  F.block<3, 3>(PHI, SG) = -C * omega_b.asDiagonal();
  F.block<3, 3>(BG, BG) = -I / q.gyro_bias_tau;
  F.block<3, 3>(BA, BA) = -I / q.acc_bias_tau;
  F.block<3, 3>(SG, SG) = -I / q.gyro_sf_tau;
  F.block<3, 3>(SA, SA) = -I / q.acc_sf_tau;
  return F;
}

namespace {
Vec21 noise_density(const ProcessNoise& q) {
  Vec21 qc = Vec21::Zero();
  qc.segment<3>(V).setConstant(q.acc_vrw * q.acc_vrw);
  qc.segment<3>(PHI).setConstant(q.gyro_arw * q.gyro_arw);
  // First-order Gauss-Markov driving noise: 2 sigma^2 / tau.
  qc.segment<3>(BG).setConstant(2.0 * q.gyro_bias_std * q.gyro_bias_std / q.gyro_bias_tau);
  qc.segment<3>(BA).setConstant(2.0 * q.acc_bias_std * q.acc_bias_std / q.acc_bias_tau);
  qc.segment<3>(SG).setConstant(2.0 * q.gyro_sf_std * q.gyro_sf_std / q.gyro_sf_tau);
  qc.segment<3>(SA).setConstant(2.0 * q.acc_sf_std * q.acc_sf_std / q.acc_sf_tau);
  return qc.cwiseProduct(q.estimated);
}
}  // namespace

ErrorDynamics error_dynamics_blocks(const Mat3& C, const Vec3& omega_b, const Vec3& f_b,
                                    const Vec3& omega_ie, const ProcessNoise& q) {
  ErrorDynamics d;
  d.W = skew(omega_ie);
  d.Ff = skew(C * f_b);
  d.C = C;
  d.Cf = C * f_b.asDiagonal();
  d.Cw = C * omega_b.asDiagonal();
  d.decay_bg = 1.0 / q.gyro_bias_tau;
  d.decay_ba = 1.0 / q.acc_bias_tau;
  d.decay_sg = 1.0 / q.gyro_sf_tau;
  d.decay_sa = 1.0 / q.acc_sf_tau;
  return d;
}

Vec21 discrete_noise_diagonal(const ProcessNoise& q, double dt) { return noise_density(q) * dt; }

void propagate_covariance(Mat21& P, const ErrorDynamics& d, const ProcessNoise& q, double dt) {
  // Phi P Phi^T = (Phi (Phi P)^T)^T: two left-applications of the block-sparse Phi.
  apply_transition<kStateDim>(d, dt, P);
  P.transposeInPlace();
  apply_transition<kStateDim>(d, dt, P);
  P.diagonal() += discrete_noise_diagonal(q, dt);
  P = 0.5 * (P + P.transpose()).eval();
}

Mat21 transition_matrix(const Mat21& F, double dt) {
  const Mat21 Fdt = F * dt;
  Mat21 Phi = Fdt + 0.5 * Fdt * Fdt;
  Phi.diagonal().array() += 1.0;
  return Phi;
}

Mat21 discrete_noise(const Mat21& Phi, const ProcessNoise& q, double dt) {
  const Vec21 qc = noise_density(q);
  Mat21 Qd = 0.5 * dt * (Phi * qc.asDiagonal() * Phi.transpose());
  Qd.diagonal() += 0.5 * dt * qc;
  return Qd;
}

void propagate_covariance(Mat21& P, const Mat21& F, const ProcessNoise& q, double dt) {
  const Mat21 Phi = transition_matrix(F, dt);
  P = Phi * P * Phi.transpose() + discrete_noise(Phi, q, dt);
  condition_covariance(P);
}

void condition_covariance(Mat21& P) {
  P = 0.5 * (P + P.transpose()).eval();
  for (int i = 0; i < kStateDim; ++i)
    if (P(i, i) < 0.0) P(i, i) = 0.0;
}

}  // namespace wheelins
