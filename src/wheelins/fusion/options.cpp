// NavigatorOptions::resolved() and the options' validate() (for options built in code; a run
// configuration's settings are checked as they are read, run/run_options.hpp).
#include "wheelins/fusion/options.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <utility>

namespace wheelins {

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
