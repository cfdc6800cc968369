// The whole-turn mean of the wheel velocity model (turn_average.hpp).
#include "wheelins/filter/turn_average.hpp"

#include <algorithm>
#include <cmath>

namespace wheelins {

namespace {
constexpr double kTurn = 2.0 * kPi;
}  // namespace

void TurnAverager::reserve(int capacity) {
  buf_.assign(static_cast<std::size_t>(std::max(capacity, 1)), Epoch{});
  head_ = count_ = 0;
}

void TurnAverager::add(const WheelVelocityModel& m, const Vec21& feedback_total,
                       const Eigen::Vector2d& level, double raw_omega_x, double dt) {
  if (buf_.empty()) return;
  Epoch& e = buf_[static_cast<std::size_t>(head_)];
  e.H = m.H;
  e.H_level = m.H_level;
  e.b = m.z_hat + m.H * feedback_total - m.H_level * level;
  e.omega_x = raw_omega_x;
  e.dt = dt;
  head_ = (head_ + 1) % capacity();
  count_ = std::min(count_ + 1, capacity());
}

bool TurnAverager::average(const Vec21& feedback_total, const Eigen::Vector2d& level,
                           TurnAverage& out) const {
  // Walk back from the newest epoch counting the angle turned (|omega_x| dt: a turn is a turn
  // either way) to the epoch in which one whole turn is complete; only the part of that epoch
  // inside the turn counts.
  double angle = 0.0;
  int n = 0;
  double last_weight = 1.0;
  for (int k = 0; k < count_; ++k) {
    const double da = std::abs(at(k).omega_x) * at(k).dt;
    if (da > 0.0 && angle + da >= kTurn) {
      last_weight = (kTurn - angle) / da;
      n = k + 1;
      break;
    }
    angle += da;
  }
  if (n == 0) return false;
  // Sum with weights dt (the last one partial), so the mean is over time.
  Eigen::Matrix<double, 3, kStateDim> H = Eigen::Matrix<double, 3, kStateDim>::Zero();
  Eigen::Matrix<double, 3, 2> H_level = Eigen::Matrix<double, 3, 2>::Zero();
  Vec3 b = Vec3::Zero();
  double w_sum = 0.0, omega = 0.0;
  for (int k = 0; k < n; ++k) {
    const Epoch& e = at(k);
    const double w = e.dt * (k == n - 1 ? last_weight : 1.0);
    H += w * e.H;
    H_level += w * e.H_level;
    b += w * e.b;
    omega += w * e.omega_x;
    w_sum += w;
  }
  if (!(w_sum > 0.0)) return false;
  out.model.H = H / w_sum;
  out.model.H_level = H_level / w_sum;
  out.model.z_hat = (b - H * feedback_total + H_level * level) / w_sum;
  out.model.z_meas.setZero();
  out.mean_omega_x = omega / w_sum;
  out.duration = w_sum;
  return true;
}

}  // namespace wheelins
