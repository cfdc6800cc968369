// The simulator's chip error model alone (sim/chip_errors.hpp, sim/draws.hpp): each
// effect switched on by itself on a constant true rate, against its definition in
// docs/simulator.md (the deterministic ones exactly, the random ones statistically
// over enough samples that a wrong sigma or correlation time fails), the
// independence of the random streams, the sensor-fault events on a chip's output,
// and the drawn chip parameters.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "wheelins/sim/chip_errors.hpp"
#include "wheelins/sim/draws.hpp"
#include "wheelins/sim/faults.hpp"

using namespace wheelins;
using namespace wheelins::sim;

namespace {

/// A configuration with only `effects` on.
SimConfig only(std::set<std::string> effects) {
  SimConfig cfg;
  cfg.effects = std::move(effects);
  cfg.seed = 7;
  return cfg;
}

struct Series {
  std::vector<Vec3> w, f;
};

/// n samples of the chip on the true rates (w, f), temperature rise dT.
Series run(const SimConfig& cfg, const ChipModel& m, int n, const Vec3& w, const Vec3& f,
           double dT = 0.0) {
  ChipErrors e(cfg, m);
  Series s;
  for (int k = 0; k < n; ++k) {
    Vec3 wm, fm;
    e.apply(dT, w, f, wm, fm, 0.0);
    s.w.push_back(wm);
    s.f.push_back(fm);
  }
  return s;
}

double stddev(const std::vector<double>& x) {
  double m = 0.0, v = 0.0;
  for (double a : x) m += a;
  m /= static_cast<double>(x.size());
  for (double a : x) v += (a - m) * (a - m);
  return std::sqrt(v / static_cast<double>(x.size() - 1));
}

const Vec3 kRate(0.3, -1.2, 0.05), kForce(0.4, -0.1, -9.8);

}  // namespace

TEST(SimChipErrors, DeterministicEffectsAreExact) {
  // Turn-on bias, scale factor / misalignment and temperature: wm = T w + b + c dT.
  SimConfig cfg = only({});
  ChipModel m;
  m.name = "left-C1";
  m.gyro_bias = Vec3(1e-3, -2e-3, 3e-3);
  m.accel_bias = Vec3(0.01, 0.02, -0.03);
  m.gyro_T << 1.001, 2e-4, -1e-4, 3e-4, 0.998, 5e-5, -2e-4, 1e-4, 1.0005;
  m.accel_T = m.gyro_T.transpose();
  m.gyro_tempco = Vec3(1e-5, 2e-5, -3e-5);
  m.accel_tempco = Vec3(1e-3, -1e-3, 2e-3);
  const double dT = 4.0;
  const Series s = run(cfg, m, 3, kRate, kForce, dT);
  const Vec3 bg = m.gyro_bias + m.gyro_tempco * dT, ba = m.accel_bias + m.accel_tempco * dT;
  for (int k = 0; k < 3; ++k) {
    EXPECT_TRUE(s.w[k].isApprox(m.gyro_T * kRate + bg, 1e-15));
    EXPECT_TRUE(s.f[k].isApprox(m.accel_T * kForce + ba, 1e-15));
  }
  // Bias steps (sensor faults) add to the bias, which gyro_bias() reports.
  ChipErrors e(cfg, m);
  Vec3 wm, fm;
  const Vec3 step_g(0.0, 0.0, 0.5 * kDeg), step_a(0.2, 0.0, 0.0);
  e.apply(dT, kRate, kForce, wm, fm, 0.0, &step_g, &step_a);
  EXPECT_TRUE(e.gyro_bias().isApprox(bg + step_g, 1e-15));
  EXPECT_TRUE(e.accel_bias().isApprox(ba + step_a, 1e-15));
  EXPECT_TRUE(wm.isApprox(m.gyro_T * kRate + bg + step_g, 1e-15));
}

TEST(SimChipErrors, WhiteNoiseHasTheDatasheetDensity) {
  // ARW / VRW: per-sample sigma = density / sqrt(dt), each axis, zero mean.
  const SimConfig cfg = only({"arw", "vrw"});
  ChipModel m;
  m.name = "body-C2";
  const Series s = run(cfg, m, 40000, kRate, kForce);
  const double dt = 1.0 / cfg.rate_hz;
  for (int i = 0; i < 3; ++i) {
    std::vector<double> gw, fa;
    for (std::size_t k = 0; k < s.w.size(); ++k) {
      gw.push_back(s.w[k][i] - kRate[i]);
      fa.push_back(s.f[k][i] - kForce[i]);
    }
    // 40 000 samples: the sample sigma is within 1 % (1 sigma 0.35 %).
    EXPECT_NEAR(stddev(gw), cfg.errors.gyro_arw / std::sqrt(dt), 0.01 * cfg.errors.gyro_arw / std::sqrt(dt));
    EXPECT_NEAR(stddev(fa), cfg.errors.accel_vrw / std::sqrt(dt), 0.01 * cfg.errors.accel_vrw / std::sqrt(dt));
  }
}

TEST(SimChipErrors, GaussMarkovBiasHasItsSigmaAndCorrelationTime) {
  SimConfig cfg = only({"gyro_gm"});
  cfg.errors.gyro_gm_tau = 2.0;  // short, so that 1000 s hold 500 correlation times
  ChipModel m;
  m.name = "right-C3";
  const double sigma = cfg.errors.gyro_gm_sigma;
  m.gyro_gm0 = Vec3(sigma, -sigma, 0.5 * sigma);  // a stationary start
  const int n = static_cast<int>(1000.0 * cfg.rate_hz);
  const Series s = run(cfg, m, n, Vec3::Zero(), kForce);
  const int lag = static_cast<int>(cfg.errors.gyro_gm_tau * cfg.rate_hz);  // one tau
  for (int i = 0; i < 3; ++i) {
    std::vector<double> b;
    for (const Vec3& w : s.w) b.push_back(w[i]);
    const double sd = stddev(b);
    EXPECT_NEAR(sd, sigma, 0.15 * sigma) << "axis " << i;
    double c0 = 0.0, c1 = 0.0;
    for (int k = 0; k + lag < n; ++k) {
      c0 += b[k] * b[k];
      c1 += b[k] * b[k + lag];
    }
    EXPECT_NEAR(c1 / c0, std::exp(-1.0), 0.12) << "axis " << i;  // rho(tau) = 1/e
  }
  // The accelerometer is untouched with accel_gm off.
  for (const Vec3& f : s.f) EXPECT_EQ(f, kForce);
}

TEST(SimChipErrors, SaturationClipsAndQuantizationRounds) {
  const SimConfig cfg = only({"saturation", "quantization"});
  ChipModel m;
  m.name = "left-C4";
  const ErrorParams& e = cfg.errors;
  const Vec3 w(2.5 * e.gyro_range, -3.0 * e.gyro_range, 0.123456);
  const Vec3 f(-2.0 * e.accel_range, 0.7654321, 1.5 * e.accel_range);
  const Series s = run(cfg, m, 1, w, f);
  EXPECT_DOUBLE_EQ(s.w[0].x(), std::nearbyint(e.gyro_range / e.gyro_lsb) * e.gyro_lsb);
  EXPECT_DOUBLE_EQ(s.w[0].y(), -std::nearbyint(e.gyro_range / e.gyro_lsb) * e.gyro_lsb);
  EXPECT_DOUBLE_EQ(s.f[0].x(), -std::nearbyint(e.accel_range / e.accel_lsb) * e.accel_lsb);
  for (int i = 0; i < 3; ++i) {
    const double qg = s.w[0][i] / e.gyro_lsb, qa = s.f[0][i] / e.accel_lsb;
    EXPECT_NEAR(qg, std::nearbyint(qg), 1e-9);  // a whole number of LSBs
    EXPECT_NEAR(qa, std::nearbyint(qa), 1e-9);
  }
  EXPECT_LE(std::abs(s.w[0].z() - w.z()), 0.5 * e.gyro_lsb + 1e-15);
  EXPECT_LE(std::abs(s.f[0].y() - f.y()), 0.5 * e.accel_lsb + 1e-15);
}

TEST(SimChipErrors, RandomStreamsAreIndependentAndRepeatable) {
  ChipModel m;
  m.name = "left-C1";
  const Series a = run(only({"arw"}), m, 50, kRate, kForce);
  const Series b = run(only({"arw"}), m, 50, kRate, kForce);
  const Series c = run(only({"arw", "vrw", "accel_gm"}), m, 50, kRate, kForce);
  for (int k = 0; k < 50; ++k) {
    EXPECT_EQ(a.w[k], b.w[k]);  // the same seed and chip: the same numbers
    EXPECT_EQ(a.w[k], c.w[k]);  // switching accelerometer effects on leaves the gyro alone
  }
  ChipModel other = m;
  other.name = "left-C2";
  const Series d = run(only({"arw"}), other, 50, kRate, kForce);
  int same = 0;
  for (int k = 0; k < 50; ++k) same += a.w[k] == d.w[k];
  EXPECT_EQ(same, 0);  // another chip: another stream
}

TEST(SimChipErrors, SensorFaultsActOnTheirChipAndInterval) {
  std::vector<FaultEvent> faults = {parse_fault_spec("dropout:left-C1:10:12"),
                                    parse_fault_spec("gyro-bias-jump:left-wheel:20:end:axis=z,value=0.5"),
                                    parse_fault_spec("stuck:left-C1:30:31:sensor=accel,axis=y")};
  ChipFaults c1(faults, "left-wheel", "left-C1"), c2(faults, "left-wheel", "left-C2"),
      body(faults, "body", "body-C1");
  EXPECT_FALSE(c1.dropped(9.995));
  EXPECT_TRUE(c1.dropped(10.0));
  EXPECT_TRUE(c1.dropped(11.995));
  EXPECT_FALSE(c1.dropped(12.0));
  EXPECT_FALSE(c2.dropped(11.0));  // only the chip named
  Vec3 g, a;
  EXPECT_FALSE(c2.steps(19.99, g, a));
  EXPECT_TRUE(c2.steps(20.0, g, a));  // the group's chips
  EXPECT_DOUBLE_EQ(g.z(), 0.5 * kDeg);
  EXPECT_EQ(a, Vec3::Zero());
  EXPECT_FALSE(body.steps(25.0, g, a));
  // Stuck: the axis repeats its last output before the start; the others move on.
  Vec3 wm(1, 2, 3), fm(4, 5, 6);
  c1.hold(29.995, wm, fm);
  EXPECT_EQ(fm, Vec3(4, 5, 6));
  wm = Vec3(7, 8, 9);
  fm = Vec3(10, 11, 12);
  c1.hold(30.0, wm, fm);
  EXPECT_EQ(fm, Vec3(10, 5, 12));
  EXPECT_EQ(wm, Vec3(7, 8, 9));
  fm = Vec3(13, 14, 15);
  c1.hold(31.0, wm, fm);  // over
  EXPECT_EQ(fm, Vec3(13, 14, 15));
}

TEST(SimChipErrors, DrawnChipsFollowTheirSigmasAndSwitches) {
  // Everything off: an error-free chip.
  const ChipModel zero = draw_chip(only({}), "left-C1");
  EXPECT_EQ(zero.gyro_bias, Vec3::Zero());
  EXPECT_EQ(zero.gyro_T, Mat3::Identity());
  EXPECT_EQ(zero.accel_tempco, Vec3::Zero());
  // Scale factors without misalignment: a diagonal T.
  const ChipModel sf = draw_chip(only({"scale_factor"}), "left-C1");
  EXPECT_NE(sf.gyro_T.diagonal(), Vec3::Ones());
  EXPECT_EQ(sf.gyro_T - Mat3(sf.gyro_T.diagonal().asDiagonal()), Mat3::Zero());
  // Over many seeds, the turn-on biases have the configured sigma; each draw does not
  // depend on the other effects.
  std::vector<double> bg, ba;
  for (std::uint64_t seed = 1; seed <= 300; ++seed) {
    SimConfig cfg = only({"gyro_bias", "accel_bias"});
    cfg.seed = seed;
    const ChipModel c = draw_chip(cfg, "right-C2");
    cfg.effects.insert("scale_factor");
    EXPECT_EQ(draw_chip(cfg, "right-C2").gyro_bias, c.gyro_bias);
    for (int i = 0; i < 3; ++i) {
      bg.push_back(c.gyro_bias[i]);
      ba.push_back(c.accel_bias[i]);
    }
  }
  const ErrorParams e;
  EXPECT_NEAR(stddev(bg), e.gyro_bias, 0.1 * e.gyro_bias);  // 900 draws: 1 sigma 2.4 %
  EXPECT_NEAR(stddev(ba), e.accel_bias, 0.1 * e.accel_bias);
}
