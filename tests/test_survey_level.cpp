// The level fit of survey/level.hpp: a Body-IMU's roll and pitch on the vehicle from the
// drive, where the vehicle stood on a slope at the start.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "wheelins/math/rotation.hpp"
#include "wheelins/survey/level.hpp"

namespace wheelins::survey {
namespace {

constexpr double kG = 9.81;

struct Drive {
  Series series;
  Mat3 C_BtoV;  ///< the true mounting (rows: the vehicle's forward, right, down in sensor axes)
  Vec3 up_at_rest;
};

/// `minutes` of a car's drive at 100 Hz after 20 s parked on a slope (pitch 3 deg, roll
/// -2 deg): accelerations and turns (0.5-1.5 m/s^2), a rolling road grade, the body's
/// vertical bumps and vibration; the sensor mounted at [178, -4, 93] deg. `accel_scale`
/// scales the manoeuvres, the grade and the bumps (0: standing with the engine running);
/// `slope` false: parked level.
Drive drive(std::uint32_t seed, double minutes, double accel_scale = 1.0, bool slope = true) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  Drive d;
  d.C_BtoV = dcm_from_euler(Vec3(178.0, -4.0, 93.0) * kDeg);
  Series& s = d.series;
  s.module = "body";
  s.dt = 0.01;
  const double park = 20.0, span = park + 60.0 * minutes;
  const auto n = static_cast<std::size_t>(span / s.dt);
  // Random phases of a few slow manoeuvres.
  std::uniform_real_distribution<double> phase(0.0, 2.0 * M_PI);
  const double p1 = phase(rng), p2 = phase(rng), p3 = phase(rng), p4 = phase(rng);
  Vec3 up_sum = Vec3::Zero();
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * s.dt;
    Vec3 f_v;
    if (t < park) {
      const double pitch = slope ? 3.0 * kDeg : 0.0, roll = slope ? -2.0 * kDeg : 0.0;
      f_v = Vec3(kG * std::sin(pitch), -kG * std::sin(roll) * std::cos(pitch), -kG * std::cos(roll) * std::cos(pitch));
    } else {
      const double u = t - park;
      const double ax = accel_scale * (1.0 * std::sin(2 * M_PI * u / 23.0 + p1) + 0.5 * std::sin(2 * M_PI * u / 7.0 + p2));
      const double ay = accel_scale * (1.5 * std::sin(2 * M_PI * u / 31.0 + p3) + 0.4 * std::sin(2 * M_PI * u / 5.0 + p4));
      const double grade = accel_scale * 2.0 * kDeg * std::sin(2 * M_PI * u / 90.0 + p1);
      const double bump = accel_scale * 0.3 * std::sin(2 * M_PI * u * 1.3) + 0.2 * n01(rng);
      f_v = Vec3(ax + kG * std::sin(grade), ay, -kG * std::cos(grade) + bump);
      f_v += Vec3(n01(rng), n01(rng), n01(rng)) * 0.5;  // the engine's and the road's vibration
    }
    const Vec3 f_s = d.C_BtoV.transpose() * f_v;
    if (t < park) up_sum += f_s;
    s.gyro.push_back(Vec3::Zero());
    s.accel.push_back(f_s);
    s.filled.push_back(1);
  }
  d.up_at_rest = up_sum.normalized();
  return d;
}

Vec3 true_up(const Drive& d) { return -(d.C_BtoV.transpose() * Vec3::UnitZ()); }
Vec3 true_forward(const Drive& d) { return d.C_BtoV.transpose() * Vec3::UnitX(); }

TEST(LevelFit, RollAndPitchComeFromTheDriveNotFromTheSlopeItStoodOn) {
  const Drive d = drive(1, 10.0);
  // At rest the up axis holds the slope (3 and 2 deg).
  EXPECT_GT(angle_deg(d.up_at_rest, true_up(d)), 3.0);
  const LevelFit fit = fit_level(d.series, d.up_at_rest, true_forward(d));
  ASSERT_TRUE(fit.found) << fit.why;
  EXPECT_LT(angle_deg(fit.up, true_up(d)), 0.5) << "sigma " << fit.sigma_roll_deg << " / " << fit.sigma_pitch_deg;
  EXPECT_GT(fit.bins, 1000);
  // The mounting drafted from it: within half a degree of the true one.
  const Mat3 C = vehicle_axes(fit.up, true_forward(d));
  EXPECT_LT(Eigen::AngleAxisd(C * d.C_BtoV.transpose()).angle() / kDeg, 0.5);
}

TEST(LevelFit, ItsSigmasMatchItsErrorsOverManyDrives) {
  // Monte-Carlo: the errors about the forward and right axes over their sigmas.
  double sum_sq = 0.0;
  int m = 0;
  for (std::uint32_t seed = 10; seed < 40; ++seed) {
    const Drive d = drive(seed, 3.0, 0.3);
    const LevelFit fit = fit_level(d.series, d.up_at_rest, true_forward(d));
    ASSERT_TRUE(fit.found) << fit.why;
    const Vec3 e = d.C_BtoV * fit.up;  // in the vehicle frame: [0, 0, -1] if exact
    sum_sq += std::pow(e.x() / (fit.sigma_pitch_deg * kDeg), 2) + std::pow(e.y() / (fit.sigma_roll_deg * kDeg), 2);
    m += 2;
  }
  const double ratio = std::sqrt(sum_sq / m);  // 1 if the sigmas are right
  RecordProperty("error_over_sigma_rms", std::to_string(ratio));
  EXPECT_GT(ratio, 0.6);
  EXPECT_LT(ratio, 1.6);
}

TEST(LevelFit, NoFitWithoutMotionOrWithTooLittleData) {
  const Drive still = drive(2, 5.0, 0.0, false);
  LevelFit fit = fit_level(still.series, still.up_at_rest, true_forward(still));
  EXPECT_FALSE(fit.found);
  EXPECT_NE(fit.why.find("hardly accelerated"), std::string::npos) << fit.why;
  const Drive short_drive = drive(3, 0.3);
  fit = fit_level(short_drive.series, short_drive.up_at_rest, true_forward(short_drive));
  EXPECT_FALSE(fit.found);
  EXPECT_NE(fit.why.find("s needed"), std::string::npos) << fit.why;
}

}  // namespace
}  // namespace wheelins::survey
