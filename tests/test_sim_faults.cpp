// Simulator fault events: dropouts, bias jumps, stuck axes and wheel slip change exactly
// what they should (against the same run without the fault), the slip physics stays exact,
// bad specs are rejected with the problem named, and scenario.yaml round-trips the events.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>

#include "wheelins/io/manifest.hpp"
#include "wheelins/sim/simulator.hpp"

using namespace wheelins;
using namespace wheelins::sim;
namespace fs = std::filesystem;

namespace {

using Row = std::array<double, 7>;
using Snapshot = std::map<std::string, std::string>;

fs::path temp_dir(const std::string& name) {
  const fs::path p = fs::temp_directory_path() /
                     ("wheelins_test_faults_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  return p;
}

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Relative path -> contents of every file of the dataset `cfg` writes.
Snapshot simulate(const SimConfig& cfg, const std::string& name) {
  const fs::path dir = temp_dir(name);
  Simulation(cfg).write(dir, false, false);
  Snapshot m;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) m[fs::relative(e.path(), dir).string()] = read_file(e.path());
  fs::remove_all(dir);
  return m;
}

/// The 7-column rows of a binary IMU / bias file.
std::vector<Row> rows(const std::string& bytes) {
  std::vector<Row> r(bytes.size() / sizeof(Row));
  std::memcpy(r.data(), bytes.data(), r.size() * sizeof(Row));
  return r;
}
std::string bytes_of(const std::vector<Row>& r) {
  return std::string(reinterpret_cast<const char*>(r.data()), r.size() * sizeof(Row));
}

/// 60 s (30 s static, then the first straight at up to 1.4 m/s), one chip per module.
SimConfig short_config(const std::string& profile) {
  SimConfig cfg;
  cfg.set_profile(profile);
  cfg.duration = 60.0;
  cfg.chips = 1;
  return cfg;
}

/// Seconds since the start of the data of a row (sample k at k / rate).
double tau(const Simulation& sim, const Row& r) { return r[0] - sim.start_time(); }

void expect_input_error(const std::function<void()>& f, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "no InputError (expected one mentioning '" << parts.front() << "')";
  } catch (const InputError& e) {
    const std::string w = e.what();
    for (const auto& p : parts) EXPECT_NE(w.find(p), std::string::npos) << "'" << p << "' not in: " << w;
  }
}

/// Forward speed of wheel g's centre from the vehicle state: v_o + C_v^n (w x p_wheel).
double wheel_centre_speed(const Simulation& sim, int g, double t) {
  const VehicleState st = sim.scenario().state(t);
  const Vec3 v = st.v_inN + st.C_VtoN * st.omega_inV.cross(sim.module(g).truth.p_inV);
  return st.C_VtoN.col(0).dot(v);
}

constexpr double kGlX[4] = {-0.86113631159405257522, -0.33998104358485626480, 0.33998104358485626480,
                            0.86113631159405257522};
constexpr double kGlW[4] = {0.34785484513745385737, 0.65214515486254614263, 0.65214515486254614263,
                            0.34785484513745385737};

}  // namespace

// A dropout removes exactly the samples stamped in [t0, t1) of its chip (all chips of a
// group); without an end the file stops at t0. Every other byte equals the fault-free run's
// (the error model still runs through the gap: same draws afterwards).
TEST(SimFaults, DropoutRemovesExactlyTheIntervalAndNothingElse) {
  const SimConfig base = short_config("datasheet");
  SimConfig cfg = base;
  cfg.faults = {parse_fault_spec("dropout:left-C1:40:45.5"), parse_fault_spec("dropout:body:50")};
  const Simulation sim(cfg);
  const auto a = simulate(base, "drop_base"), b = simulate(cfg, "drop_fault");
  ASSERT_EQ(a.size(), b.size());
  const auto left = rows(a.at("left-wheel-imu/tri_C1_imu.bin")), body = rows(a.at("body-imu/tri_C1_imu.bin"));
  ASSERT_EQ(left.size(), 12000u);
  std::vector<Row> left_kept, body_kept;
  for (const Row& r : left)
    if (!(tau(sim, r) >= 40.0 && tau(sim, r) < 45.5)) left_kept.push_back(r);
  for (const Row& r : body)
    if (tau(sim, r) < 50.0) body_kept.push_back(r);
  EXPECT_EQ(left_kept.size(), 12000u - 1100u);  // 5.5 s at 200 Hz
  EXPECT_EQ(body_kept.size(), 9999u);           // samples at 0.005 .. 49.995 s
  EXPECT_TRUE(b.at("left-wheel-imu/tri_C1_imu.bin") == bytes_of(left_kept));
  EXPECT_TRUE(b.at("body-imu/tri_C1_imu.bin") == bytes_of(body_kept));
  const auto last = rows(b.at("body-imu/tri_C1_imu.bin")).back();
  EXPECT_NEAR(tau(sim, last), 49.995, 1e-9);
  // Everything else is unchanged, byte for byte: the other chips, the error-free streams,
  // the bias logs (the chip's bias exists through the gap), truth, odometer, manifests.
  for (const auto& [k, v] : a) {
    if (k == "left-wheel-imu/tri_C1_imu.bin" || k == "body-imu/tri_C1_imu.bin" || k == "errors.yaml" ||
        k == "scenario.yaml")
      continue;
    EXPECT_TRUE(b.at(k) == v) << k << " changed by a dropout";
  }
  // errors.yaml lists the events with their stamps.
  const YAML::Node e = YAML::Load(b.at("errors.yaml"));
  ASSERT_EQ(e["faults"].size(), 2u);
  EXPECT_EQ(e["faults"][0]["spec"].as<std::string>(), "dropout:left-C1:40:45.5");
  EXPECT_DOUBLE_EQ(e["faults"][0]["stamps_s"][0].as<double>(), sim.start_time() + 40.0);
  EXPECT_EQ(e["faults"][1]["stamps_s"][1].as<std::string>(), "end");
  EXPECT_EQ(YAML::Load(a.at("errors.yaml"))["faults"].size(), 0u);
  // scenario.yaml reproduces the faulted dataset.
  SimConfig again;
  again.apply_yaml(YAML::Load(b.at("scenario.yaml")), "scenario.yaml");
  const auto c = simulate(again, "drop_again");
  for (const auto& [k, v] : b) EXPECT_TRUE(c.at(k) == v) << k << " differs when rerun from scenario.yaml";
}

// A bias jump adds its step to one axis from t0 on (to t1 or the end) and to the bias log;
// nothing else changes. No quantization, so the difference is the step to rounding.
TEST(SimFaults, BiasJumpAddsTheStepFromItsStart) {
  SimConfig base = short_config("datasheet");
  base.disable({"quantization", "saturation"});
  SimConfig cfg = base;
  cfg.faults = {parse_fault_spec("gyro-bias-jump:right-C1:40:end:axis=z,value=0.5"),
                parse_fault_spec("accel-bias-jump:body:35:45:axis=x,value=-0.2")};
  const Simulation sim(cfg);
  const auto a = simulate(base, "jump_base"), b = simulate(cfg, "jump_fault");
  struct Check {
    std::string file;
    int column;  // 1..3 gyro xyz, 4..6 accel xyz
    double step, t0, t1;
  };
  const double gstep = 0.5 * kDeg;
  for (const Check& c : {Check{"right-wheel-imu/tri_C1_imu.bin", 3, gstep, 40.0, 1e9},
                         Check{"errors/right-C1_bias.bin", 3, gstep, 40.0, 1e9},
                         Check{"body-imu/tri_C1_imu.bin", 4, -0.2, 35.0, 45.0},
                         Check{"errors/body-C1_bias.bin", 4, -0.2, 35.0, 45.0}}) {
    const auto ra = rows(a.at(c.file)), rb = rows(b.at(c.file));
    ASSERT_EQ(ra.size(), rb.size()) << c.file;
    int stepped = 0;
    for (std::size_t i = 0; i < ra.size(); ++i) {
      const double t = tau(sim, ra[i]);
      const bool on = t >= c.t0 && t < c.t1;
      stepped += on;
      for (int j = 0; j < 7; ++j) {
        if (j == c.column && on) EXPECT_NEAR(rb[i][j] - ra[i][j], c.step, 1e-12) << c.file << " t " << t;
        else EXPECT_EQ(rb[i][j], ra[i][j]) << c.file << " column " << j << " t " << t;
      }
    }
    EXPECT_GT(stepped, 0) << c.file;
  }
  for (const char* f : {"left-wheel-imu/tri_C1_imu.bin", "ideal/right-wheel_imu.bin", "GINS.bin", "manifest.yaml"})
    EXPECT_TRUE(a.at(f) == b.at(f)) << f;
  const YAML::Node e = YAML::Load(b.at("errors.yaml"));
  EXPECT_DOUBLE_EQ(e["faults"][0]["gyro_bias_step_rad_s"][2].as<double>(), gstep);
  EXPECT_DOUBLE_EQ(e["faults"][1]["accel_bias_step_m_s2"][0].as<double>(), -0.2);
}

// A stuck axis repeats its last value before t0 over [t0, t1); the other axes and the data
// after t1 equal the fault-free run's.
TEST(SimFaults, StuckAxisHoldsItsLastValue) {
  const SimConfig base = short_config("datasheet");
  SimConfig cfg = base;
  cfg.faults = {parse_fault_spec("stuck:body-C1:32:38:sensor=gyro,axis=z"),
                parse_fault_spec("stuck:left-wheel:45:46:sensor=accel,axis=y")};
  const Simulation sim(cfg);
  const auto a = simulate(base, "stuck_base"), b = simulate(cfg, "stuck_fault");
  struct Check {
    std::string file;
    int column;
    double t0, t1;
  };
  for (const Check& c : {Check{"body-imu/tri_C1_imu.bin", 3, 32.0, 38.0},
                         Check{"left-wheel-imu/tri_C1_imu.bin", 5, 45.0, 46.0}}) {
    const auto ra = rows(a.at(c.file)), rb = rows(b.at(c.file));
    ASSERT_EQ(ra.size(), rb.size());
    double held = 0.0;
    std::set<double> original;  // what the axis read without the fault
    for (std::size_t i = 0; i < ra.size(); ++i) {
      const double t = tau(sim, ra[i]);
      const bool on = t >= c.t0 && t < c.t1;
      if (t < c.t0) held = ra[i][c.column];
      for (int j = 0; j < 7; ++j) {
        if (j == c.column && on) {
          EXPECT_EQ(rb[i][j], held) << c.file << " t " << t;
          original.insert(ra[i][j]);
        } else {
          EXPECT_EQ(rb[i][j], ra[i][j]) << c.file << " column " << j << " t " << t;
        }
      }
    }
    EXPECT_GT(original.size(), 3u) << c.file << ": the axis varies without the fault";
  }
  for (const char* f : {"right-wheel-imu/tri_C1_imu.bin", "ideal/body_imu.bin", "errors/body-C1_bias.bin"})
    EXPECT_TRUE(a.at(f) == b.at(f)) << f;
}

// The slip window: 0 outside [t0, t1], 1 inside the ramps, exact derivatives, integral
// (t1 - t0) - ramp; short events get ramps of half their length.
TEST(SimFaults, SlipWindowIsSmoothAndExact) {
  const double t0 = 10.0, t1 = 13.0, r = kSlipRamp;
  EXPECT_EQ(slip_window<3>(t0 - 1e-9, t0, t1).value(), 0.0);
  EXPECT_EQ(slip_window<3>(t1 + 1e-9, t0, t1).value(), 0.0);
  EXPECT_EQ(slip_window<3>(t0 + r, t0, t1).value(), 1.0);
  EXPECT_EQ(slip_window<3>(11.5, t0, t1).value(), 1.0);
  EXPECT_NEAR(slip_window<3>(t0 + 0.5 * r, t0, t1).value(), 0.5, 1e-13);
  EXPECT_LT(slip_window<3>(t0 + 1e-3, t0, t1).value(), 1e-80);  // flat at the ends: ~e^(-r/1ms)
  // Derivatives against central differences, on both ramps.
  const double h = 1e-5;
  for (double t : {10.03, 10.1, 10.17, 12.85, 12.93}) {
    const J w = slip_window<3>(t, t0, t1);
    auto f = [&](double s) { return slip_window<3>(s, t0, t1).value(); };
    auto d1 = [&](double s) { return slip_window<3>(s, t0, t1).deriv(1); };
    auto d2 = [&](double s) { return slip_window<3>(s, t0, t1).deriv(2); };
    EXPECT_NEAR(w.deriv(1), (f(t + h) - f(t - h)) / (2 * h), 1e-6 * std::max(1.0, std::abs(w.deriv(1)))) << t;
    EXPECT_NEAR(w.deriv(2), (d1(t + h) - d1(t - h)) / (2 * h), 1e-5 * std::max(1.0, std::abs(w.deriv(2)))) << t;
    EXPECT_NEAR(w.deriv(3), (d2(t + h) - d2(t - h)) / (2 * h), 1e-4 * std::max(1.0, std::abs(w.deriv(3)))) << t;
  }
  // Integral by Gauss-Legendre on 1 ms steps.
  auto integral = [&](double a, double b, double e0, double e1) {
    double s = 0.0;
    const long n = std::lround((b - a) / 1e-3);
    for (long k = 0; k < n; ++k)
      for (int i = 0; i < 4; ++i)
        s += 0.5e-3 * kGlW[i] * slip_window<3>(a + 1e-3 * (k + 0.5 * (1 + kGlX[i])), e0, e1).value();
    return s;
  };
  EXPECT_NEAR(integral(9.0, 14.0, t0, t1), (t1 - t0) - r, 1e-11);
  EXPECT_NEAR(integral(9.0, 11.0, t0, t0 + 0.3), 0.15, 1e-11);  // ramps of 0.15 s
  EXPECT_NEAR(slip_window<3>(t0 + 0.15, t0, t0 + 0.3).value(), 1.0, 1e-15);
}

// Slip physics (ideal data, flat, no earth rate, mounting and lever arm zero): in the middle
// of the event -R gyro_x is (1 + s) times the wheel-centre speed; the wheel angle is the
// exact integral of its rate; outside the event the data are the fault-free ones (after it,
// the wheel is turned by the extra angle: gyro_x equal, the y/z axes rotated by it).
TEST(SimFaults, SlipChangesTheWheelRateExactly) {
  SimConfig base = short_config("ideal");
  base.duration = 70.0;
  base.start_time = 0.0;  // small times: 1e-5 s central differences below stay accurate
  base.earth_rotation = false;
  base.vehicle.left.mounting_rpy.setZero();
  base.vehicle.right.mounting_rpy.setZero();
  base.vehicle.right.lever_arm_inB.setZero();
  SimConfig cfg = base;
  cfg.faults = {parse_fault_spec("slip:right-wheel:50:54:ratio=0.5"),
                parse_fault_spec("slip:left-wheel:56:59:ratio=-1")};
  const Simulation s0(base), s1(cfg);
  const double t0 = s1.start_time();
  for (int g : {1, 0}) {
    const double ratio = g == 1 ? 0.5 : -1.0, ea = g == 1 ? 50.0 : 56.0, eb = g == 1 ? 54.0 : 59.0;
    // (1) -R gyro_x = (1 + s) v_wc in the middle of the event (sample means on both sides).
    const auto samples = s1.ideal_samples(g, 14000);
    const double R = s1.module(g).radius;
    double max_err = 0.0, min_speed = 1e9;
    for (const ImuSample& s : samples) {
      if (s.t - t0 < ea + 0.3 || s.t - t0 > eb - 0.3) continue;
      double mean_speed = 0.0;
      for (int i = 0; i < 4; ++i)
        mean_speed += 0.5 * kGlW[i] * wheel_centre_speed(s1, g, s.t - s.dt + 0.5 * s.dt * (1.0 + kGlX[i]));
      max_err = std::max(max_err, std::abs(-R * s.dtheta.x() / s.dt - (1.0 + ratio) * mean_speed));
      min_speed = std::min(min_speed, mean_speed);
    }
    std::printf("%s slip %g: max | -R gyro_x - (1+s) v_wheel | = %.3g m/s (speeds >= %.2f m/s)\n",
                Simulation::group_name(g), ratio, max_err, min_speed);
    EXPECT_GT(min_speed, 1.0);
    EXPECT_LT(max_err, 1e-9);
    // (2) The wheel angle: truth() (Gauss-Legendre per sample interval) against a fine
    // integral of the rate difference over the event (4-point Gauss-Legendre on 0.7 ms
    // steps, a grid unrelated to the 5 ms samples), and against slip_extra_angle.
    const double a = t0 + ea, b = t0 + eb, step = 7e-4;
    double fine = 0.0;
    const long n = std::lround(std::ceil((b - a) / step));
    for (long k = 0; k < n; ++k) {
      const double x0 = a + k * step, x1 = std::min(b, x0 + step);
      for (int i = 0; i < 4; ++i) {
        const double t = 0.5 * (x0 + x1) + 0.5 * (x1 - x0) * kGlX[i];
        fine += 0.5 * (x1 - x0) * kGlW[i] * (s1.wheel_rate(g, t) - s0.wheel_rate(g, t));
      }
    }
    const double after = t0 + eb + 1.0;
    const double extra = s1.truth(g, after).wheel_angle - s0.truth(g, after).wheel_angle;
    ModuleModel::SlipEvent ev{a, b, ratio};
    std::printf("%s: extra wheel angle %.12f rad, fine integral %.12f, slip_extra_angle %.12f\n",
                Simulation::group_name(g), extra, fine, s1.slip_extra_angle(g, ev));
    EXPECT_NEAR(extra, fine, 1e-9);
    EXPECT_NEAR(s1.slip_extra_angle(g, ev), fine, 1e-9);
    EXPECT_NEAR(extra, ratio * 1.4 * (eb - ea - kSlipRamp) / R, 0.05 * std::abs(extra));  // ~1.4 m/s
    // (3) Jets against central differences on the ramp (velocity, acceleration, rate).
    for (double t : {a + 0.07, b - 0.12}) {
      const double h = 1e-5;
      const ImuTruth m2 = s1.truth(g, t - 2 * h), m = s1.truth(g, t - h), c = s1.truth(g, t),
                     p = s1.truth(g, t + h), p2 = s1.truth(g, t + 2 * h);
      const Vec3 v_fd = (-p2.p_inN + 8.0 * p.p_inN - 8.0 * m.p_inN + m2.p_inN) / (12 * h);
      const Vec3 a_fd = (-p2.v_inN + 8.0 * p.v_inN - 8.0 * m.v_inN + m2.v_inN) / (12 * h);
      const Vec3 w_fd = rotvec_from_quat(Quat(m.C_StoN.transpose() * p.C_StoN)) / (2 * h);
      EXPECT_LT((v_fd - c.v_inN).norm(), 1e-7) << t;
      EXPECT_LT((a_fd - c.a_inN).norm(), 1e-6 * std::max(1.0, c.a_inN.norm())) << t;
      EXPECT_LT((w_fd - c.omega_nb_inS).norm(), 1e-5 * std::max(1.0, c.omega_nb_inS.norm())) << t;
    }
  }
  // (4) The written data: before each event the wheel's files are the fault-free ones byte
  // for byte, the body and the truth entirely; after the event gyro_x is the same and the
  // y/z components are those of the fault-free run rotated by the extra angle.
  const auto A = simulate(base, "slip_base"), B = simulate(cfg, "slip_fault");
  for (const char* f : {"body-imu/tri_C1_imu.bin", "ideal/body_imu.bin", "GINS.bin", "odo.bin", "manifest.yaml"})
    EXPECT_TRUE(A.at(f) == B.at(f)) << f;
  const double ea = 50.0, eb = 54.0;
  const double extra = s1.truth(1, t0 + 60.0).wheel_angle - s0.truth(1, t0 + 60.0).wheel_angle;
  for (const char* f : {"right-wheel-imu/tri_C1_imu.bin", "ideal/right-wheel_imu.bin"}) {
    const auto ra = rows(A.at(f)), rb = rows(B.at(f));
    ASSERT_EQ(ra.size(), rb.size());
    std::size_t before = 0;
    double max_dev = 0.0;
    const double c = std::cos(extra), sn = std::sin(extra);
    for (std::size_t i = 0; i < ra.size(); ++i) {
      const double t = tau(s1, ra[i]);
      if (t <= ea) {
        EXPECT_TRUE(ra[i] == rb[i]) << f << " t " << t;
        ++before;
      } else if (t > eb + 0.005) {
        // b-frame of the faulted wheel = that of the fault-free one turned by `extra` about
        // x (C_b^v = C0 rot_x(-alpha)): its readings are rot_x(extra) times the others.
        for (int o : {1, 4}) {
          const Vec3 u(ra[i][o], ra[i][o + 1], ra[i][o + 2]), v(rb[i][o], rb[i][o + 1], rb[i][o + 2]);
          const Vec3 rotated(u.x(), c * u.y() - sn * u.z(), sn * u.y() + c * u.z());
          max_dev = std::max(max_dev, (v - rotated).norm());
        }
      }
    }
    EXPECT_EQ(before, 10000u) << f;  // samples at 0.005 .. 50 s
    std::printf("%s after the slip: max |reading - rot_x(extra) fault-free| = %.3g\n", f, max_dev);
    EXPECT_LT(max_dev, 1e-8) << f;
  }
  // The left wheel is locked over [56, 59] s: -R gyro_x ~ 0 in the middle (shown above);
  // errors.yaml states both events' extra angles.
  const YAML::Node e = YAML::Load(B.at("errors.yaml"));
  ASSERT_EQ(e["faults"].size(), 2u);
  EXPECT_NEAR(e["faults"][0]["extra_wheel_angle_rad"].as<double>(), extra, 1e-9);
  EXPECT_LT(e["faults"][1]["extra_wheel_angle_rad"].as<double>(), -40.0);  // -1.4 m/s * 2.8 s / R
}

// Bad specs and YAML entries are rejected with the problem named.
TEST(SimFaults, BadSpecsNameTheProblem) {
  struct Bad {
    std::string spec;
    std::vector<std::string> says;
  };
  const Bad bad[] = {
      {"warp:left-C1:10", {"warp:left-C1:10", "unknown kind 'warp'"}},
      {"dropout:left-C0:10", {"unknown target 'left-C0'"}},
      {"dropout:front-wheel:10", {"unknown target 'front-wheel'"}},
      {"dropout:left-C1:20:10", {"T1", "must be after the start"}},
      {"dropout:left-C1:20:20", {"must be after the start"}},
      {"dropout:left-C1:-5", {"T0", ">= 0", "'-5'"}},
      {"dropout:left-C1:soon", {"T0", "'soon'"}},
      {"dropout:left-C1", {"KIND:TARGET:T0"}},
      {"dropout:left-C1:1:2:3:4", {"too many"}},
      {"gyro-bias-jump:left-C1:10:end:value=0.5", {"axis: missing"}},
      {"gyro-bias-jump:left-C1:10:end:axis=z", {"value: missing"}},
      {"accel-bias-jump:body:10:axis=q,value=1", {"axis", "x, y or z", "'q'"}},
      {"gyro-bias-jump:body:10:axis=x,value=lots", {"value", "deg/s", "'lots'"}},
      {"stuck:body-C1:10:20:axis=z", {"sensor: missing"}},
      {"stuck:body-C1:10:20:axis=z,sensor=baro", {"sensor", "gyro or accel"}},
      {"slip:body:10:20:ratio=0.5", {"slip acts on a wheel", "'body'"}},
      {"slip:left-C1:10:20:ratio=0.5", {"slip acts on a wheel"}},
      {"slip:left-wheel:10:20", {"ratio: missing"}},
      {"slip:left-wheel:10:20:ratio=-1.5", {"ratio", "[-1, 10]"}},
      {"dropout:left-C1:10:20:axis=x", {"axis", "not a key of dropout"}},
      {"slip:left-wheel:10:20:ratio=1,speed=2", {"speed", "unknown key for slip"}},
      {"slip:left-wheel:10:20:ratio=1,ratio=2", {"ratio", "given twice"}},
  };
  for (const Bad& b : bad) {
    auto says = b.says;
    says.push_back("--fault '" + b.spec + "'");
    expect_input_error([&] { parse_fault_spec(b.spec); }, says);
  }
  // Against the data: chips that do not exist, a start after the end of the data.
  SimConfig cfg = short_config("ideal");
  cfg.faults = {parse_fault_spec("dropout:left-C2:10")};
  expect_input_error([&] { (void)Simulation(cfg); }, {"dropout:left-C2:10:end", "no chip left-C2", "1 chip"});
  cfg.faults = {parse_fault_spec("stuck:body:75:80:sensor=accel,axis=x")};
  expect_input_error([&] { (void)Simulation(cfg); }, {"stuck:body:75:80", "outside the data", "0 to 60 s"});
  // YAML: the key path and what was expected.
  auto yaml_error = [&](const std::string& text, const std::vector<std::string>& says) {
    SimConfig c;
    expect_input_error([&] { c.apply_yaml(YAML::Load(text), "'s.yaml'"); }, says);
  };
  yaml_error("faults: {kind: dropout}", {"'s.yaml': faults", "expected a list"});
  yaml_error("faults: [{target: left-C1, start_s: 3}]", {"faults[0].kind: missing"});
  yaml_error("faults: [{kind: dropout, target: left-C1, start_s: 3}, {kind: gyro-bias-jump, target: body, "
             "start_s: 3, axis: x, value: 2}]",
             {"faults[1].value", "unknown key for gyro-bias-jump", "value_deg_s"});
  yaml_error("faults: [{kind: stuck, target: body, start_s: 3, end_s: 2, sensor: gyro, axis: x}]",
             {"faults[0].end_s", "after the start"});
  yaml_error("faults: [{kind: slip, target: left-wheel, start_s: [3], ratio: 1}]", {"faults[0].start_s"});
  yaml_error("faults: [\"dropout:left-C1:x\"]", {"faults[0]", "'dropout:left-C1:x'", "T0"});
}

// The CLI: --fault appends events; a bad one exits non-zero with the message; the summary
// lists the events.
TEST(SimFaults, CliFaultOption) {
  const fs::path dir = temp_dir("cli");
  const fs::path err = temp_dir("cli_err.txt"), out = temp_dir("cli_out.txt");
  const std::string cmd = std::string(WHEELINS_BINARY) + " simulate --profile ideal --chips 1 --duration 40 --out " +
                          dir.string();
  const int rc = std::system((cmd + " --fault slip:body:3:4:ratio=1 2>" + err.string()).c_str());
  EXPECT_NE(rc, 0);
  EXPECT_NE(read_file(err).find("slip acts on a wheel"), std::string::npos) << read_file(err);
  EXPECT_FALSE(fs::exists(dir / "manifest.yaml"));
  const int ok = std::system((cmd + " --fault dropout:left-C1:10:12 --fault 'gyro-bias-jump:body:5:end:axis=x,"
                                    "value=1' >" + out.string())
                                 .c_str());
  EXPECT_EQ(ok, 0);
  const std::string summary = read_file(out);
  EXPECT_NE(summary.find("dropout:left-C1:10:12"), std::string::npos) << summary;
  EXPECT_NE(summary.find("gyro-bias-jump:body:5:end:axis=x,value=1"), std::string::npos) << summary;
  EXPECT_EQ(fs::file_size(dir / "left-wheel-imu" / "tri_C1_imu.bin"), (8000u - 400u) * 56u);
  fs::remove_all(dir);
  fs::remove(err);
  fs::remove(out);
}

// scenario.yaml writes the events back; reading it gives the same events and text again.
// Entries may also be spec strings.
TEST(SimFaults, YamlRoundTrip) {
  SimConfig cfg;
  for (const char* s : {"dropout:left-C1:300:360", "dropout:body:500", "gyro-bias-jump:right-C1:400:end:axis=z,value=0.5",
                        "accel-bias-jump:left-wheel:12.25:13:axis=y,value=-0.03",
                        "stuck:body-C1:200:260:sensor=gyro,axis=z", "slip:left-wheel:150:155:ratio=0.5",
                        "slip:right-wheel:600:603:ratio=-1"})
    cfg.faults.push_back(parse_fault_spec(s));
  EXPECT_EQ(cfg.faults[1].spec(), "dropout:body:500:end");
  EXPECT_EQ(parse_fault_spec(cfg.faults[3].spec()).spec(), cfg.faults[3].spec());
  const std::string text = cfg.to_yaml();
  SimConfig back;
  back.apply_yaml(YAML::Load(text), "scenario.yaml");
  ASSERT_EQ(back.faults.size(), cfg.faults.size());
  for (std::size_t i = 0; i < cfg.faults.size(); ++i) {
    const FaultEvent &a = cfg.faults[i], &b = back.faults[i];
    EXPECT_EQ(a.spec(), b.spec());
    EXPECT_EQ(a.kind, b.kind);
    EXPECT_EQ(a.target, b.target);
    EXPECT_EQ(a.start, b.start);
    EXPECT_EQ(a.end, b.end);
    EXPECT_EQ(a.axis, b.axis);
    EXPECT_EQ(a.gyro, b.gyro);
    EXPECT_EQ(a.value_si(), b.value_si());
    EXPECT_EQ(a.ratio, b.ratio);
  }
  EXPECT_EQ(back.to_yaml(), text);
  EXPECT_NE(text.find("value_m_s2: -0.03"), std::string::npos);
  // Spec strings in the list; `faults: []` and null clear it.
  SimConfig s;
  s.apply_yaml(YAML::Load("faults: [\"stuck:body-C2:1:2:sensor=accel,axis=y\", {kind: dropout, target: body, "
                          "start_s: 3, end_s: null}]"),
               "x");
  ASSERT_EQ(s.faults.size(), 2u);
  EXPECT_EQ(s.faults[0].spec(), "stuck:body-C2:1:2:sensor=accel,axis=y");
  EXPECT_EQ(s.faults[1].spec(), "dropout:body:3:end");
  s.apply_yaml(YAML::Load("faults: []"), "x");
  EXPECT_TRUE(s.faults.empty());
}

// --set errors.gyro_range_deg_s lowers the full scale: the Wheel-IMU gyro saturates at robot
// speeds (the error-free stream does not), and both manifests state the range.
TEST(SimFaults, LoweredGyroRangeSaturatesAndIsInTheManifests) {
  SimConfig cfg = short_config("datasheet");
  cfg.apply_setting("errors.gyro_range_deg_s=500");
  EXPECT_EQ(cfg.errors.gyro_range, 500.0 * kDeg);
  const fs::path dir = temp_dir("sat");
  const Simulation sim(cfg);
  sim.write(dir, false, false);
  const auto chip = rows(read_file(dir / "left-wheel-imu" / "tri_C1_imu.bin"));
  const auto ideal = rows(read_file(dir / "ideal" / "left-wheel_imu.bin"));
  double chip_max = 0.0, ideal_max = 0.0;
  int clipped = 0;
  for (std::size_t i = 0; i < chip.size(); ++i) {
    chip_max = std::max(chip_max, std::abs(chip[i][1]));
    ideal_max = std::max(ideal_max, std::abs(ideal[i][1]));
    clipped += std::abs(chip[i][1]) >= 500.0 * kDeg - cfg.errors.gyro_lsb;
  }
  std::printf("left-wheel gyro_x: ideal up to %.1f deg/s, chip up to %.1f deg/s, %d samples at the clamp\n",
              ideal_max / kDeg, chip_max / kDeg, clipped);
  EXPECT_GT(ideal_max, 700.0 * kDeg);
  EXPECT_LE(chip_max, 500.0 * kDeg + 0.5 * cfg.errors.gyro_lsb);
  EXPECT_GT(clipped, 1000);
  for (const char* m : {"manifest.yaml", "manifest-ideal.yaml"})
    for (const ModuleSpec& s : load_manifest(dir / m).modules) EXPECT_NEAR(s.gyro_range, 500.0 * kDeg, 1e-12) << m;
  fs::remove_all(dir);
  // Without the saturation effect no range is stated.
  cfg.disable({"saturation"});
  EXPECT_EQ(Simulation(cfg).manifest().modules[0].gyro_range, 0.0);
  EXPECT_EQ(Simulation(cfg).ideal_manifest().modules[0].gyro_range, 0.0);
}
