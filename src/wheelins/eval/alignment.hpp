// The start of a trajectory aligned onto a reference track: the rotation about the vertical
// and the shift that carry its first `length` metres of travel onto the reference's (and,
// optionally, the reference antenna's horizontal position on the vehicle). This is how a
// run without an initial heading (a local, odometry frame) is placed in the reference's
// frame for scoring -- the initial heading taken from the reference, as the paper does, by
// the start of the drive only, so the rest of the drive is scored as the dead reckoning it
// is -- and how `wheelins calibrate --reference` finds the initial heading and the antenna.
//
// Model, at the reference epochs t_k of the window (horizontal, north-east):
//   g_k = s + R(theta) (q_k + C(psi_k) l)
// g_k the reference position, q_k the trajectory's (interpolated), psi_k its heading,
// C(psi) the vehicle's forward/right axes in north-east, l the antenna (forward, right) in
// the vehicle frame. For a given theta the rest is linear least squares; theta is found by
// a search over the circle and refined by golden section. Its 1 sigma comes from the
// residuals and the curvature of the cost in theta, with the residuals' correlation over
// the window counted by their lag-1 autocorrelation. Reference epochs closer than 0.1 s to
// the last one used are skipped (a 200 Hz truth gives the fit and sigmas of the same track
// at 10 Hz).
#pragma once

#include <vector>

#include "wheelins/nav/types.hpp"

namespace wheelins::eval {

using Vec2 = Eigen::Vector2d;

/// A horizontal track: times, north-east positions [m] (in one local frame) and, for a
/// trajectory, its heading [rad].
struct PlanarTrack {
  std::vector<double> t;
  std::vector<Vec2> p_ne;
  std::vector<double> heading;  ///< empty for a reference without attitude
};

struct StartAlignmentOptions {
  double length = 100.0;        ///< [m] of the reference's travel the fit uses (<= 0: all)
  bool estimate_antenna = false;
  Vec2 antenna = Vec2::Zero();  ///< (forward, right) [m], when not estimated
};

struct StartAlignment {
  bool found = false;
  double yaw = 0.0;         ///< theta [rad]: added to the trajectory's headings
  double yaw_sigma = 0.0;   ///< [rad]
  Vec2 shift = Vec2::Zero();
  Vec2 antenna = Vec2::Zero();        ///< (forward, right) [m]
  Vec2 antenna_sigma = Vec2::Zero();
  double rms = 0.0;         ///< [m] residual
  double length = 0.0;      ///< [m] travelled in the window
  std::size_t points = 0;
  double t_end = 0.0;       ///< end of the window [s]
};

/// Fits the alignment (see the header); `found` false when the window has fewer than 5
/// points or the trajectory has no heading.
StartAlignment fit_start_alignment(const PlanarTrack& reference, const PlanarTrack& trajectory,
                                   const StartAlignmentOptions& options = {});

/// p' = shift + R(yaw) p.
Vec2 apply_alignment(const StartAlignment& a, const Vec2& p);

}  // namespace wheelins::eval
