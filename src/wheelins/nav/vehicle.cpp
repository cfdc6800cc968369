// The module geometry helpers of vehicle.hpp: a Wheel-IMU's sensor axes into its b-frame.
#include "wheelins/nav/vehicle.hpp"

namespace wheelins {

Mat3 axle_axis_permutation(int axle_axis) {
  // Row i of P picks the sensor axis that becomes b-axis i: (a, a+1, a+2) cyclically, a
  // rotation (det +1), so the b-frame stays right-handed.
  Mat3 P = Mat3::Zero();
  const int a = ((axle_axis % 3) + 3) % 3;
  for (int i = 0; i < 3; ++i) P(i, (a + i) % 3) = 1.0;
  return P;
}

Mat3 wheel_sensor_to_body(const ImuModule& module) {
  return dcm_from_euler(module.mounting_rpy) * axle_axis_permutation(module.axle_axis);
}

}  // namespace wheelins
