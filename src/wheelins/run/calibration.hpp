// The installation calibration pass of a run (docs/filter.md section 15): every selected
// module's file read once through the input checks into a WheelImuCalibrator, the
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

/// The estimates of a run's modules.
struct InstallationCalibration {
  std::vector<WheelImuCalibration> wheels;  ///< in the order of the run's modules
  std::vector<BodyImuCalibration> bodies;
  bool empty() const { return wheels.empty() && bodies.empty(); }
};

/// Reads the modules among `modules` and returns their estimates (Wheel-IMUs: axle, lever
/// arm, relative radius; Body-IMUs: mounting); samples after `t_end` are not used.
InstallationCalibration calibrate_installation(
    const Manifest& m, const std::vector<std::string>& modules,
    const InstallationCalibrationOptions& opt, bool isolate_faults, bool progress,
    double t_end = std::numeric_limits<double>::infinity());

/// The manifest with each calibrated module's mounting, lever arm and radius replaced by
/// the estimates (an unobserved part keeps the manifest's value).
Manifest apply_calibration(Manifest m, const InstallationCalibration& cal);

/// calibration.yaml: per module the estimates, their 1 sigma, the manifest values and
/// whether the data determined them, in the manifest's keys and units.
std::string calibration_yaml(const InstallationCalibration& cal, const Manifest& m);

/// A readable table of the same.
std::string calibration_report(const InstallationCalibration& cal);

}  // namespace wheelins
