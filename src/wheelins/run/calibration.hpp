// The installation calibration pass of a run (docs/filter.md section 15): every selected
// Wheel-IMU's file read once through the input checks into a WheelImuCalibrator, the
// manifest refined with the estimates, and the estimates as text (calibration.yaml and a
// table).
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "wheelins/filter/installation_calibration.hpp"
#include "wheelins/io/diagnostics.hpp"
#include "wheelins/io/manifest.hpp"

namespace wheelins {

/// How a run treats the installation geometry of its Wheel-IMUs.
enum class CalibrationMode {
  kEstimate,  ///< estimated from the data before navigating (the default)
  kManifest,  ///< the manifest's values as they are
};

/// Reads the Wheel-IMU modules among `modules` (Body-IMUs are not calibrated) and returns
/// their estimates, in the order of `modules`; samples after `t_end` are not used.
std::vector<WheelImuCalibration> calibrate_installation(
    const Manifest& m, const std::vector<std::string>& modules,
    const InstallationCalibrationOptions& opt, bool isolate_faults, bool progress,
    double t_end = std::numeric_limits<double>::infinity());

/// The manifest with each calibrated module's mounting and lever arm replaced by the
/// estimates (an unobserved part keeps the manifest's value).
Manifest apply_calibration(Manifest m, const std::vector<WheelImuCalibration>& cal);

/// calibration.yaml: per module the estimates, their 1 sigma, the manifest values and
/// whether the data determined them, in the manifest's keys and units.
std::string calibration_yaml(const std::vector<WheelImuCalibration>& cal, const Manifest& m);

/// A readable table of the same.
std::string calibration_report(const std::vector<WheelImuCalibration>& cal);

}  // namespace wheelins
