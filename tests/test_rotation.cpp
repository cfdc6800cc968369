#include <gtest/gtest.h>

#include "wheelins/math/rotation.hpp"
#include "wheelins/nav/earth.hpp"

using namespace wheelins;

TEST(Rotation, EulerRoundTrip) {
  for (double r : {-2.5, -0.3, 0.0, 0.7, 3.0})
    for (double p : {-1.2, -0.1, 0.0, 0.4, 1.3})
      for (double y : {-3.0, -1.0, 0.0, 0.5, 2.9}) {
        const Vec3 rpy(r, p, y);
        const Vec3 back = euler_from_dcm(dcm_from_euler(rpy));
        EXPECT_NEAR(back.x(), r, 1e-12);
        EXPECT_NEAR(back.y(), p, 1e-12);
        EXPECT_NEAR(back.z(), y, 1e-12);
      }
}

TEST(Rotation, EulerIsZyx) {
  // Yaw 90 deg: the body x-axis points east.
  const Mat3 C = dcm_from_euler(Vec3(0, 0, kPi / 2));
  EXPECT_NEAR((C * Vec3::UnitX() - Vec3::UnitY()).norm(), 0.0, 1e-12);
  // Pitch up 90 deg: the body x-axis points up (-z in NED).
  const Mat3 P = dcm_from_euler(Vec3(0, kPi / 2, 0));
  EXPECT_NEAR((P * Vec3::UnitX() + Vec3::UnitZ()).norm(), 0.0, 1e-12);
}

TEST(Rotation, RotvecExpLog) {
  for (const Vec3& rv : {Vec3(0.1, -0.2, 0.3), Vec3(1e-10, 0, 0), Vec3(0, 3.0, 0.1)}) {
    const Vec3 back = rotvec_from_quat(quat_from_rotvec(rv));
    EXPECT_NEAR((back - rv).norm(), 0.0, 1e-12);
    // exp([rv]x) via series vs closed form
    Mat3 K = skew(rv), term = Mat3::Identity(), sum = Mat3::Identity();
    for (int k = 1; k < 30; ++k) {
      term = term * K / k;
      sum += term;
    }
    EXPECT_NEAR((sum - dcm_from_rotvec(rv)).norm(), 0.0, 1e-12);
  }
}

TEST(Rotation, Skew) {
  const Vec3 a(1, 2, 3), b(-4, 0.5, 2);
  EXPECT_NEAR((skew(a) * b - a.cross(b)).norm(), 0.0, 1e-15);
}

TEST(Rotation, JacobiansMatchIntegral) {
  // integral_0^1 exp(s [phi]) ds == J_l(phi); J_r^{-1} is the inverse of J_r.
  for (const Vec3& phi : {Vec3(0.075, 0.001, -0.002), Vec3(1.0, -0.5, 0.3), Vec3(1e-7, 0, 0)}) {
    Mat3 integral = Mat3::Zero();
    const int n = 2000;
    for (int i = 0; i < n; ++i) integral += dcm_from_rotvec(phi * ((i + 0.5) / n)) / n;
    EXPECT_NEAR((integral - so3_left_jacobian(phi)).norm(), 0.0, 1e-6);
    EXPECT_NEAR((so3_right_jacobian_inverse(phi) * so3_right_jacobian(phi) - Mat3::Identity()).norm(),
                0.0, 1e-12);
  }
}

TEST(Rotation, WrapPi) {
  EXPECT_NEAR(wrap_pi(3 * kPi / 2), -kPi / 2, 1e-12);
  EXPECT_NEAR(wrap_pi(-3 * kPi / 2), kPi / 2, 1e-12);
  EXPECT_NEAR(wrap_pi(kPi), kPi, 1e-12);
  EXPECT_NEAR(wrap_pi(0.1), 0.1, 1e-15);
}

TEST(Earth, LocalFrameRoundTrip) {
  const earth::Geodetic origin{30.5 * kDeg, 114.3 * kDeg, 20.0};
  const earth::LocalFrame frame(origin);
  const Vec3 ned(523.25, -871.5, -3.25);
  const Vec3 back = frame.ned_from_geodetic(frame.geodetic_from_ned(ned));
  EXPECT_NEAR((back - ned).norm(), 0.0, 1e-6);
  // One arc-second of latitude is about 30.8 m north.
  earth::Geodetic g = origin;
  g.lat += kDeg / 3600.0;
  const Vec3 d = frame.ned_from_geodetic(g);
  EXPECT_NEAR(d.x(), 30.8, 0.1);
  EXPECT_NEAR(d.y(), 0.0, 1e-6);
}

TEST(Earth, GeodeticFromEcefInvertsEcefFromGeodetic) {
  // The closed form (Bowring + one refinement) against the forward transformation, from
  // the equator to the poles and from -1 km to 100 km.
  for (double lat_deg = -90.0; lat_deg <= 90.0; lat_deg += 0.7)
    for (double h : {-1000.0, -12.3, 0.0, 20.0, 8848.0, 100000.0}) {
      const earth::Geodetic g{lat_deg * kDeg, (lat_deg * 3.1 - 40.0) * kDeg, h};
      const earth::Geodetic back = earth::geodetic_from_ecef(earth::ecef_from_geodetic(g));
      ASSERT_NEAR(back.lat, g.lat, 1e-13) << lat_deg << " deg, " << h << " m";
      ASSERT_NEAR(back.h, g.h, 1e-6) << lat_deg << " deg, " << h << " m";
      if (std::abs(lat_deg) < 89.9) {
        ASSERT_NEAR(wrap_pi(back.lon - g.lon), 0.0, 1e-14);
      }
    }
}

TEST(Earth, NormalGravity) {
  EXPECT_NEAR(earth::normal_gravity(0.0, 0.0), 9.7803, 1e-3);
  EXPECT_NEAR(earth::normal_gravity(kPi / 2, 0.0), 9.8322, 1e-3);
}
