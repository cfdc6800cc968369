// Noise identification (filter/noise_identification.hpp): the Allan variance against a
// batch computation and known noise, and the innovation covariance matching and bias
// instability matchers in closed loops whose true noise is known.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "wheelins/filter/noise_identification.hpp"

using namespace wheelins;

namespace {

/// Non-overlapping Allan variance of one axis at cluster size m, by the definition.
double batch_allan(const std::vector<double>& y, std::size_t m) {
  std::vector<double> means;
  for (std::size_t k = 0; k + m <= y.size(); k += m) {
    double s = 0.0;
    for (std::size_t j = 0; j < m; ++j) s += y[k + j];
    means.push_back(s / static_cast<double>(m));
  }
  double sum = 0.0;
  for (std::size_t k = 1; k < means.size(); ++k) sum += (means[k] - means[k - 1]) * (means[k] - means[k - 1]);
  return sum / (2.0 * static_cast<double>(means.size() - 1));
}

}  // namespace

TEST(NoiseIdentification, AllanVarianceEqualsTheBatchDefinition) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::vector<double> x;
  AllanAccumulator a;
  double walk = 0.0;
  for (int k = 0; k < 6000; ++k) {
    walk += 0.01 * n01(rng);
    const double v = 0.5 * n01(rng) + walk + 0.3;
    x.push_back(v);
    a.add(Vec3(v, 2 * v, -v), 0.005);
  }
  for (int level = 0; level < 10; ++level) {
    const double want = batch_allan(x, std::size_t(1) << level);
    EXPECT_NEAR(a.variance(level).x(), want, 1e-12 * want) << "level " << level;
    EXPECT_NEAR(a.variance(level).y(), 4 * want, 4e-12 * want) << "level " << level;
    EXPECT_NEAR(a.tau(level), 0.005 * (1 << level), 1e-12);
  }
}

TEST(NoiseIdentification, WhiteNoiseDensityAndABoundOnTheBiasInstabilityFrom30s) {
  // A gyro at rest: 0.24 deg/sqrt(h) of white noise, 200 Hz, 30 s, constant bias.
  const double arw = 0.24 * kDeg / 60.0, dt = 0.005;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n01(0.0, 1.0);
  AllanAccumulator a;
  for (int k = 0; k < 6000; ++k) {
    Vec3 y;
    for (int i = 0; i < 3; ++i) y[i] = 0.01 + arw / std::sqrt(dt) * n01(rng);
    a.add(y, dt);
  }
  const SensorNoiseEstimate e = estimate_sensor_noise(a);
  ASSERT_TRUE(e.valid);
  EXPECT_NEAR(e.white, arw, 0.03 * arw);
  EXPECT_NEAR(e.duration, 30.0, 1e-9);
  // White noise only: the Allan deviation keeps falling, the floor is not reached and the
  // bias instability figure is a bound, about N / sqrt(tau_max) / 0.664.
  EXPECT_FALSE(e.floor_reached);
  EXPECT_GT(e.bias_tau, 2.0);  // the longest cluster time with 8 differences in 30 s
  EXPECT_NEAR(e.bias_instability, arw / std::sqrt(e.bias_tau) / 0.664, 0.35 * e.bias_instability);
}

TEST(NoiseIdentification, AVibrationDoesNotReadAsAngleRandomWalk) {
  // The real car standing with its engine running: 14 s at 120 Hz, a 22.4 Hz vibration of
  // 0.05 rad/s on every axis over a white noise of 0.5 deg/sqrt(h). At the sample interval
  // the vibration reads as an angle random walk of several deg/sqrt(h); it does not
  // integrate into an angle, and the white noise is read where it has averaged out.
  const double arw = 0.5 * kDeg / 60.0, dt = 1.0 / 120.0, f = 22.4, amp = 0.05;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n01(0.0, 1.0);
  AllanAccumulator a;
  for (int k = 0; k < 1680; ++k) {
    Vec3 y;
    for (int i = 0; i < 3; ++i)
      y[i] = amp * std::sin(2.0 * kPi * f * k * dt + i) + arw / std::sqrt(dt) * n01(rng);
    a.add(y, dt);
  }
  const SensorNoiseEstimate e = estimate_sensor_noise(a);
  ASSERT_TRUE(e.valid);
  EXPECT_GT(std::sqrt(a.variance(0).mean() * a.tau(0)), 3.0 * arw);  // what tau0 would give
  EXPECT_NEAR(e.white, arw, 0.2 * arw);
  EXPECT_GT(e.white_tau, 0.1);
  EXPECT_LE(e.white_tau, kWhiteTauMax);
}

TEST(NoiseIdentification, WhiteNoiseIsReadAtTheSampleIntervalWhenNothingElseIsThere) {
  // Pure white noise: every level agrees within its scatter and the shortest, the most
  // certain, is taken (over 20 records, none of them read at a longer cluster time).
  const double n = 0.004, dt = 0.005;
  std::normal_distribution<double> n01(0.0, 1.0);
  for (int seed = 0; seed < 20; ++seed) {
    std::mt19937_64 rng(100 + seed);
    AllanAccumulator a;
    for (int k = 0; k < 4000; ++k) a.add(Vec3(n01(rng), n01(rng), n01(rng)) * (n / std::sqrt(dt)), dt);
    const SensorNoiseEstimate e = estimate_sensor_noise(a);
    EXPECT_NEAR(e.white_tau, dt, 1e-9) << "seed " << seed;
    EXPECT_NEAR(e.white, n, 0.05 * n) << "seed " << seed;
  }
}

TEST(NoiseIdentification, BiasInstabilityFloorIsFoundWhenTheRecordIsLongEnough) {
  // White noise N plus a rate random walk K: sigma_A^2 = N^2 / tau + K^2 tau / 3, whose
  // minimum lies at tau* = sqrt(3) N / K (here 1 s) inside the 200 s record.
  const double dt = 0.005, N = 0.004, K = std::sqrt(3.0) * N / 1.0;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n01(0.0, 1.0);
  AllanAccumulator a;
  Vec3 b = Vec3::Zero();
  for (int k = 0; k < 40000; ++k) {
    Vec3 y;
    for (int i = 0; i < 3; ++i) {
      b[i] += K * std::sqrt(dt) * n01(rng);
      y[i] = b[i] + N / std::sqrt(dt) * n01(rng);
    }
    a.add(y, dt);
  }
  const SensorNoiseEstimate e = estimate_sensor_noise(a);
  EXPECT_TRUE(e.floor_reached);
  EXPECT_GT(e.bias_tau, 0.25);
  EXPECT_LT(e.bias_tau, 4.0);
  const double min_sigma = std::sqrt(N * N / 1.0 + K * K * 1.0 / 3.0);
  EXPECT_NEAR(e.bias_instability, min_sigma / 0.664, 0.3 * min_sigma / 0.664);
  EXPECT_NEAR(e.white, N, 0.03 * N);
}

TEST(NoiseIdentification, CovarianceMatchingFindsTheVelocityRandomWalkAndEachAxisNoise) {
  // A closed loop: a 3-axis velocity random walk of density q_true observed at 2 Hz with
  // per-axis noise R_true, filtered by a Kalman filter that uses the matcher's q and R.
  // Starting from wrong figures (q 100x too small, R 4x too large in sigma), the matcher
  // must land near the truth on every axis.
  const double dt = 0.5, vrw_true = 2.0 / 60.0;
  const Vec3 r_true(0.02 * 0.02, 0.015 * 0.015, 0.03 * 0.03);
  const Vec3 r_nominal(0.03 * 0.03, 0.02 * 0.02, 0.02 * 0.02);
  for (const double vrw_start : {0.2 / 60.0, 6.0 / 60.0}) {
    VelocityNoiseMatcher m;
    VelocityNoiseMatcher::Options opt;
    opt.window = 200;
    opt.r_floor_fraction = 0.25;
    m.reset(opt, vrw_start, 0.1 / 60.0, r_nominal);
    std::mt19937_64 rng(5);
    std::normal_distribution<double> n01(0.0, 1.0);
    Vec3 v = Vec3::Zero(), v_hat = Vec3::Zero(), P = Vec3::Constant(0.01);
    for (int k = 0; k < 20000; ++k) {
      for (int i = 0; i < 3; ++i) v[i] += vrw_true * std::sqrt(dt) * n01(rng);
      const double q = m.vrw() * m.vrw();
      const Vec3 r = m.r_diag();
      P.array() += q * dt;
      Vec3 z, dz, S;
      for (int i = 0; i < 3; ++i) {
        z[i] = v[i] + std::sqrt(r_true[i]) * n01(rng);
        dz[i] = v_hat[i] - z[i];
        S[i] = P[i] + r[i];
        const double K = P[i] / S[i];
        v_hat[i] -= K * dz[i];
        P[i] *= (1 - K);
      }
      m.add(dz, S, dt);
    }
    SCOPED_TRACE(vrw_start * 60);
    EXPECT_NEAR(m.vrw(), vrw_true, 0.15 * vrw_true);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(std::sqrt(m.r_diag()[i]), std::sqrt(r_true[i]), 0.2 * std::sqrt(r_true[i])) << "axis " << i;
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(m.nis_axes()[i], 1.0, 0.15);
  }
}

TEST(NoiseIdentification, CovarianceMatchingNeverGoesBelowItsFloors) {
  VelocityNoiseMatcher m;
  VelocityNoiseMatcher::Options opt;
  opt.window = 20;
  m.reset(opt, 1.0 / 60.0, 0.5 / 60.0, Vec3(1e-4, 1e-4, 1e-4));
  for (int k = 0; k < 200; ++k) m.add(Vec3::Zero(), Vec3::Constant(2e-4), 0.5);  // innovations of 0
  EXPECT_NEAR(m.vrw(), 0.5 / 60.0, 1e-12);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(m.r_diag()[i], 0.25 * 1e-4, 1e-15);
}

TEST(NoiseIdentification, BiasInstabilityFollowsTheCorrectionsWithinFloorAndPrior) {
  const double tau = 3600.0, dt = 0.5;
  std::mt19937_64 rng(9);
  std::normal_distribution<double> n01(0.0, 1.0);
  const double sigma_true = 20.0 * kDeg / 3600.0;  // a random walk of 2 sigma^2 / tau
  const double q = 2.0 * sigma_true * sigma_true / tau;
  BiasInstabilityMatcher m;
  m.reset(100, 200.0 * kDeg / 3600.0, 5.0 * kDeg / 3600.0, tau);
  EXPECT_DOUBLE_EQ(m.sigma(), 200.0 * kDeg / 3600.0);
  for (int k = 0; k < 5000; ++k) {
    // The largest of three axes' corrections: E[max^2] of 3 normals is about 1.9 sigma^2.
    Vec3 c;
    for (int i = 0; i < 3; ++i) c[i] = std::sqrt(q * dt / 1.9) * n01(rng);
    m.add(c, dt);
  }
  EXPECT_NEAR(m.sigma(), sigma_true, 0.3 * sigma_true);
  for (int k = 0; k < 2000; ++k) m.add(Vec3::Zero(), dt);
  EXPECT_DOUBLE_EQ(m.sigma(), 5.0 * kDeg / 3600.0);
  for (int k = 0; k < 2000; ++k) m.add(Vec3::Constant(1.0), dt);
  EXPECT_DOUBLE_EQ(m.sigma(), 200.0 * kDeg / 3600.0);
}
