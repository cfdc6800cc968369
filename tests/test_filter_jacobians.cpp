// Every Jacobian of the filter against a finite-difference Jacobian of the
// nonlinear function it linearises, with the error conventions of error_state.hpp:
//   r_hat = r + dr, v_hat = v + dv, C_hat = exp(-[phi x]) C,
//   omega_hat = omega + b_g + diag(omega) s_g,  f_hat = f + b_a + diag(f) s_a.
#include <gtest/gtest.h>

#include <string>

#include "wheelins/filter/body_velocity.hpp"
#include "wheelins/filter/error_model.hpp"
#include "wheelins/filter/position_constraint.hpp"
#include "wheelins/filter/wheel_velocity.hpp"
#include "wheelins/filter/zero_motion.hpp"
#include "wheelins/nav/earth.hpp"

using namespace wheelins;

namespace {

// A wheel-like attitude: heading 37 deg (+90 for the axle), wheel angle 1.1 rad, small tilt.
Mat3 wheel_attitude() { return dcm_from_euler(Vec3(1.1, 0.03, (37.0 + 90.0) * kDeg)); }

struct NavTruth {
  Vec3 p = Vec3(10.0, -4.0, 0.3);
  Vec3 v = Vec3(1.1, 0.8, 0.02);
  Mat3 C = wheel_attitude();
  Vec3 omega = Vec3(-14.2, 0.3, -0.2);  // rad/s, b-frame
  Vec3 f = Vec3(0.4, -3.1, -9.2);       // m/s^2, b-frame
};

// Perturbs the truth by an error vector dx (the estimate = truth (+) dx).
struct Estimate {
  Vec3 p, v, omega, f;
  Mat3 C;
};
Estimate perturb(const NavTruth& t, const Vec21& dx) {
  Estimate e;
  e.p = t.p + dx.segment<3>(P);
  e.v = t.v + dx.segment<3>(V);
  e.C = dcm_from_rotvec(-dx.segment<3>(PHI)) * t.C;
  e.omega = t.omega + dx.segment<3>(BG) + t.omega.cwiseProduct(dx.segment<3>(SG));
  e.f = t.f + dx.segment<3>(BA) + t.f.cwiseProduct(dx.segment<3>(SA));
  return e;
}

// The nonlinear w-frame dynamics of position and velocity (the mechanization's continuous form).
struct Derivs {
  Vec3 p_dot, v_dot;
};
Derivs dynamics(const Vec3& v, const Mat3& C, const Vec3& f, const Vec3& w_ie, double g) {
  return {v, C * f + Vec3(0, 0, g) - 2.0 * w_ie.cross(v)};
}

// Time derivative of the navigation error (rows P, V, PHI) for error dx.
Eigen::Matrix<double, 9, 1> error_rate(const NavTruth& t, const Vec21& dx, const Vec3& w_ie) {
  const Estimate e = perturb(t, dx);
  const Derivs dt = dynamics(t.v, t.C, t.f, w_ie, 9.8);
  const Derivs de = dynamics(e.v, e.C, e.f, w_ie, 9.8);
  // phi from C_hat C^T = exp(-[phi x]); differentiate along the flow with a tiny step.
  // Exact flow of C_dot = C [omega x] - [w_ie x] C for constant rates over +-h;
  // a central difference in time keeps both truncation and roundoff small.
  const double h = 1e-3;
  auto flow = [&](const Mat3& C, const Vec3& omega, double dt) {
    return Mat3(dcm_from_rotvec(-w_ie * dt) * C * dcm_from_rotvec(omega * dt));
  };
  auto phi_of = [](const Mat3& Ch, const Mat3& Ct) {
    return Vec3(-rotvec_from_quat(Quat(Mat3(Ch * Ct.transpose()))));
  };
  const Vec3 phi_plus = phi_of(flow(e.C, e.omega, h), flow(t.C, t.omega, h));
  const Vec3 phi_minus = phi_of(flow(e.C, e.omega, -h), flow(t.C, t.omega, -h));
  Eigen::Matrix<double, 9, 1> r;
  r.segment<3>(0) = de.p_dot - dt.p_dot;
  r.segment<3>(3) = de.v_dot - dt.v_dot;
  r.segment<3>(6) = (phi_plus - phi_minus) / (2 * h);
  return r;
}

/// Central differences of the innovation `innovation_at(dx)` over every error state, against H.
template <class F>
void expect_jacobian(const F& innovation_at, const Eigen::Matrix<double, 3, kStateDim>& H, const char* what) {
  const double eps = 1e-6;
  for (int j = 0; j < kStateDim; ++j) {
    Vec21 dx = Vec21::Zero();
    dx(j) = eps;
    const Vec3 plus = innovation_at(dx);
    dx(j) = -eps;
    const Vec3 col = (plus - innovation_at(dx)) / (2 * eps);
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(col(i), H(i, j), 1e-6 * (1.0 + std::abs(H(i, j)))) << what << " H(" << i << "," << j << ")";
  }
}

}  // namespace

TEST(FilterJacobian, ErrorDynamicsMatchFiniteDifference) {
  const NavTruth t;
  const Vec3 w_ie = earth::earth_rate_ned(30.5 * kDeg);
  ProcessNoise q;
  const Mat21 F = error_dynamics(t.C, t.omega, t.f, w_ie, q);
  const double eps = 1e-5;
  for (int j = 0; j < kStateDim; ++j) {
    Vec21 dx = Vec21::Zero();
    dx(j) = eps;
    const auto plus = error_rate(t, dx, w_ie);
    dx(j) = -eps;
    const auto minus = error_rate(t, dx, w_ie);
    const Eigen::Matrix<double, 9, 1> col = (plus - minus) / (2 * eps);
    for (int i = 0; i < 9; ++i)
      EXPECT_NEAR(col(i), F(i, j), 2e-5 * (1.0 + std::abs(F(i, j))))
          << "F(" << i << "," << j << ")";
  }
  // Gauss-Markov rows: d(b)/dt = -b / tau.
  EXPECT_DOUBLE_EQ(F(BG, BG), -1.0 / q.gyro_bias_tau);
  EXPECT_DOUBLE_EQ(F(SA + 2, SA + 2), -1.0 / q.acc_sf_tau);
}

namespace {
WheelVelocityInput wheel_input(const Estimate& e, double mean_omega_x) {
  WheelVelocityInput in;
  in.C_BtoW = e.C;
  in.v_IinW = e.v;
  in.omega_ib_b = e.omega;
  in.omega_ie_inW = earth::earth_rate_ned(30.5 * kDeg);
  in.lever_arm_inB = Vec3(0.012, -0.004, 0.006);
  in.vehicle_roll = 0.02;
  in.vehicle_pitch = -0.035;
  set_own_wheel_speed(in, 0.097, mean_omega_x);
  return in;
}
}  // namespace

TEST(FilterJacobian, WheelVelocityMatchesFiniteDifference) {
  // Level and unsteered; tilted and steered 20 deg (the level turned into the wheel's frame).
  for (double steering : {0.0, 20.0 * kDeg})
  for (int axle_sign : {1, -1}) {
    const NavTruth t;
    const double mean_wx = -14.0;
    auto residual = [&](const Vec21& dx) {
      const Estimate e = perturb(t, dx);
      // The window-mean speed sees the same residual gyro errors as the current sample.
      const double mean = mean_wx + dx(BG) + mean_wx * dx(SG);
      WheelVelocityInput in = wheel_input(e, mean);
      in.axle_sign = axle_sign;
      if (steering != 0.0) in.vehicle_roll = 0.03, in.vehicle_pitch = -0.02, in.steering = steering;
      set_own_wheel_speed(in, 0.097, mean);
      return wheel_velocity_model(in).innovation();
    };
    WheelVelocityInput in0 = wheel_input(perturb(t, Vec21::Zero()), mean_wx);
    in0.axle_sign = axle_sign;
    if (steering != 0.0) in0.vehicle_roll = 0.03, in0.vehicle_pitch = -0.02, in0.steering = steering;
    set_own_wheel_speed(in0, 0.097, mean_wx);
    const WheelVelocityModel m = wheel_velocity_model(in0);
    const std::string what = "axle " + std::to_string(axle_sign) + " steering " + std::to_string(steering);
    expect_jacobian(residual, m.H, what.c_str());
  }
}

TEST(FilterJacobian, WheelVelocityPredictsTrueWheelCentreVelocity) {
  // A level wheel rolling forward at heading 37 deg with the IMU on the wheel centre:
  // the prediction is [v, 0, 0] and the measured speed matches it.
  const double radius = 0.1, speed = 1.5, heading = 37 * kDeg;
  WheelVelocityInput in;
  in.C_BtoW = rot_z(heading + kPi / 2) * rot_x(-0.7);
  in.v_IinW = speed * Vec3(std::cos(heading), std::sin(heading), 0.0);
  in.omega_ib_b = Vec3(-speed / radius, 0, 0);
  set_own_wheel_speed(in, radius, -speed / radius);
  const auto m = wheel_velocity_model(in);
  EXPECT_NEAR((m.z_hat - Vec3(speed, 0, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(m.innovation().norm(), 0.0, 1e-12);
  EXPECT_NEAR(wheel_vehicle_heading(in.C_BtoW, 1), heading, 1e-12);
}

TEST(FilterJacobian, BodyVelocityMatchesFiniteDifference) {
  NavTruth t;
  t.C = dcm_from_euler(Vec3(0.02, -0.04, 1.3));
  t.omega = Vec3(0.01, -0.02, 0.35);
  BodyVelocityInput base;
  base.omega_ie_inW = earth::earth_rate_ned(30.5 * kDeg);
  base.C_BtoV = dcm_from_euler(Vec3(0.5, -0.8, 1.2) * kDeg);
  base.lever_arm_inB = Vec3(-0.25, 0.16, 0.2);
  base.measured_speed = 1.3;
  auto model_at = [&](const Vec21& dx) {
    const Estimate e = perturb(t, dx);
    BodyVelocityInput in = base;
    in.C_BtoW = e.C;
    in.v_IinW = e.v;
    in.omega_ib_b = e.omega;
    return body_velocity_model(in);
  };
  expect_jacobian([&](const Vec21& dx) { return model_at(dx).innovation(); }, model_at(Vec21::Zero()).H,
                  "body velocity");
}

TEST(FilterJacobian, PositionConstraintMatchesFiniteDifference) {
  // A body; a wheel; a steered wheel (turned 20 deg against the vehicle).
  for (int kind : {0, 1, 2}) {
    const bool wheel = kind > 0;
    NavTruth t;
    if (!wheel) t.C = dcm_from_euler(Vec3(0.02, -0.04, 1.3));
    ReferencePointInput base;
    base.wheel = wheel;
    base.lever_arm_inB = wheel ? Vec3(0.004, -0.003, 0.005) : Vec3::Zero();
    base.p_inV = wheel ? Vec3(0.0, -0.165, 0.0) : Vec3(0.2, 0.02, -0.15);
    base.vehicle_roll = 0.03;
    base.vehicle_pitch = -0.02;
    base.C_BtoV = dcm_from_euler(Vec3(0.5, -0.8, 1.2) * kDeg);
    if (kind == 2) {
      base.steering = 20.0 * kDeg;
      base.p_inV = Vec3(2.6, -0.75, 0.0);
    }
    auto model_at = [&](const Vec21& dx) {
      const Estimate e = perturb(t, dx);
      ReferencePointInput in = base;
      in.C_BtoW = e.C;
      in.p_IinW = e.p;
      return reference_point_model(in);
    };
    const auto m = model_at(Vec21::Zero());
    const double eps = 1e-6;
    for (int j = 0; j < kStateDim; ++j) {
      Vec21 dx = Vec21::Zero();
      dx(j) = eps;
      const Vec3 plus = model_at(dx).r_o;
      dx(j) = -eps;
      const Vec3 col = (plus - model_at(dx).r_o) / (2 * eps);
      for (int i = 0; i < 3; ++i)
        EXPECT_NEAR(col(i), m.H(i, j), 1e-6 * (1.0 + std::abs(m.H(i, j))))
            << "kind " << kind << " H(" << i << "," << j << ")";
    }
  }
}

TEST(FilterJacobian, ZeroVelocityAndZeroRateMatchFiniteDifference) {
  // A Wheel-IMU's attitude; an earth rate magnified (the model is linear in it) so that the
  // attitude block is tested, a rate and a velocity away from zero so that every block is.
  NavTruth t;
  const Vec3 w_ie(0.3, -0.2, 0.5);
  auto input_at = [&](const Vec21& dx) {
    const Estimate e = perturb(t, dx);
    ZeroMotionInput in;
    in.C_BtoW = e.C;
    in.v_IinW = e.v;
    in.omega_ib_b = e.omega;
    in.omega_ie_inW = w_ie;
    return in;
  };
  for (int which : {0, 1}) {
    auto model_at = [&](const Vec21& dx) {
      return which == 0 ? zero_velocity_model(input_at(dx)) : zero_rate_model(input_at(dx));
    };
    expect_jacobian([&](const Vec21& dx) { return model_at(dx).innovation(); }, model_at(Vec21::Zero()).H,
                    which == 0 ? "zero velocity" : "zero rate");
  }
  // At rest the true state predicts the measurement exactly: no velocity, and the gyro
  // showing the earth's rotation only.
  t.v.setZero();
  t.omega = t.C.transpose() * w_ie;
  EXPECT_NEAR(zero_velocity_model(input_at(Vec21::Zero())).innovation().norm(), 0.0, 1e-15);
  EXPECT_NEAR(zero_rate_model(input_at(Vec21::Zero())).innovation().norm(), 0.0, 1e-15);
}

TEST(FilterJacobian, ReferencePointOfLevelWheelAndBody) {
  // Vehicle at (5, 2) heading 30 deg; the left wheel centre is at v (0, -0.165, 0).
  const double psi = 30 * kDeg;
  const Vec3 o(5, 2, 0);
  ReferencePointInput w;
  w.C_BtoW = rot_z(psi + kPi / 2) * rot_x(-0.4);
  w.lever_arm_inB = Vec3(0.003, 0.002, -0.004);
  w.p_inV = Vec3(0, -0.165, 0);
  w.p_IinW = o + rot_z(psi) * w.p_inV - w.C_BtoW * w.lever_arm_inB;
  EXPECT_NEAR((reference_point_model(w).r_o - o).norm(), 0.0, 1e-12);
  ReferencePointInput b;
  b.wheel = false;
  b.C_BtoV = dcm_from_euler(Vec3(0.01, 0.02, 0.03));
  b.C_BtoW = rot_z(psi) * b.C_BtoV;
  b.p_inV = Vec3(0.2, 0.0, -0.15);
  b.p_IinW = o + rot_z(psi) * b.p_inV;
  EXPECT_NEAR((reference_point_model(b).r_o - o).norm(), 0.0, 1e-12);
}

// The centralized filter's cross-terms (Section VI-B-2): a Wheel-INS measurement depends on
// the Body-INS attitude through the shared vehicle level (eq. 5, theta_3 and phi_3).

TEST(FilterJacobian, WheelVelocityAndReferencePointLevelJacobians) {
  // Level and steered wheels: a steered wheel's model takes the vehicle's level turned into
  // its own heading frame, its H_level stays d/d the vehicle's roll and pitch.
  for (double steering : {0.0, 0.35})
  for (double roll : {0.02, -0.3}) {
    const NavTruth t;
    WheelVelocityInput base = wheel_input(perturb(t, Vec21::Zero()), -14.0);
    base.vehicle_roll = roll;
    base.vehicle_pitch = 0.05;
    base.steering = steering;
    ReferencePointInput rp;
    rp.C_BtoW = t.C;
    rp.p_IinW = t.p;
    rp.lever_arm_inB = Vec3(0.004, -0.003, 0.005);
    rp.p_inV = Vec3(0.01, -0.165, 0.02);
    rp.vehicle_roll = base.vehicle_roll;
    rp.vehicle_pitch = base.vehicle_pitch;
    rp.steering = steering;
    const WheelVelocityModel m = wheel_velocity_model(base);
    const ReferencePointModel r = reference_point_model(rp);
    const double eps = 1e-6;
    for (int k = 0; k < 2; ++k) {
      auto vel_at = [&](double s) {
        WheelVelocityInput in = base;
        (k == 0 ? in.vehicle_roll : in.vehicle_pitch) += s;
        return wheel_velocity_model(in).z_hat;
      };
      auto ro_at = [&](double s) {
        ReferencePointInput in = rp;
        (k == 0 ? in.vehicle_roll : in.vehicle_pitch) += s;
        return reference_point_model(in).r_o;
      };
      const Vec3 dv = (vel_at(eps) - vel_at(-eps)) / (2 * eps);
      const Vec3 dr = (ro_at(eps) - ro_at(-eps)) / (2 * eps);
      for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(dv(i), m.H_level(i, k), 1e-7 * (1.0 + std::abs(m.H_level(i, k))))
            << "velocity roll " << roll << " steering " << steering << " (" << i << "," << k << ")";
        EXPECT_NEAR(dr(i), r.H_level(i, k), 1e-8) << "reference point (" << i << "," << k << ")";
      }
    }
    EXPECT_GT(m.H_level.cwiseAbs().maxCoeff(), 1e-2);
    EXPECT_GT(r.H_level.cwiseAbs().maxCoeff(), 1e-3);
  }
  // A Body-IMU's o does not depend on a shared level.
  ReferencePointInput b;
  b.wheel = false;
  EXPECT_EQ(reference_point_model(b).H_level.cwiseAbs().maxCoeff(), 0.0);
}

TEST(FilterJacobian, VehicleLevelSensitivityMatchesFiniteDifference) {
  // Roll/pitch of C_v^w = C_b^w C_v^b of a Body-IMU under its attitude error
  // (C_hat = exp(-[phi x]) C), and the chain into a Wheel-INS innovation (the Body-INS
  // block of the centralized H).
  const Mat3 C_BtoV = dcm_from_euler(Vec3(0.5, -0.8, 1.2) * kDeg);
  const Mat3 C_body = dcm_from_euler(Vec3(0.03, -0.05, 2.1)) * C_BtoV;
  const Mat3 C_VtoW = C_body * C_BtoV.transpose();
  const Eigen::Matrix<double, 2, 3> L = vehicle_level_sensitivity(C_VtoW);
  const NavTruth t;
  WheelVelocityInput base = wheel_input(perturb(t, Vec21::Zero()), -14.0);
  auto level_at = [&](const Vec3& phi) {
    const Vec3 rpy = euler_from_dcm(dcm_from_rotvec(-phi) * C_body * C_BtoV.transpose());
    return Eigen::Vector2d(rpy.x(), rpy.y());
  };
  auto innovation_at = [&](const Vec3& phi) {
    const Eigen::Vector2d lv = level_at(phi);
    WheelVelocityInput in = base;
    in.vehicle_roll = lv.x();
    in.vehicle_pitch = lv.y();
    return wheel_velocity_model(in).innovation();
  };
  const Eigen::Vector2d lv0 = level_at(Vec3::Zero());
  base.vehicle_roll = lv0.x();
  base.vehicle_pitch = lv0.y();
  const Eigen::Matrix<double, 3, 3> H_body = wheel_velocity_model(base).H_level * L;
  const double eps = 1e-6;
  for (int j = 0; j < 3; ++j) {
    Vec3 dphi = Vec3::Zero();
    dphi(j) = eps;
    const Eigen::Vector2d col = (level_at(dphi) - level_at(-dphi)) / (2 * eps);
    const Vec3 hcol = (innovation_at(dphi) - innovation_at(-dphi)) / (2 * eps);
    for (int i = 0; i < 2; ++i) EXPECT_NEAR(col(i), L(i, j), 1e-8) << "L(" << i << "," << j << ")";
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(hcol(i), H_body(i, j), 1e-7) << "H_body(" << i << "," << j << ")";
  }
}
