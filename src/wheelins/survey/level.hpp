// A Body-IMU's roll and pitch on the vehicle from the drive (a level fit), not from the
// up-axis at rest: where the vehicle stood still (a parking spot, a ramp) it was tilted
// by the ground, and the gravity it measured there holds that tilt; the mounting does not.
//
// In the vehicle frame (x forward, y right, z down) the specific force's vertical part
// is gravity plus the body's vertical accelerations; its forward and lateral parts carry
// the vehicle's accelerations, braking and turning. With the right mounting the vertical
// part does not follow the horizontal ones; a roll or pitch error of the mounting mixes
// them: f_z' = f_z + pitch * f_x - roll * f_y to first order. So the fit regresses the
// vertical specific force on the forward and lateral ones (0.5 s means, each minute less
// its own mean: the sensor's bias, gravity and the road's slowly changing grade drop out;
// a grade moves f_x by g sin(grade) and f_z only by its square) and turns the down axis
// by the slopes until they vanish. The slopes' standard errors are the fit's uncertainty.
#pragma once

#include <string>

#include "wheelins/nav/types.hpp"
#include "wheelins/survey/series.hpp"

namespace wheelins::survey {

struct LevelFitOptions {
  double bin = 0.5;          ///< [s] specific force averaged over this (a car body's vibration is far larger)
  double chunk = 60.0;       ///< [s] each chunk less its own mean
  int min_bins = 100;        ///< fewer 0.5 s means in chunks than this: not fitted
  double min_excitation = 0.15;  ///< [m/s^2] rms of the horizontal specific force (demeaned) below which it is not fitted
  double max_sigma_deg = 1.5;   ///< a fit less certain than this (either axis) is not taken
  int iterations = 3;
};

struct LevelFit {
  bool found = false;
  Vec3 up = Vec3::UnitZ();      ///< the vehicle's up axis in sensor axes (unit)
  double sigma_roll_deg = 0.0;  ///< 1-sigma of the fit about the vehicle's forward axis
  double sigma_pitch_deg = 0.0;  ///< 1-sigma of the fit about the vehicle's right axis
  int bins = 0;                  ///< 0.5 s means fitted
  double excitation = 0.0;       ///< [m/s^2] rms of the demeaned horizontal specific force
  std::string why;               ///< when not found: why, in words
};

/// The level fit of a body's series: `up0` its up axis at rest (the start), `forward` the
/// vehicle's forward axis in sensor axes (from its accelerations); only bins whose series
/// samples are all filled count.
LevelFit fit_level(const Series& s, const Vec3& up0, const Vec3& forward, const LevelFitOptions& options = {});

/// Rows forward, right, down of the vehicle in sensor axes (C_b^v) from an up axis and a
/// forward axis (made orthogonal to it).
Mat3 vehicle_axes(const Vec3& up, const Vec3& forward);

/// The angle between two vectors [deg].
double angle_deg(const Vec3& a, const Vec3& b);

}  // namespace wheelins::survey
