// `wheelins info`: what this build is and the conventions it uses.
#include <iostream>

#include "cli.hpp"

namespace {
const bool registered = wheelins::cli::register_command(
    100, "info", "Print the frame conventions and units wheelins uses", [](CLI::App&) {
      return []() {
        std::cout << "wheelins 0.1.0\n"
                     "frames: v (mid rear axle; x fwd, y right, z down), w/n (NED), "
                     "Wheel-IMU b (x along axle, right), Body-IMU b (x fwd, y right, z down)\n"
                     "Euler angles: ZYX [roll, pitch, yaw]; Wheel-IMU yaw = vehicle heading + 90 deg\n"
                     "binary data: little-endian float64 rows (Wheel-INS dataset layout)\n";
        return 0;
      };
    });
}  // namespace
