// What one module's data say about the module by themselves, before any manifest is
// believed: whether it spins (a Wheel-IMU) and about which sensor axis and which way,
// when it is at rest, its gyro bias and which way is up in its own axes; and the
// signals the clock and role surveys compare across modules: the wheel's spin rate and
// every module's yaw rate about the vertical.
//
// The yaw rate of a Wheel-IMU is read without knowing its mounting: the rotation in the
// wheel plane (the gyro with its spin axis taken out, and the part of the spin that leaks
// into the other axes through a small misalignment regressed out) projected onto the
// vertical the accelerometer shows in that plane (the specific force with its centripetal
// part -- proportional to the squared spin rate for a sensor off the hub -- and its
// tangential part regressed out, smoothed over 0.25 s). Positive is counter-clockwise seen
// from above (a left turn), as for a Body-IMU's rate about its measured up-axis.
#pragma once

#include <string>
#include <vector>

#include "wheelins/survey/series.hpp"

namespace wheelins::survey {

struct Interval {
  double start = 0.0, end = 0.0;
  double length() const { return end - start; }
};

struct TraitOptions {
  double min_spin_rate = 2.0;    ///< [rad/s] a wheel's 95th percentile spin rate in motion exceeds it
  double min_spin_share = 0.8;   ///< the spin axis's share of the rotation in motion
  double rest_rate = 0.08;       ///< [rad/s] a resting wheel's spin rate stays within this of its bias
  double min_rest = 1.0;         ///< [s] shortest rest interval kept
  double body_rest_factor = 3.0; ///< a body at rest: gyro and accelerometer std within this factor of their quietest 10 %
};

struct ModuleTraits {
  std::string module;
  bool spins = false;        ///< one sensor axis carries a wheel's rotation
  int spin_axis = 0;         ///< the sensor axis with the most rotation in motion (0 x, 1 y, 2 z)
  double spin_share = 0.0;   ///< its share of the mean square rate in motion
  double spin_p95 = 0.0;     ///< 95th percentile |rate| about it in motion [rad/s]
  /// Mean sign of the spin-axis rate in motion, weighted by the rate: +1 all one way,
  /// -1 all the other, near 0 back and forth.
  double spin_direction = 0.0;
  double motion_time = 0.0;  ///< [s] not at rest
  Vec3 gyro_bias = Vec3::Zero();  ///< mean rate at rest, sensor axes [rad/s]
  Vec3 up = Vec3::UnitZ();        ///< unit specific force at rest (points up), sensor axes
  bool rest_found = false;
  std::vector<Interval> rest;     ///< rest intervals (module time)
};

/// The traits of one module's series.
ModuleTraits analyse_module(const Series& s, const TraitOptions& options = {});

/// A Wheel-IMU's spin rate about its spin axis, its rest bias removed [rad/s] (per bin).
std::vector<double> spin_rate(const Series& s, const ModuleTraits& t);

/// The yaw rate about the vertical [rad/s] per bin, positive counter-clockwise from above:
/// a Body-IMU's rate about its up-axis; a Wheel-IMU's as the header says.
std::vector<double> yaw_rate(const Series& s, const ModuleTraits& t);

/// Per bin: whether the module rests (its own criterion, as for `rest`).
std::vector<std::uint8_t> rest_mask(const Series& s, const ModuleTraits& t);

}  // namespace wheelins::survey
