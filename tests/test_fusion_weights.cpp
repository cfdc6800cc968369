// The reference weights of eq. (8) from each subsystem's own uncertainty
// (fusion/aids/position_constraint/reference_weights.hpp): the variance of a subsystem's reference point, the
// averaged inverse-variance weights, a module leaving and rejoining the mean, the
// record over time (weights.csv) and the run configuration's keys. The end-to-end case
// (a poor chip counts less) is FusionFaults.APoorChipCountsLessWithWeightsFromTheCovariance.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "io_test_util.hpp"
#include "wheelins/fusion/centralized.hpp"
#include "wheelins/fusion/aids/position_constraint/reference_weights.hpp"
#include "wheelins/run/run_config.hpp"

using namespace wheelins;
namespace fs = std::filesystem;

namespace {

FusionOptions covariance_weighting(double window = 60.0) {
  FusionOptions o;
  o.weighting = ReferenceWeighting::kCovariance;
  o.weight_window = window;
  return o;
}

}  // namespace

TEST(JointCovarianceCondition, TheMeanYawScaleFactorIsHeldAndTheDifferencesStay) {
  // Three independent yaw-rate scale factors of variance s2 (one state of each IMU's block):
  // conditioned on their mean (CentralizedFilter::hold_common_yaw_scale_factor), each keeps
  // 2/3 of its variance and the mean has none left (to its floor r = 1e-10); a second
  // conditioning changes nothing; other states are untouched.
  auto joint = make_joint_covariance(3);
  const double s2 = 3000e-6 * 3000e-6;
  Mat21 P = Mat21::Identity() * 1e-4;
  P(SG + 2, SG + 2) = s2;
  for (int i = 0; i < 3; ++i) joint->set_block(i, P);
  std::array<Eigen::Matrix<double, 1, kStateDim>, kMaxCentralized> h{};
  for (int i = 0; i < 3; ++i) {
    h[i].setZero();
    h[i](SG + 2) = 1.0 / 3.0;
  }
  joint->condition(h);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(joint->block(i)(SG + 2, SG + 2), s2 * 2.0 / 3.0, 1e-3 * s2);
    EXPECT_EQ(joint->block(i)(V, V), 1e-4);
  }
  const Mat21 before = joint->block(1);
  joint->condition(h);
  EXPECT_EQ(joint->block(1), before) << "the mean's variance is below the floor already";
}

TEST(JointCovarianceCondition, TheCommonYawScaleFactorWeighsEachImuByItsPriorVariance) {
  // Two Wheel-IMUs (their yaw-rate scale factor the mean of two axes: half the variance of
  // one) and a Body-IMU (one axis), equal figures: 0.4, 0.4, 0.2, the mean of least variance.
  const double p = 1e-6;
  auto w = inverse_variance_weights({p / 2, p / 2, p}, 3);
  EXPECT_NEAR(w[0], 0.4, 1e-12);
  EXPECT_NEAR(w[1], 0.4, 1e-12);
  EXPECT_NEAR(w[2], 0.2, 1e-12);
  EXPECT_EQ(w[3], 0.0);
  // A chip with three times the scale-factor figure counts a ninth; one without such states
  // (a Wheel-INS not estimating them) none.
  w = inverse_variance_weights({p / 2, 9 * p / 2, 0.0}, 3);
  EXPECT_NEAR(w[0], 0.9, 1e-12);
  EXPECT_NEAR(w[1], 0.1, 1e-12);
  EXPECT_EQ(w[2], 0.0);
  w = inverse_variance_weights({0.0, 0.0}, 2);
  EXPECT_EQ(w[0] + w[1], 0.0);
}

TEST(ReferenceWeights, VarianceOfTheReferencePointIsItsHorizontalTrace) {
  // o = r_b + a heading lever: H has I in the position block and a column in phi_z.
  ReferencePointModel r;
  r.H.block<3, 3>(0, P).setIdentity();
  r.H(0, PHI + 2) = -0.5;
  r.H(1, PHI + 2) = 1.5;
  Mat21 cov = Mat21::Zero();
  cov.block<3, 3>(P, P) = Vec3(1.0, 4.0, 9.0).asDiagonal();
  cov(PHI + 2, PHI + 2) = 0.01;
  cov(P, PHI + 2) = cov(PHI + 2, P) = 0.02;
  // tr of the top 2x2 of H P H^T: (1 + 0.25 * 0.01 - 2 * 0.5 * 0.02) + (4 + 2.25 * 0.01)
  const double expected = 1.0 + 0.0025 - 0.02 + 4.0 + 0.0225;
  EXPECT_NEAR(reference_point_variance(r, cov), expected, 1e-12);
  const Mat3 full = r.H * cov * r.H.transpose();
  EXPECT_NEAR(reference_point_variance(r, cov), full(0, 0) + full(1, 1), 1e-12);
}

TEST(ReferenceWeights, InverseVarianceAveragedOverTheWindow) {
  ReferenceWeights w(covariance_weighting(10.0), {0.5, 0.5});
  ASSERT_TRUE(w.from_covariance());
  w.observe(0, 1.0, true);
  w.observe(1, 4.0, true);
  EXPECT_DOUBLE_EQ(w.weight(0), 1.0);
  EXPECT_DOUBLE_EQ(w.weight(1), 0.25);
  // The next epoch moves the average by a tenth of the change, not all of it.
  w.observe(0, 2.0, true);
  EXPECT_DOUBLE_EQ(w.weight(0), 1.0 / 1.1);
  // A variance of zero is floored: no subsystem's o is exact.
  ReferenceWeights z(covariance_weighting(), {0.5, 0.5});
  z.observe(0, 0.0, true);
  EXPECT_DOUBLE_EQ(z.weight(0), 1.0 / ReferenceWeights::kMinVariance);
}

TEST(ReferenceWeights, AModuleThatRejoinsStartsAfreshFromItsNewCovariance) {
  ReferenceWeights w(covariance_weighting(10.0), {0.5, 0.5});
  for (int k = 0; k < 100; ++k) w.observe(0, 1.0, true);
  w.observe(0, 0.0, false);  // out (fault handling): no average kept
  w.observe(0, 9.0, true);   // back, restarted with a larger covariance
  EXPECT_DOUBLE_EQ(w.weight(0), 1.0 / 9.0);
}

TEST(ReferenceWeights, FixedWeightsAreKeptAndRecorded) {
  FusionOptions o;
  ReferenceWeights w(o, {0.25, 0.75});
  EXPECT_FALSE(w.from_covariance());
  w.observe(0, 100.0, true);  // ignored
  EXPECT_DOUBLE_EQ(w.weight(0), 0.25);
  EXPECT_DOUBLE_EQ(w.weight(1), 0.75);
  std::array<double, kMaxModules> k{};
  k[0] = 0.25;
  k[1] = 0.75;
  w.record(10.0, k);
  k[0] = 0.0;  // left out at this epoch
  k[1] = 1.0;
  w.record(11.0, k);
  ASSERT_EQ(w.history().size(), 2u);
  const std::vector<WeightSummary> s = summarize_weights(w.history(), 2);
  EXPECT_DOUBLE_EQ(s[0].mean, 0.25);
  EXPECT_DOUBLE_EQ(s[0].counted, 0.5);
  EXPECT_DOUBLE_EQ(s[1].min, 0.75);
  EXPECT_DOUBLE_EQ(s[1].max, 1.0);
  EXPECT_EQ(weights_csv(w.history(), {"left-C1", "right-C1"}),
            "t,left-C1,right-C1\n10.000,0.250000,0.750000\n11.000,0.000000,1.000000\n");
  const std::string text = weights_report(s, w.history().size(), {"left-C1", "right-C1"}, o);
  EXPECT_NE(text.find("equal"), std::string::npos) << text;
  EXPECT_NE(text.find("left-C1      0.250 [0.250, 0.250]  (counted in 50.0 % of the epochs)"),
            std::string::npos)
      << text;
}

TEST(ReferenceWeights, RunConfigurationChoosesTheWeighting) {
  const iotest::ScratchDir dir;
  const fs::path cfg = dir / "w.yaml";
  iotest::write_text(cfg, "dataset: m.yaml\nfusion: {weights: covariance, weight_window_epochs: 30}\n");
  RunConfig c = load_run_config(cfg, {});
  EXPECT_EQ(c.nav.fusion.weighting, ReferenceWeighting::kCovariance);
  EXPECT_DOUBLE_EQ(c.nav.fusion.weight_window, 30.0);
  EXPECT_TRUE(c.nav.fusion.weights.empty());
  iotest::write_text(cfg, "dataset: m.yaml\nfusion: {weights: equal}\n");
  EXPECT_EQ(load_run_config(cfg, {}).nav.fusion.weighting, ReferenceWeighting::kFixed);
  iotest::write_text(cfg, "dataset: m.yaml\nfusion: {weights: [1, 2]}\n");
  c = load_run_config(cfg, {});
  EXPECT_EQ(c.nav.fusion.weighting, ReferenceWeighting::kFixed);
  EXPECT_EQ(c.nav.fusion.weights, (std::vector<double>{1, 2}));
  iotest::write_text(cfg, "dataset: m.yaml\nfusion: {weights: inverse}\n");
  EXPECT_HAS(iotest::error_of([&] { load_run_config(cfg, {}); }),
             "fusion.weights: expected equal, covariance or standalone");
  iotest::write_text(cfg, "dataset: m.yaml\nfusion: {weights: standalone}\n");
  EXPECT_EQ(load_run_config(cfg, {}).nav.fusion.weighting, ReferenceWeighting::kStandalone);
  iotest::write_text(cfg, "dataset: m.yaml\nfusion: {weights: covariance, weight_window_epochs: 0}\n");
  EXPECT_HAS(iotest::error_of([&] { load_run_config(cfg, {}); }), "fusion.weight_window_epochs: must be in");
  EXPECT_THROW(weighting_from_name("x"), InputError);
  // Fixed weights and weights from the covariance together are refused by the options.
  NavigatorOptions n;
  n.fusion.weighting = ReferenceWeighting::kCovariance;
  n.fusion.weights = {1.0, 1.0};
  EXPECT_THROW(n.validate(), InputError);
  n.fusion.weighting = ReferenceWeighting::kStandalone;
  EXPECT_THROW(n.validate(), InputError);
}

// The constraint-free drift model against its closed forms at a constant speed v: the angle
// random walk alone gives a lateral variance v^2 q t^3 / 3, a constant bias of variance s2
// v^2 s2 t^4 / 4 (both the exact integrals of e' = v psi, psi' = b + w).
TEST(StandaloneDrift, LateralVarianceMatchesTheClosedForms) {
  const double v = 5.0, arw = 0.3 * kDeg / 60.0, T = 600.0;
  StandaloneDrift a;
  a.start(0.0, 0.0, 0.0, 0.0);
  for (int k = 1; k <= 600; ++k) a.step(k * 1.0, 0.0, v, arw, 0.0, 3600.0);
  EXPECT_NEAR(a.lateral_variance() / (v * v * arw * arw * T * T * T / 3.0), 1.0, 2e-3);
  StandaloneDrift b;
  const double s = 10.0 * kDeg / 3600.0;
  b.start(0.0, 0.0, s * s, 0.0);
  b.step(T, 0.0, v, 0.0, 0.0, 3600.0);  // one call, split into 1 s steps inside
  EXPECT_NEAR(b.lateral_variance() / (v * v * s * s * T * T * T * T / 4.0), 1.0, 2e-3);
  EXPECT_DOUBLE_EQ(b.t, T);
  // A bias that wanders (Gauss-Markov of sigma s, from zero) drifts, less than one of that
  // sigma held from the start; standing still adds nothing.
  StandaloneDrift c;
  c.start(0.0, 0.0, 0.0, 0.0);
  c.step(T, 0.0, v, 0.0, s, 3600.0);
  EXPECT_GT(c.lateral_variance(), 0.01 * b.lateral_variance());
  EXPECT_LT(c.lateral_variance(), b.lateral_variance());
  const double before = c.lateral_variance();
  c.step(T + 100.0, 0.0, 0.0, arw, s, 3600.0);
  EXPECT_DOUBLE_EQ(c.lateral_variance(), before);
}

// A yaw-rate scale factor s puts s times the turned angle into the heading: driving at v on
// a circle at yaw rate omega from the start, psi = s omega t, so var(e) = v^2 omega^2 sf2
// t^4 / 4, and the same whether the heading comes in steps of 1 s or at once; driving
// straight it adds nothing, and turning back undoes the heading error it made.
TEST(StandaloneDrift, AScaleFactorDriftsWithTheTurnedAngle) {
  const double v = 5.0, omega = 0.1, sf = 3000e-6, T = 60.0;
  StandaloneDrift a;
  a.start(0.0, 0.0, 0.0, sf * sf);
  for (int k = 1; k <= 60; ++k) a.step(k * 1.0, std::remainder(omega * k, 2.0 * kPi), v, 0.0, 0.0, 3600.0);
  EXPECT_NEAR(a.lateral_variance() / (v * v * omega * omega * sf * sf * T * T * T * T / 4.0), 1.0, 2e-3);
  EXPECT_NEAR(a.P(1, 1) / std::pow(sf * omega * T, 2), 1.0, 1e-9);
  StandaloneDrift straight;
  straight.start(0.0, 1.0, 0.0, sf * sf);
  straight.step(T, 1.0, v, 0.0, 0.0, 3600.0);
  EXPECT_DOUBLE_EQ(straight.lateral_variance(), 0.0);
  StandaloneDrift back;  // a left turn of 0.5 rad, then back to the start's heading
  back.start(0.0, 0.0, 0.0, sf * sf);
  back.step(5.0, 0.5, v, 0.0, 0.0, 3600.0);
  EXPECT_GT(back.P(1, 1), 0.0);
  back.step(10.0, 0.0, v, 0.0, 0.0, 3600.0);
  EXPECT_NEAR(back.P(1, 1), 0.0, 1e-18);
  EXPECT_GT(back.lateral_variance(), 0.0);
}

// A Body-IMU's unmodulated yaw bias makes its drift on its own grow faster than a Wheel-IMU's
// of the same chip, so its weight falls over the run; two Wheel-IMUs of one chip stay equal.
TEST(StandaloneDrift, TheBodyImuCountsLessTheLongerItDrivesOnItsOwn) {
  FusionOptions o;
  o.weighting = ReferenceWeighting::kStandalone;
  ReferenceWeights w(o, {1.0, 1.0, 1.0});
  EXPECT_TRUE(w.from_standalone());
  ImuNoise q;
  q.gyro_arw = 0.25 * kDeg / 60.0;
  q.gyro_bias_std = 10.0 * kDeg / 3600.0;
  const double bias_var0 = std::pow(3.0 * kDeg / 3600.0, 2);
  double body_share_early = 0.0;
  for (int k = 1; k <= 900; ++k) {
    w.observe_standalone(0, k, 0.0, 5.0, q, true, 0.0, 0.0);
    w.observe_standalone(1, k, 0.0, 5.0, q, true, 0.0, 0.0);
    w.observe_standalone(2, k, 0.0, 5.0, q, false, bias_var0, 0.0);
    if (k == 30) body_share_early = w.weight(2) / (w.weight(0) + w.weight(1) + w.weight(2));
  }
  const double body_share = w.weight(2) / (w.weight(0) + w.weight(1) + w.weight(2));
  EXPECT_DOUBLE_EQ(w.weight(0), w.weight(1));
  EXPECT_LT(body_share, 0.1);
  EXPECT_GT(body_share_early, 0.2);
}
