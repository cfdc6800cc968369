// What only a reference (a GNSS track) can show of a vehicle and a recording, estimated
// from one recording with one (`wheelins calibrate --reference`):
//   * each wheel's absolute rolling radius: the reference's speed against the wheel's turn
//     rate, v_ref(t) = R * omega_fwd(t) + c * yaw_rate(t) (c takes the wheel's lateral offset
//     from the antenna in turns), over the epochs faster than min_speed, both smoothed over
//     1 s; a second pass without the residuals beyond 4 MADs; 1 sigma from the scatter of
//     the same fit on 5 parts of the drive (the standard error of their mean) or the least
//     squares' own, whichever is larger;
//   * the reference's clock offset, refined: the shift of its times that best fits its speed
//     to an unsteered wheel's with the yaw term (the antenna's speed departs from the
//     wheels' in turns);
//   * the initial heading and the antenna's horizontal position on the vehicle: a dead
//     reckoning of the unsteered wheels with the radii, in a local frame, aligned onto the
//     reference over its first `align_length` metres (eval/alignment.hpp);
//   * each wheel's yaw scale factor (the scale of its gyro axes in the wheel plane): its own
//     Wheel-INS with the radii, the clock and the antenna above, its heading error against
//     the reference's course regressed on the heading turned (run/yaw_scale_fit.hpp);
// Vehicle values (radii, yaw scales, antenna) carry over to its other recordings; the initial heading
// belongs to this recording only.
#pragma once

#include <string>
#include <vector>

#include "wheelins/eval/alignment.hpp"
#include "wheelins/io/diagnostics.hpp"
#include "wheelins/io/manifest.hpp"
#include "wheelins/run/calibration.hpp"
#include "wheelins/run/yaw_scale_fit.hpp"

namespace wheelins {

struct ReferenceCalibrationOptions {
  double min_speed = 1.5;        ///< [m/s] reference speed of the epochs the radius uses
  double align_length = 300.0;   ///< [m] of the reference's travel the heading fit uses (<= 0: all)
  bool estimate_antenna = true;
  bool estimate_yaw_scale = true;   ///< each wheel's yaw scale factor (yaw_scale_fit.hpp)
  YawScaleFitOptions yaw_scale;
  double max_antenna_sigma = 0.15;  ///< [m] the antenna is taken as observed below this 1 sigma
  bool progress = false;
};

struct WheelRadiusFit {
  std::string module;
  CalibratedValue radius;     ///< [m] for the filter (its own speed against the reference)
  CalibratedValue odometry_radius;  ///< [m] for the raw axle rate (a plain odometer)
  double manifest_radius = 0.0;
  YawScaleFit yaw;                  ///< its yaw scale factor (yaw_scale_fit.hpp)
  double manifest_yaw_scale = 0.0;
  double correlation = 0.0;   ///< of the reference's speed and the fit
  std::size_t epochs = 0;
};

struct ReferenceCalibration {
  std::vector<WheelRadiusFit> wheels;
  CalibratedValue initial_heading;        ///< [rad]
  CalibratedValue truth_time_offset;      ///< [s] the reference's clock, refined
  CalibratedValue antenna_forward, antenna_right;  ///< [m], in the v-frame
  eval::StartAlignment alignment;
  std::vector<std::string> navigation_modules;  ///< the dead reckoning the heading came from
  std::vector<std::string> notes;
};

/// Estimates the above for `modules` of `m` (its truth and truth_time_offset_s; the wheels
/// among the modules, a Body-IMU among them for the yaw rate). `installation`, if not
/// empty, is applied before (a run's installation calibration).
ReferenceCalibration calibrate_against_reference(const Manifest& m, const std::vector<std::string>& modules,
                                                 const InstallationCalibration& installation,
                                                 const ReferenceCalibrationOptions& options, const WarningSink& warn);

/// The manifest with the radii, the yaw scales, the initial heading and the antenna applied (what is not
/// observed keeps the manifest's value).
Manifest apply_reference_calibration(Manifest m, const ReferenceCalibration& cal);

/// A readable table of the estimates.
std::string reference_calibration_report(const ReferenceCalibration& cal);

/// The same as YAML (appended to calibration.yaml): per value the estimate, 1 sigma, the
/// manifest's value and whether it was observed.
std::string reference_calibration_yaml(const ReferenceCalibration& cal, const Manifest& m);

}  // namespace wheelins
