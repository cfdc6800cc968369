// Installation calibration of a Wheel-IMU from its own data (docs/filter.md section 15):
// the axle direction in its frame (the mounting pitch and yaw) and its lever arm to the
// wheel centre, estimated by a recursive accumulator in front of the filter.
//
// Both quantities show in the data averaged over whole wheel turns, taken by angle (each
// sample weighted by the angle it turns through), where everything that turns with the
// wheel cancels: gravity, the vehicle's acceleration and its yaw rate seen from the wheel.
//  * Axle: the rotation vector of a turn is 2 pi times the spin axis (the mean spin axis of
//    Chen et al. 2019, the paper's ref. chen2019): summed over all turns, its direction in
//    the b-frame given by the manifest is the axle. Its component about the axle itself
//    (the mounting roll) is a wheel-angle offset: unobservable and without effect.
//  * Lever arm: the accelerometer at r = -l from the wheel centre reads, per turn, in the
//    axle-perpendicular plane (b y, z), the centripetal and tangential terms
//      f_y = c l_y + s l_z + b_y,   f_z = c l_z - s l_y + b_z,
//    c the turn's mean omega_x^2, s its mean angular acceleration, b the accelerometer bias.
//    The bias is taken as constant over a chunk of `chunk_s` and eliminated per chunk (the
//    regressors centred within the chunk), so a drifting bias does not leak into l; l is
//    observable where the wheel speed varies within chunks (stops, corners). l_x (along
//    the axle) gives no term: unobservable and without effect on the wheel velocity.
//  * Relative wheel radii (two Wheel-IMUs on either side of the vehicle): over time bins
//    of `rate_bin_s`, the vehicle yaw rate that the wheels themselves see (each
//    Wheel-IMU's in-plane rate projected on the down direction its accelerometer shows,
//    psi_dot = -(w_y f_y + w_z f_z) / g: gravity turns with the wheel exactly as the yaw
//    rate does, so the product does not) against the wheels' speed difference,
//      track psi_dot = r_L w_L - r_R w_R,
//    fitted for eps_L - eps_R (the radii's relative errors) and a scale of psi_dot.
//    estimate_relative_radius() combines two sides' series.
//  * A Body-IMU's mounting: roll and pitch from the axis the vehicle turns about
//    (BodyImuCalibrator), the yaw from its lateral specific force against the Wheel-IMUs'
//    axle accelerometers (estimate_body_yaw()).
// Each estimate is combined with a Gaussian prior around the manifest value; with no
// information it stays there and says so (observed = false).
//
// Per sample: fixed-size arithmetic, no allocation (the time-bin series are reserved for
// the expected duration up front).
//
// The parts, by what they estimate (this header includes them all):
//  * calib/calibration_types.hpp: the options and the results (WheelImuCalibration,
//    BodyImuCalibration, CalibratedValue);
//  * calib/wheel_imu_calibrator.hpp: WheelImuCalibrator, a Wheel-IMU's axle and lever arm;
//  * calib/relative_radius.hpp: estimate_relative_radius(), the wheels' relative radii;
//  * calib/body_imu_calibrator.hpp: BodyImuCalibrator and estimate_body_yaw(), a Body-IMU's
//    mounting;
//  * calib/bins.hpp: the static-period sums and the time-bin series they share;
//    calib/prior.hpp: the estimates' priors (calib_detail, for the calibrators' sources).
#pragma once

#include "wheelins/calib/bins.hpp"
#include "wheelins/calib/body_imu_calibrator.hpp"
#include "wheelins/calib/calibration_types.hpp"
#include "wheelins/calib/relative_radius.hpp"
#include "wheelins/calib/wheel_imu_calibrator.hpp"
