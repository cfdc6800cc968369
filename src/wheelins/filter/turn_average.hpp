// The wheel velocity model averaged over whole wheel turns (docs/filter.md section 15.1).
//
// A lever arm or an axle direction that is slightly wrong makes an error in the predicted
// wheel-centre velocity of eq. (5) that turns with the wheel: C_b^w (omega x dl) for a lever
// arm off by dl, and a heading psi_v that wobbles by the axle's tilt once per turn. Sampled
// at 2 Hz it aliases into a random-looking error of a few per cent of the speed. Averaged
// over whole turns it cancels to first order, whatever the wheel angle at the update.
//
// The averager keeps, for each epoch of the last few seconds, the model of eq. (5) evaluated
// at that epoch (z_hat_i, H_i, H_level_i), and returns at an update their mean over the
// last whole turn before it, together with the mean gyro x rate over the same epochs (the speed
// measured over the same span, so the two stay in step when the vehicle speeds up).
//
// Linearization: the mean innovation is (1/N) sum_i H_i dx_i with dx_i the error at epoch i;
// over one turn (under 4 s) the error states the model sees (velocity, attitude,
// sensor errors) change little, so dx_i ~ dx_now and H = mean H_i.
// Feedback inside the window: every correction dx applied since epoch i moved the state the
// model of epoch i was evaluated at; z_hat_i is brought to the current estimate to first
// order by subtracting H_i (D_now - D_i), with D the running sum of the corrections fed back
// (StrapdownEkf::feedback_total(); a feedback dx moves every estimate by -dx, so z_hat by
// -H dx). Likewise the vehicle level (shared by a Body-INS and set
// at updates): + H_level_i (level_now - level_i). Both are kept as sums, so an update costs
// one pass over the window.
#pragma once

#include <vector>

#include "wheelins/filter/wheel_velocity.hpp"

namespace wheelins {

struct TurnAverage {
  WheelVelocityModel model;  ///< mean z_hat, H, H_level (no measured speed, no speed terms in H)
  double mean_omega_x = 0.0; ///< mean raw gyro x over the same epochs [rad/s]
  double duration = 0.0;     ///< of the turn [s]
};

class TurnAverager {
 public:
  /// Room for `capacity` epochs (allocated here, once; nothing is allocated per epoch).
  void reserve(int capacity);
  int capacity() const { return static_cast<int>(buf_.size()); }
  void clear() { count_ = 0; }
  int size() const { return count_; }

  /// One epoch: its model (evaluated with no measured speed and no speed sensitivities), the
  /// feedback total and the vehicle level [roll, pitch] it was evaluated at, its raw gyro x
  /// rate and its interval.
  void add(const WheelVelocityModel& m, const Vec21& feedback_total, const Eigen::Vector2d& level,
           double raw_omega_x, double dt);

  /// The mean over the last whole wheel turn (time-weighted; the oldest epoch by the fraction
  /// of it inside the turn), brought to the feedback total and level of now. False when the
  /// epochs kept do not hold one whole turn (slow, stopped, or just started).
  bool average(const Vec21& feedback_total, const Eigen::Vector2d& level, TurnAverage& out) const;

 private:
  struct Epoch {
    Eigen::Matrix<double, 3, kStateDim> H;
    Eigen::Matrix<double, 3, 2> H_level;
    Vec3 b;  ///< z_hat + H D - H_level level at this epoch
    double omega_x = 0.0, dt = 0.0;
  };
  /// The k-th newest epoch (0 = the newest).
  const Epoch& at(int k) const {
    return buf_[static_cast<std::size_t>((head_ - 1 - k + capacity()) % capacity())];
  }
  std::vector<Epoch> buf_;
  int head_ = 0;   ///< where the next epoch goes
  int count_ = 0;
};

}  // namespace wheelins
