// The strapdown EKF of strapdown_ekf.hpp: initialisation, the nominal propagation with
// the accumulation of F over the covariance interval, the time update, and the feedback.
#include "wheelins/filter/strapdown_ekf.hpp"

namespace wheelins {

void StrapdownEkf::initialize(const NavState& state, const ImuErrors& errors,
                              const ProcessNoise& noise, const InitialUncertainty& init,
                              const MechanizationOptions& mech) {
  state_ = state;
  errors_ = errors;
  noise_ = noise;
  mech_ = mech;
  have_last_ = false;
  // The constant blocks of F (earth rate, Gauss-Markov decays) once; the others accumulate.
  pending_ = error_dynamics_blocks(Mat3::Identity(), Vec3::Zero(), Vec3::Zero(),
                                   mech.omega_ie_inW, noise);
  clear_pending();
  P_.setZero();
  P_.block<3, 3>(P, P).diagonal().setConstant(init.position * init.position);
  P_.block<3, 3>(V, V).diagonal().setConstant(init.velocity * init.velocity);
  P_.block<3, 3>(PHI, PHI).diagonal() << init.roll_pitch * init.roll_pitch,
      init.roll_pitch * init.roll_pitch, init.heading * init.heading;
  P_.block<3, 3>(BG, BG).diagonal().setConstant(noise.gyro_bias_std * noise.gyro_bias_std);
  P_.block<3, 3>(BA, BA).diagonal().setConstant(noise.acc_bias_std * noise.acc_bias_std);
  P_.block<3, 3>(SG, SG).diagonal().setConstant(noise.gyro_sf_std * noise.gyro_sf_std);
  P_.block<3, 3>(SA, SA).diagonal().setConstant(noise.acc_sf_std * noise.acc_sf_std);
  initialized_ = true;
}

void StrapdownEkf::propagate_nominal(const ImuSample& raw) {
  const ImuSample cur = compensate(raw, errors_);
  mechanize(mech_, have_last_ ? last_ : cur, cur, state_);
  last_ = cur;
  last_raw_ = raw;
  have_last_ = true;
  // The epoch's varying blocks of F (error_dynamics_blocks) times dt, taken straight from
  // the increments: [f x] dt = [C dvel x], C diag(f) dt = C diag(dvel), C diag(w) dt =
  // C diag(dtheta). The constant blocks were set at initialize().
  const Mat3 C = state_.C_ItoW();
  pending_.Ff += skew(C * cur.dvel);
  pending_.C += cur.dt * C;
  pending_.Cf += C * cur.dvel.asDiagonal();
  pending_.Cw += C * cur.dtheta.asDiagonal();
  pending_dt_ += cur.dt;
}

ErrorDynamics StrapdownEkf::pending_dynamics() const {
  ErrorDynamics d = pending_;
  if (pending_dt_ > 0.0) {
    const double k = 1.0 / pending_dt_;
    d.Ff *= k;
    d.C *= k;
    d.Cf *= k;
    d.Cw *= k;
  }
  return d;
}

void StrapdownEkf::clear_pending() {
  pending_.Ff.setZero();
  pending_.C.setZero();
  pending_.Cf.setZero();
  pending_.Cw.setZero();
  pending_dt_ = 0.0;
}

void StrapdownEkf::flush_covariance() {
  if (pending_dt_ <= 0.0) return;
  propagate_covariance(P_, pending_dynamics(), noise_, pending_dt_);
  clear_pending();
}

void StrapdownEkf::feedback(const Vec21& dx) {
  // r = r_hat - dr, v = v_hat - dv, C = exp([phi x]) C_hat, totals += residuals.
  state_.p_IinW -= dx.segment<3>(P);
  state_.v_IinW -= dx.segment<3>(V);
  state_.q_ItoW = (quat_from_rotvec(dx.segment<3>(PHI)) * state_.q_ItoW).normalized();
  errors_.bg += dx.segment<3>(BG);
  errors_.ba += dx.segment<3>(BA);
  errors_.sg += dx.segment<3>(SG);
  errors_.sa += dx.segment<3>(SA);
}

}  // namespace wheelins
