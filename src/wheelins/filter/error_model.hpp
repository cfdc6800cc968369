// Time update of the error-state covariance (paper eq. 2, the phi-angle model,
// plus the earth-rate terms when the w-frame rotates).
#pragma once

#include "wheelins/filter/error_state.hpp"
#include "wheelins/io/manifest.hpp"

namespace wheelins {

/// Continuous-time white-noise densities and Gauss-Markov parameters, SI.
struct ProcessNoise {
  double gyro_arw = 0, acc_vrw = 0;                    ///< [rad/sqrt(s)], [m/s/sqrt(s)]
  double gyro_bias_std = 0, acc_bias_std = 0;          ///< GM steady-state sigma
  double gyro_sf_std = 0, acc_sf_std = 0;
  double gyro_bias_tau = 3600, acc_bias_tau = 3600, gyro_sf_tau = 3600, acc_sf_tau = 3600;
  static ProcessNoise from(const ImuNoise& n);
};

/// The continuous-time error dynamics F of eq. (2):
///   d(dr)  = dv
///   d(dv)  = [f^w x] phi + C (b_a + diag(f) s_a) - 2 [w_ie x] dv
///   d(phi) = -[w_ie x] phi - C (b_g + diag(w) s_g)
///   d(b)   = -b / tau   (each of b_g, b_a, s_g, s_a)
/// C = C_b^w; omega_b and f_b are the compensated rate and specific force.
Mat21 error_dynamics(const Mat3& C_BtoW, const Vec3& omega_b, const Vec3& f_b,
                     const Vec3& omega_ie_inW, const ProcessNoise& q);

/// Phi = I + F dt.
Mat21 transition_matrix(const Mat21& F, double dt);
/// The trapezoidal Qd = (Phi Qc Phi^T + Qc) dt / 2.
Mat21 discrete_noise(const Mat21& Phi, const ProcessNoise& q, double dt);

/// P <- Phi P Phi^T + Qd over dt, with Phi = I + F dt and the trapezoidal
/// Qd = (Phi Qc Phi^T + Qc) dt / 2, Qc the diagonal noise density (the noise
/// enters through C, which is orthogonal, so C Qc C^T = Qc for isotropic sensors).
void propagate_covariance(Mat21& P, const Mat21& F, const ProcessNoise& q, double dt);

/// Keeps P symmetric (after every step) and its diagonal non-negative.
void condition_covariance(Mat21& P);

}  // namespace wheelins
