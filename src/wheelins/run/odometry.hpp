// The naive dead reckoning users compare against (the baseline of docs/real-data.md): the
// vehicle's speed from its wheels (each wheel IMU's rate about its axle, less its bias at
// rest, times its radius; the mean of the wheels given, moved to the reference point o),
// its heading from a Body-IMU's rate about the vertical (its mounting applied, less its
// bias at rest) -- or, without one, from the speed difference of two wheels on opposite
// sides over their lateral distance -- integrated from the manifest's start (or heading 0
// without one). No filter, no update, no error model: what a wheel encoder and a gyro give.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "wheelins/io/manifest.hpp"
#include "wheelins/nav/trajectory_record.hpp"

namespace wheelins {

struct OdometryRequest {
  Manifest manifest;
  std::vector<std::string> wheels;  ///< wheel modules whose speeds are averaged
  std::string gyro;                 ///< a body module for the yaw rate; empty: the wheels' speed difference
  double output_interval = 0.0;     ///< [s] between records; 0: every sample of the first wheel
  std::function<void(const TrajectoryRecord&)> on_record;
};

struct OdometryResult {
  std::size_t records = 0;
  double distance = 0.0;     ///< [m] integrated
  double t_start = 0.0, t_end = 0.0;
  std::string heading_source;
};

/// Runs the dead reckoning; InputError for a module that is not what it is used as, or two
/// wheels on one side without a gyro.
OdometryResult run_wheel_odometry(const OdometryRequest& request);

}  // namespace wheelins
