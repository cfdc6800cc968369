// The vehicle and its IMUs as the estimator is told about them: each module's
// kind, geometry and noise figures (ImuModule), and what a run starts from (the
// w-frame origin, the static period of the alignment, the initial heading,
// gravity) -- VehicleSetup. SI units throughout.
//
// The dataset manifest (io/manifest.hpp) states the same with the files the data
// are in; io converts a Manifest into a VehicleSetup. Nothing here knows about
// files or their formats.
#pragma once

#include <string>
#include <vector>

#include "wheelins/math/rotation.hpp"
#include "wheelins/nav/earth.hpp"

namespace wheelins {

enum class ModuleKind { kWheel, kBody };

/// Noise figures a filter assumes for one IMU (SI: rad, s, m): white noise densities
/// and the first-order Gauss-Markov sigmas and correlation times of the sensor errors.
struct ImuNoise {
  double gyro_arw = 0.24 * kDeg / 60.0;   ///< angle random walk [rad/sqrt(s)]
  double acc_vrw = 0.3 / 60.0;            ///< velocity random walk [m/s/sqrt(s)]
  double gyro_bias_std = 50.0 * kDeg / 3600.0;  ///< residual gyro bias std [rad/s]
  double acc_bias_std = 0.01;             ///< residual accelerometer bias std [m/s^2]
  double gyro_sf_std = 3000e-6;           ///< residual gyro scale-factor std [-]
  double acc_sf_std = 3000e-6;            ///< residual accelerometer scale-factor std [-]
  double gyro_bias_tau = 3600.0;          ///< Gauss-Markov correlation times [s]
  double acc_bias_tau = 3600.0;
  double gyro_sf_tau = 3600.0;
  double acc_sf_tau = 3600.0;
};

/// One IMU module: what it is, where it sits on the vehicle, and its noise.
struct ImuModule {
  std::string name;             ///< unique, e.g. "left-C1"
  ModuleKind kind = ModuleKind::kWheel;
  double rate_hz = 200.0;       ///< nominal sample rate
  /// Wheel-IMU: the wheel centre in the v-frame. Body-IMU: the IMU centre in the v-frame. [m]
  Vec3 p_inV = Vec3::Zero();
  /// Wheel-IMU: lever arm from the IMU centre to the wheel centre in the b-frame [m].
  Vec3 lever_arm_inB = Vec3::Zero();
  /// Body-IMU: C_b^v as ZYX Euler [roll, pitch, yaw]. Wheel-IMU: the small rotation of the
  /// sensor axes from the ideal wheel b-frame (the paper's mounting angles). [rad]
  Vec3 mounting_rpy = Vec3::Zero();
  int axle_sign = 1;            ///< Wheel-IMU: +1 if b x-axis points right, -1 if left
  /// Wheel-IMU: which sensor axis lies along the axle (0: x, 1: y, 2: z). The b-frame takes
  /// it as its x-axis and the next two cyclically (y, z for x; z, x for y; x, y for z), so
  /// the b-frame stays right-handed; mounting_rpy then rotates the result (sensor_to_body()).
  int axle_axis = 0;
  double wheel_radius = 0.0;    ///< Wheel-IMU nominal wheel radius [m]
  /// Wheel-IMU on a steered wheel: the wheel turns against the vehicle about its (vertical)
  /// kingpin by the steering angle, which its subsystem estimates (filter/steering.hpp). The
  /// v-frame origin o is then the mid rear (unsteered) axle: p_inV.x is the wheel's distance
  /// ahead of it.
  bool steered = false;
  /// Wheel-IMU: the scale-factor error of its gyro about the vehicle's vertical, s: the two
  /// gyro axes in the wheel plane read (1 + s) times the rate about them (their mean scale
  /// factor: as the wheel rolls the yaw rate turns through both), so their readings are
  /// divided by (1 + s). The wheel's rotation cancels a bias, not a scale factor, and
  /// nothing but a heading reference shows it (`wheelins calibrate --reference`). [-]
  double yaw_scale = 0.0;
  /// Gyro full scale [rad/s] (readings at it are saturated); 0 = not stated.
  double gyro_range = 0.0;
  /// Accelerometer full scale [m/s^2]; 0 = not stated. A reading beyond either range (+5 %)
  /// cannot come from the sensor: the run leaves it out as a fault.
  double accel_range = 0.0;
  ImuNoise noise;
};

/// The cyclic permutation that takes sensor axis `axle_axis` to the b-frame's x-axis
/// (the next sensor axes to y and z): b = P * sensor.
Mat3 axle_axis_permutation(int axle_axis);

/// C_s^b of a module: the sensor axes into its b-frame. A Wheel-IMU's axes are first
/// permuted so that its axle axis is x (axle_axis_permutation), then rotated by its mounting
/// angles; a Body-IMU's mounting is C_b^v and its samples stay in sensor axes (identity).
Mat3 wheel_sensor_to_body(const ImuModule& module);

/// The fewest samples of every module in the static period the initial alignment accepts.
constexpr int kMinStaticSamples = 10;

/// What a navigation run is told before its first sample.
struct VehicleSetup {
  std::string source;             ///< where it was stated (e.g. a manifest file), for messages
  earth::Geodetic origin;         ///< the w-frame origin (reference point o at the start)
  double static_start = 0.0;      ///< static period for the initial alignment [s]
  double static_end = 0.0;
  double initial_heading = 0.0;   ///< vehicle heading at the start [rad]
  /// False when nothing stated the initial heading: the run navigates in a local frame
  /// (an odometry frame, as ROS's `odom`) whose x-axis is the vehicle's heading at the start.
  bool heading_known = true;
  double gravity = 9.8;           ///< [m/s^2]
  std::vector<ImuModule> modules;
  /// Per module (same order): where its samples come from (e.g. a file), for messages.
  std::vector<std::string> data_sources;

  /// The module named `name`, or nullptr.
  const ImuModule* find(const std::string& name) const {
    for (const auto& m : modules)
      if (m.name == name) return &m;
    return nullptr;
  }
};

}  // namespace wheelins
