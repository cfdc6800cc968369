// The steering observer of steering.hpp: delta' = psi_w' - (v / x) sin(delta), and the
// start's delta_0 from the wheel's turn over its first `onset_distance`.
#include "wheelins/filter/steering.hpp"

#include <algorithm>
#include <cmath>

#include "wheelins/math/rotation.hpp"

namespace wheelins {

namespace {

/// The smallest whole number of revolutions (at least one) that rolls `distance`.
double whole_revolutions(double distance, double wheel_radius) {
  if (!(wheel_radius > 0.0)) return distance;
  const double circumference = 2.0 * kPi * wheel_radius;
  return std::max(1.0, std::ceil(distance / circumference - 1e-9)) * circumference;
}

}  // namespace

SteeringObserver::SteeringObserver(double distance_ahead, double wheel_radius, const SteeringOptions& opt)
    : x_(distance_ahead), opt_(opt),
      onset_(whole_revolutions(opt.onset_distance, wheel_radius)),
      reference_onset_(whole_revolutions(opt.reference_onset_distance, wheel_radius)) {}

SteeringObserver::Step SteeringObserver::step(double wheel_yaw_rate, double speed, double dt,
                                              double wheel_heading, double vehicle_heading) {
  Step out;
  if (dt > 0.0) speed_lp_ += (speed - speed_lp_) * std::min(1.0, dt / opt_.standstill_time);
  const bool rolling = std::abs(speed_lp_) > opt_.standstill_speed;
  const bool reference = vehicle_heading != kNoHeading;
  switch (phase_) {
    case Phase::kStanding:
      if (!rolling) {
        // Steering at rest: the wheel turns, the vehicle does not.
        rate_ = wheel_yaw_rate;
        delta_ += rate_ * dt;
        return out;
      }
      phase_ = Phase::kOnset;
      out.rolling_began = true;
      referenced_ = reference;
      if (reference) {
        ref_start_ = ref_last_ = vehicle_heading;
        gap_last_ = wrap_pi(wheel_heading - vehicle_heading);
      }
      [[fallthrough]];
    case Phase::kOnset: {
      if (referenced_ && !reference) referenced_ = false;  // the reference left: alone
      if (referenced_) {
        // delta as the wheel's heading less the vehicle's (offset by the wheel's error).
        const double gap = wrap_pi(wheel_heading - vehicle_heading);
        rate_ = dt > 0.0 ? wrap_pi(gap - gap_last_) / dt : 0.0;
        gap_last_ = gap;
        delta_ = gap;  // for now (the error is added at the end)
        ref_last_ = vehicle_heading;
        if (rolling) {
          turn_ += wheel_yaw_rate * dt;  // should the reference leave
          gap_sum_ += gap * speed * dt;
          distance_ += speed * dt;
        }
      } else {
        // delta held: the vehicle turns with the wheel, except where it stands again.
        rate_ = rolling ? 0.0 : wheel_yaw_rate;
        delta_ += rate_ * dt;
        if (rolling) {
          turn_ += wheel_yaw_rate * dt;
          distance_ += speed * dt;
          // Meanwhile the turn so far says delta_0 roughly: the wheel's path (and the
          // vehicle's point it carries) follows it rather than the armed delta, which can
          // be tens of degrees off (a car parked with its wheels turned).
          if (std::abs(distance_) >= opt_.provisional_distance && std::abs(distance_) < onset_) {
            const double provisional = std::asin(std::clamp(x_ * turn_ / distance_, -0.95, 0.95));
            out.turn = provisional - delta_;
            delta_ = provisional;
          }
        }
      }
      const double needed = referenced_ ? reference_onset_ : onset_;
      if (std::abs(distance_) >= needed) {
        double delta_end = 0.0;
        if (referenced_) {
          // The vehicle turns by sin(delta) / x per metre: the mean steering over the onset,
          // against the mean gap (delta less the wheel's heading error).
          const double turn = wrap_pi(ref_last_ - ref_start_);
          const double mean_delta = std::asin(std::clamp(x_ * turn / distance_, -0.95, 0.95));
          const double error = mean_delta - gap_sum_ / distance_;
          out.turn = error;
          delta_end = delta_ + error;
        } else {
          // Rolling at constant steering, the wheel turns by sin(delta) / x per metre.
          delta_end = std::asin(std::clamp(x_ * turn_ / distance_, -0.95, 0.95));
          out.turn = delta_end - delta_;
        }
        delta_ = delta_end;
        phase_ = Phase::kTracking;
      }
      return out;
    }
    case Phase::kTracking:
      rate_ = wheel_yaw_rate - speed / x_ * std::sin(delta_);
      delta_ += rate_ * dt;
      return out;
  }
  return out;
}

}  // namespace wheelins
