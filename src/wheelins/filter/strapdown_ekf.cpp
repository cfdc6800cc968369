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
  P_.diagonal() = P_.diagonal().cwiseProduct(noise.estimated);  // held states: no uncertainty
  ++starts_;
  ++revision_;
  feedback_total_.setZero();
  S_.setZero();
  held_var_.setZero();
  n_held_ = 0;
  for (int k = 0; k < kStateDim; ++k)
    if (noise.held(k)) {
      if (n_held_ == kMaxHeld)
        throw InputError("at most 3 error states can be held (not estimated) per IMU");
      held_[n_held_] = k;
      held_var_(n_held_) = held_state_variance(noise, k);
      S_(k, n_held_) = 1.0;
      ++n_held_;
    }
  reported_dirty_ = true;
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
  const ErrorDynamics d = pending_dynamics();
  propagate_covariance(P_, d, noise_, pending_dt_);
  if (n_held_) apply_transition<kMaxHeld>(d, pending_dt_, S_);
  reported_dirty_ = true;
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
  feedback_total_ += dx;
}

void StrapdownEkf::rotate_about_vertical(double angle, const Vec3& pivot) {
  const Mat3 R = rot_z(angle);
  state_.q_ItoW = (Quat(R) * state_.q_ItoW).normalized();
  state_.v_IinW = R * state_.v_IinW;
  state_.p_IinW = pivot + R * (state_.p_IinW - pivot);
  ++revision_;
}

void StrapdownEkf::set_noise(const ProcessNoise& noise) {
  // The held states must stay what they were at initialize(): their rows of P are zero.
  noise_.gyro_arw = noise.gyro_arw;
  noise_.acc_vrw = noise.acc_vrw;
  noise_.gyro_bias_std = noise.gyro_bias_std;
  noise_.acc_bias_std = noise.acc_bias_std;
  noise_.gyro_sf_std = noise.gyro_sf_std;
  noise_.acc_sf_std = noise.acc_sf_std;
}

void StrapdownEkf::set_gyro_bias_uncertainty(double sigma) {
  P_.middleRows<3>(BG).setZero();
  P_.middleCols<3>(BG).setZero();
  P_.block<3, 3>(BG, BG).diagonal().setConstant(sigma * sigma);
  P_.diagonal() = P_.diagonal().cwiseProduct(noise_.estimated);
  reported_dirty_ = true;
}

const Mat21& StrapdownEkf::reported_covariance() const {
  if (!n_held_) return P_;
  // P changes at the covariance steps and the updates only; the records between them (every
  // epoch) read the cache.
  if (reported_dirty_) {
    const Eigen::Matrix<double, kStateDim, kMaxHeld> SV = S_ * held_var_.asDiagonal();
    reported_ = P_ + SV.lazyProduct(S_.transpose());
    reported_ = 0.5 * (reported_ + reported_.transpose()).eval();
    reported_dirty_ = false;
  }
  return reported_;
}

double held_state_variance(const ProcessNoise& q, int k) {
  const double s = k >= SA   ? q.acc_sf_std
                   : k >= SG ? q.gyro_sf_std
                   : k >= BA ? q.acc_bias_std
                   : k >= BG ? q.gyro_bias_std
                             : 0.0;
  return s * s;
}

}  // namespace wheelins
