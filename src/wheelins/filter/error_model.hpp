// Time update of the error-state covariance (paper eq. 2, the phi-angle model,
// plus the earth-rate terms when the w-frame rotates).
#pragma once

#include "wheelins/filter/error_state.hpp"
#include "wheelins/nav/vehicle.hpp"

namespace wheelins {

/// The noise model of the error states: the module's figures (ImuNoise, SI: white noise
/// densities ARW and VRW, first-order Gauss-Markov sigmas and correlation times), and which
/// states the filter estimates. A state that is not estimated (estimated(k) == 0) is held at
/// its estimate: no process noise and no initial uncertainty, so its row and column of P stay
/// zero through every time update (Phi's row of a Gauss-Markov state is its decay alone) and
/// every measurement update (its gain row is zero). docs/filter.md section 13.4.
struct ProcessNoise : ImuNoise {
  ProcessNoise() = default;
  ProcessNoise(const ImuNoise& n) : ImuNoise(n) {}  // NOLINT(google-explicit-constructor)
  Vec21 estimated = Vec21::Ones();
  /// The estimated states a velocity update may correct: 0 makes a state a Schmidt
  /// "consider" state of the velocity updates (its gain row zero, its covariance kept and
  /// used), so that only the position constraint moves it (YawScaleFactors::kFromConstraint).
  Vec21 velocity_gain = Vec21::Ones();
  bool velocity_consider() const { return velocity_gain.minCoeff() == 0.0; }
  bool held(int k) const { return estimated(k) == 0.0; }
};

/// P for a positive-definiteness test: the rows and columns of the held states (zero by
/// construction) replaced by those of the identity.
inline Mat21 estimated_block(const Mat21& P, const ProcessNoise& q) {
  Mat21 out = P;
  for (int k = 0; k < kStateDim; ++k)
    if (q.held(k)) {
      out.row(k).setZero();
      out.col(k).setZero();
      out(k, k) = 1.0;
    }
  return out;
}

/// The continuous-time error dynamics F of eq. (2):
///   d(dr)  = dv
///   d(dv)  = [f^w x] phi + C (b_a + diag(f) s_a) - 2 [w_ie x] dv
///   d(phi) = -[w_ie x] phi - C (b_g + diag(w) s_g)
///   d(b)   = -b / tau   (each of b_g, b_a, s_g, s_a)
/// C = C_b^w; omega_b and f_b are the compensated rate and specific force.
Mat21 error_dynamics(const Mat3& C_BtoW, const Vec3& omega_b, const Vec3& f_b,
                     const Vec3& omega_ie_inW, const ProcessNoise& q);

/// The non-zero blocks of F (eq. 2) for one epoch (or their mean over several); Phi is
/// applied through them (apply_transition), never as a dense 21 x 21 product.
struct ErrorDynamics {
  Mat3 W = Mat3::Zero();   ///< [w_ie x]
  Mat3 Ff = Mat3::Zero();  ///< [f^w x]
  Mat3 C = Mat3::Zero();   ///< C_b^w
  Mat3 Cf = Mat3::Zero();  ///< C diag(f)
  Mat3 Cw = Mat3::Zero();  ///< C diag(omega)
  double decay_bg = 0, decay_ba = 0, decay_sg = 0, decay_sa = 0;  ///< 1 / tau
};
ErrorDynamics error_dynamics_blocks(const Mat3& C_BtoW, const Vec3& omega_b, const Vec3& f_b,
                                    const Vec3& omega_ie_inW, const ProcessNoise& q);

/// F M for a 21 x K block of rows, using only F's non-zero blocks (eq. 2).
template <int K>
Eigen::Matrix<double, kStateDim, K> apply_dynamics(const ErrorDynamics& d,
                                                   const Eigen::Matrix<double, kStateDim, K>& M) {
  Eigen::Matrix<double, kStateDim, K> FM;
  FM.template middleRows<3>(P) = M.template middleRows<3>(V);
  FM.template middleRows<3>(V) =
      -2.0 * d.W * M.template middleRows<3>(V) + d.Ff * M.template middleRows<3>(PHI) +
      d.C * M.template middleRows<3>(BA) + d.Cf * M.template middleRows<3>(SA);
  FM.template middleRows<3>(PHI) = -d.W * M.template middleRows<3>(PHI) -
                                   d.C * M.template middleRows<3>(BG) -
                                   d.Cw * M.template middleRows<3>(SG);
  FM.template middleRows<3>(BG) = -d.decay_bg * M.template middleRows<3>(BG);
  FM.template middleRows<3>(BA) = -d.decay_ba * M.template middleRows<3>(BA);
  FM.template middleRows<3>(SG) = -d.decay_sg * M.template middleRows<3>(SG);
  FM.template middleRows<3>(SA) = -d.decay_sa * M.template middleRows<3>(SA);
  return FM;
}

/// M <- Phi M for a 21 x K block of rows, Phi = I + F dt + (F dt)^2 / 2: the transition
/// of eq. (2), exact to second order in dt for a constant F. One step may span several IMU
/// epochs (the lower-rate covariance update, StrapdownEkf::set_covariance_interval) with F
/// the mean over them; F then varies (a spinning wheel's C), so the step is exact to first
/// order and its second-order term drops the commutators of F over the interval
/// (FilterCovariance.LowerRateTimeUpdateFollowsThePerEpochOne bounds the effect). Only F's
/// non-zero blocks are used.
template <int K>
void apply_transition(const ErrorDynamics& d, double dt, Eigen::Matrix<double, kStateDim, K>& M) {
  const Eigen::Matrix<double, kStateDim, K> FM = apply_dynamics<K>(d, M);
  M += dt * FM + (0.5 * dt * dt) * apply_dynamics<K>(d, FM);
}

/// The discrete process noise Qd = Qc dt (diagonal). The trapezoidal rule's cross terms,
/// of relative size |F| dt / 2, are left out; over the default 0.05 s covariance interval
/// this changed no printed digit of the experiment's tables (BENCHMARKS.md, accuracy).
Vec21 discrete_noise_diagonal(const ProcessNoise& q, double dt);

/// Phi = I + F dt + (F dt)^2 / 2 (as apply_transition).
Mat21 transition_matrix(const Mat21& F, double dt);
/// The trapezoidal Qd = (Phi Qc Phi^T + Qc) dt / 2.
Mat21 discrete_noise(const Mat21& Phi, const ProcessNoise& q, double dt);

/// P <- Phi P Phi^T + Qd over dt, with Phi of transition_matrix and the trapezoidal
/// Qd = (Phi Qc Phi^T + Qc) dt / 2, Qc the diagonal noise density (the noise
/// enters through C, which is orthogonal, so C Qc C^T = Qc for isotropic sensors).
void propagate_covariance(Mat21& P, const Mat21& F, const ProcessNoise& q, double dt);

/// The same through the block structure: P <- Phi P Phi^T + Qd with Qd = Qc dt and Phi
/// to second order (apply_transition). Several times fewer operations than the dense
/// form; equal to it to O(dt^2).
void propagate_covariance(Mat21& P, const ErrorDynamics& d, const ProcessNoise& q, double dt);

/// Keeps P symmetric (after every step) and its diagonal non-negative.
void condition_covariance(Mat21& P);

}  // namespace wheelins
