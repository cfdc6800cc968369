// A Wheel-IMU's yaw scale factor (ImuModule::yaw_scale) from a reference track: its own
// Wheel-INS, started in a local frame and aligned onto the reference's start (as a run
// is scored), gives a heading error e(t) against the reference's course at every truth epoch
// with one (eval/metrics.hpp: the antenna's lead in turns taken off). A gyro that reads
// (1 + s) times the yaw rate turns the heading by (1 + s) times the vehicle's turn, so
//   e(t) = a + b (t - t0) + s psi(t),   psi(t) = the heading turned since t0 (the run's own),
// by least squares (a: the start's alignment, b: a residual yaw bias). The residuals follow
// each other (the course is taken over 1 s and the filter's errors are slow), so the
// least squares' sigma is inflated by sqrt((1 + rho) / (1 - rho)), rho their lag-1
// autocorrelation. The scale is observed when its sigma is below max_sigma, the data tell it
// from the manifest's value (|s| at least min_significance sigmas: a correction the data cannot
// tell from none would only add its own error), the heading turned spans at least min_turn and
// the total is within ManifestLimits::kYawScalePpm.
#pragma once

#include <cstddef>
#include <string>

#include "wheelins/calib/calibration_types.hpp"
#include "wheelins/io/manifest.hpp"

namespace wheelins {

struct YawScaleFitOptions {
  double max_sigma = 2000e-6;  ///< [-] the largest 1 sigma of an observed scale
  double min_turn = 1.5;       ///< [rad] the least span of the heading turned (about 90 deg)
  double min_significance = 2.0;  ///< |s| / sigma of an observed scale
};

struct YawScaleFit {
  /// The module's yaw scale with this fit applied over the manifest's:
  /// (1 + manifest) (1 + s) - 1; 1 sigma that of s; applied only when observed. Without a
  /// fit (too few epochs with a heading error) the manifest's, not observed.
  CalibratedValue yaw_scale;
  double fitted = 0.0;       ///< s over the manifest's value [-]
  double turn_span = 0.0;    ///< [rad] max - min of psi over the epochs fitted
  double residual = 0.0;     ///< [rad] rms of the fit
  std::size_t epochs = 0;    ///< truth epochs with a heading error
};

/// The fit for wheel `module` of `m` (its truth, clock, radii and antenna as calibrated; the
/// manifest's initial heading is not used). InputError as a run's.
YawScaleFit fit_yaw_scale(const Manifest& m, const std::string& module, const YawScaleFitOptions& options = {});

}  // namespace wheelins
