// NavigatorOptions::describe() (the option listing of `wheelins run`) and validate().
#include "wheelins/fusion/options.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <utility>

namespace wheelins {

namespace {
const char* describe_yaw(YawScaleFactorChoice c) {
  switch (c) {
    case YawScaleFactorChoice::kAuto:
      return "from the position constraint when it takes in a Body-IMU, else held "
             "(unobservable without a heading reference)";
    case YawScaleFactorChoice::kHeld: return "held (unobservable without a heading reference)";
    case YawScaleFactorChoice::kFromConstraint: return "from the position constraint only";
    case YawScaleFactorChoice::kEstimated: return "estimated from every update";
  }
  return "?";
}
}  // namespace

NavigatorOptions NavigatorOptions::resolved(int n_modules, bool has_body) const {
  NavigatorOptions o = *this;
  YawScaleFactors mode = YawScaleFactors::kHeld;
  switch (yaw_scale_factors) {
    case YawScaleFactorChoice::kAuto:
      // Without a heading reference the vehicle's yaw-rate scale factor is a heading error that
      // no measurement shows, and held it is carried as a consider term outside the gains. But
      // the constraint shows the difference of the IMUs' headings; a Body-IMU's heading then
      // counts only if every subsystem's covariance holds its own yaw-scale uncertainty (else
      // the Body-INS, whose yaw bias drifts, follows the Wheel-INSs). Two Wheel-IMUs alone have
      // equal priors: estimated or held, their mean heading is the same. (The centralized
      // filter holds their weighted mean: CentralizedFilter::hold_common_yaw_scale_factor.)
      if (fusion.position_constraint && has_body && n_modules >= 2)
        mode = YawScaleFactors::kFromConstraint;
      break;
    case YawScaleFactorChoice::kHeld: mode = YawScaleFactors::kHeld; break;
    case YawScaleFactorChoice::kFromConstraint: mode = YawScaleFactors::kFromConstraint; break;
    case YawScaleFactorChoice::kEstimated: mode = YawScaleFactors::kEstimated; break;
  }
  o.wheel.yaw_scale_factors = o.body.yaw_scale_factors = mode;
  return o;
}

std::string NavigatorOptions::describe() const {
  std::ostringstream o;
  auto onoff = [](bool b) { return b ? "on" : "off"; };
  o << "velocity update interval:   " << wheel.velocity_update_interval << " s\n"
    << "wheel speed window:         " << wheel.speed_window << " s\n"
    << "Wheel-INS velocity model:   "
    << (wheel.turn_average ? "averaged over the last whole wheel turn (within " +
                                 std::to_string(wheel.turn_window) + " s)"
                           : std::string("at the update epoch (paper)")) << "\n"
    << "wheel speed sharing:        "
    << (fusion.speed == SpeedSharing::kMean ? "mean of Wheel-IMUs (paper)" : "own wheel (Body-INS: their mean)") << "\n"
    << "Wheel-INS velocity sigma:   " << wheel.velocity_std.transpose() << " m/s\n"
    << "Body-INS velocity sigma:    " << body.velocity_std.transpose() << " m/s\n"
    << "position constraint:        " << onoff(fusion.position_constraint) << ", every "
    << fusion.position_update_interval << " s, sigma " << fusion.position_std << " m\n"
    << "reference weights (eq. 8):  "
    << (fusion.weighting == ReferenceWeighting::kCovariance
            ? "inverse variance of each subsystem's o, averaged over " +
                  std::to_string(static_cast<int>(fusion.weight_window)) + " constraint epochs"
            : fusion.weighting == ReferenceWeighting::kStandalone
                ? std::string("inverse of each subsystem's drift on its own (federated, no reset)")
                : std::string(fusion.weights.empty() ? "equal (paper)" : "fixed, as configured"))
    << "\n"
    << "Body-INS level to wheels:   " << onoff(fusion.share_level) << "\n"
    << "filter structure:           "
    << (fusion.centralized ? "centralized (one joint covariance)"
                          : "distributed (paper; with several IMUs its 1-sigma figures are too small, "
                            "--centralized gives consistent ones)") << "\n"
    << "innovation gates (vel/pos): " << wheel.gate << " / " << fusion.position_gate
    << " (0 = off)\n"
    << "initial sigma:              position " << wheel.init.position << " m, velocity "
    << wheel.init.velocity << " m/s, roll/pitch " << wheel.init.roll_pitch / kDeg
    << " deg, heading " << wheel.init.heading / kDeg << " deg\n"
    << "mechanization:              "
    << (mechanization == MechanizationOptions::Method::kRotationExact ? "rotation-exact"
                                                                       : "classic two-sample")
    << "\n"
    << "earth rotation:             " << (earth_rotation ? "compensated" : "ignored") << "\n"
    << "covariance time update:     "
    << (covariance_interval > 0 ? "every " + std::to_string(covariance_interval) + " s"
                                : std::string("every epoch"))
    << "\n"
    << "noise model:                "
    << (noise.enabled ? "identified from the data (rest: Allan variance; motion: Mehra, window " +
                            std::to_string(static_cast<int>(noise.window)) + " updates)"
                      : std::string("the given figures, held fixed"))
    << "\n"
    << "yaw-rate scale factors:     " << describe_yaw(yaw_scale_factors) << "\n"
    << "axle accelerometer SF:      "
    << (wheel.estimate_axle_accel_scale_factor ? "estimated" : "held (not told from its bias on one-way turns)")
    << "\n"
    << faults.describe()
    << "standstill:                 "
    << (standstill.enabled
            ? "zero velocity and rate while every IMU is quiet for " + std::to_string(standstill.min_time) +
                  " s (rates < " + std::to_string(standstill.max_rate / kDeg) + " deg/s, specific force within " +
                  std::to_string(standstill.max_force_spread) + " m/s^2)"
            : std::string("off"))
    << "\n"
    << "output interval:            "
    << (output_interval > 0 ? std::to_string(output_interval) + " s" : std::string("every epoch"))
    << "\n";
  return o.str();
}

void NoiseAdaptationOptions::validate() const {
  auto fail = [](const char* what, double v) {
    char got[48];
    std::snprintf(got, sizeof got, ", got %.17g", v);
    throw InputError(what + std::string(got));
  };
  if (!(window >= 5.0 && window <= 1e5)) fail("noise adaptation window: must be in [5, 1e5] updates", window);
  if (!(r_floor_fraction > 0.0 && r_floor_fraction <= 1.0))
    fail("noise adaptation: the measurement-noise floor must be in (0, 1] of its given sigma", r_floor_fraction);
  if (!(vrw_max > 0.0 && std::isfinite(vrw_max))) fail("noise adaptation: vrw_max must be > 0", vrw_max);
  if (!(min_speed >= 0.0 && std::isfinite(min_speed))) fail("noise adaptation: min_speed must be >= 0", min_speed);
  if (!(settle >= 0.0 && std::isfinite(settle))) fail("noise adaptation: settle must be >= 0 s", settle);
  if (!(bias_floor >= 0.0 && std::isfinite(bias_floor))) fail("noise adaptation: bias floor must be >= 0", bias_floor);
}

void StandstillOptions::validate() const {
  const std::pair<double, const char*> values[] = {
      {max_rate, "max_rate_deg_s"}, {max_force_spread, "max_force_spread_m_s2"}, {block, "block_s"},
      {min_time, "min_time_s"},     {velocity_std, "velocity_std_m_s"},          {rate_std, "rate_std_deg_s"}};
  for (const auto& [v, key] : values)
    if (!(v > 0.0 && std::isfinite(v)))
      throw InputError(std::string("standstill.") + key + ": must be > 0, got " + std::to_string(v));
  if (min_time < 2.0 * block)
    throw InputError("standstill.min_time_s: must be at least two blocks (" + std::to_string(2.0 * block) +
                     " s), got " + std::to_string(min_time));
}

void NavigatorOptions::validate() const {
  auto fail = [](const char* what, double v) {
    char got[48];
    std::snprintf(got, sizeof got, ", got %.17g", v);
    throw InputError(what + std::string(got));
  };
  static_assert(kMaxCovarianceInterval == 0.5, "quoted below");
  if (!(covariance_interval >= 0.0 && covariance_interval <= kMaxCovarianceInterval))
    fail("covariance interval: must be in [0, 0.5] s", covariance_interval);
  if (!(output_interval >= 0.0) || !std::isfinite(output_interval))
    fail("output interval: must be >= 0 s (0 = every epoch)", output_interval);
  if (!(wheel.velocity_update_interval > 0.0) || !std::isfinite(wheel.velocity_update_interval))
    fail("velocity update interval: must be > 0 s", wheel.velocity_update_interval);
  if (!(fusion.position_update_interval > 0.0) || !std::isfinite(fusion.position_update_interval))
    fail("position update interval: must be > 0 s", fusion.position_update_interval);
  if (!(fusion.position_std > 0.0) || !std::isfinite(fusion.position_std))
    fail("position constraint sigma: must be > 0 m", fusion.position_std);
  if (!(fusion.weight_window >= 1.0 && fusion.weight_window <= 1e6))
    fail("reference weight window: must be in [1, 1e6] constraint epochs", fusion.weight_window);
  if (!(fusion.heading_offset_window > 0.0) || !std::isfinite(fusion.heading_offset_window))
    fail("heading offset window: must be > 0 s", fusion.heading_offset_window);
  if (fusion.weighting != ReferenceWeighting::kFixed && !fusion.weights.empty())
    throw InputError("fusion weights: fixed weights and weights from the data exclude each other");
  noise.validate();
  standstill.validate();
}

}  // namespace wheelins
