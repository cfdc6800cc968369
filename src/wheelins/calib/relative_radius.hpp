// The wheels' relative radii (docs/filter.md section 15): the two sides' Wheel-IMUs' speed
// difference against the yaw rate the wheels themselves see, over the time bins their
// WheelImuCalibrators keep (estimate_relative_radius()).
#pragma once

#include <vector>

#include "wheelins/calib/calibration_types.hpp"
#include "wheelins/calib/wheel_imu_calibrator.hpp"

namespace wheelins {

/// The relative radius of two sides' Wheel-IMUs from their rate series (module y in the
/// v-frame tells the sides; more than one module on a side, e.g. several chips on one
/// wheel, are averaged). Sets `wheel_radius` in each of `results` (same order as
/// `cals`); a single side leaves every radius at the manifest's, not observed.
void estimate_relative_radius(const std::vector<const WheelImuCalibrator*>& cals,
                              const InstallationCalibrationOptions& opt,
                              std::vector<WheelImuCalibration>& results);

}  // namespace wheelins
