// The EKF measurement update shared by every measurement model, with a
// PX4-EKF2-style report of what each fusion did.
//
// Convention: the innovation is dz = z_hat - z_meas = H dx + e (dx = estimate - truth),
// the error estimate is dx = K dz, and the caller feeds dx back into its state.
#pragma once

#include <Eigen/Cholesky>
#include <array>

#include "wheelins/filter/error_state.hpp"

namespace wheelins {

/// Chi-square quantile at 99.9 % for 1..6 degrees of freedom (innovation gating).
constexpr std::array<double, 7> kChi2_999 = {0.0, 10.828, 13.816, 16.266, 18.467, 20.515, 22.458};

/// What one fusion did: innovation, its predicted variance, and the test ratio
/// NIS / chi2_999(dim) (> 1 means the innovation is inconsistent at 99.9 %).
struct UpdateReport {
  int dim = 0;
  std::array<double, 6> innovation{};
  std::array<double, 6> innovation_var{};
  double nis = 0.0;
  double test_ratio = 0.0;
  bool accepted = false;
};

/// Fuses one measurement of dimension M into (P, dx) of an N-dimensional error state: a
/// subsystem's 21 states, or the stacked states of all IMUs (the centralized filter). With
/// gate > 0, rejects it (P and dx untouched) when test_ratio > gate. Joseph form keeps P
/// positive. `K_out` (optional) receives the gain of an accepted update. With `gain_mask`,
/// the states whose entry is 0 are Schmidt "consider" states of this update: their rows of
/// K are zeroed (the other states' gains still account for their covariance), and the
/// Joseph form below keeps P the covariance of that suboptimal gain.
template <int M, int N>
UpdateReport ekf_update(Eigen::Matrix<double, N, N>& P, Eigen::Matrix<double, N, 1>& dx,
                        const Eigen::Matrix<double, M, N>& H, const Eigen::Matrix<double, M, 1>& dz,
                        const Eigen::Matrix<double, M, M>& R, double gate = 0.0,
                        Eigen::Matrix<double, N, M>* K_out = nullptr,
                        const Eigen::Matrix<double, N, 1>* gain_mask = nullptr) {
  static_assert(M >= 1 && M <= 6);
  using MatM = Eigen::Matrix<double, M, M>;
  using MatNM = Eigen::Matrix<double, N, M>;
  // Coefficient-based (lazy) products: at these fixed sizes they beat Eigen's blocked GEMM,
  // which packs its operands first.
  const MatNM PHt = P.lazyProduct(H.transpose());
  const MatM S = H.lazyProduct(PHt) + R;
  const Eigen::LLT<MatM> llt(S);
  UpdateReport rep;
  rep.dim = M;
  for (int i = 0; i < M; ++i) {
    rep.innovation[i] = dz(i);
    rep.innovation_var[i] = S(i, i);
  }
  if (llt.info() != Eigen::Success) return rep;  // S not positive: skip, report not accepted
  rep.nis = dz.dot(llt.solve(dz));
  rep.test_ratio = rep.nis / kChi2_999[M];
  if (gate > 0.0 && rep.test_ratio > gate) return rep;

  MatNM K = llt.solve(PHt.transpose()).transpose();
  if (gain_mask) K = gain_mask->asDiagonal() * K;
  if (K_out) *K_out = K;
  dx += K * (dz - H.lazyProduct(dx));
  // Joseph form (I - KH) P (I - KH)^T + K R K^T, multiplied out so that no n x n x n
  // product is formed: P - K (PH^T)^T - (PH^T) K^T + K S K^T (S = HPH^T + R). The
  // identity holds for any K, so the form keeps Joseph's tolerance of a K that is not
  // exactly optimal; O(n^2 M) instead of O(n^3).
  const MatNM KS = K.lazyProduct(S);
  if constexpr (N > kStateDim) {
    // The stacked error state of the centralized filter (63 to 105 states): the same
    // update on the lower triangle only, then mirrored; half the work of the full form,
    // which is most of the cost at that size. (A subsystem's 21 states keep the full form
    // below, symmetrised after: the golden runs pin its rounding.)
    for (int j = 0; j < N; ++j)
      for (int i = j; i < N; ++i)
        P(i, j) += KS.row(i).dot(K.row(j)) - K.row(i).dot(PHt.row(j)) - PHt.row(i).dot(K.row(j));
    P.template triangularView<Eigen::StrictlyUpper>() = P.transpose();
  } else {
    P -= K.lazyProduct(PHt.transpose());
    P -= PHt.lazyProduct(K.transpose());
    P += KS.lazyProduct(K.transpose());
    P = 0.5 * (P + P.transpose()).eval();
  }
  rep.accepted = true;
  return rep;
}

}  // namespace wheelins
