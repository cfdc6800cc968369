// Simulator datasets: determinism, effect switches, the real robot path, bad input.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "wheelins/io/binary.hpp"
#include "wheelins/io/manifest.hpp"
#include "wheelins/sim/simulator.hpp"

using namespace wheelins;
using namespace wheelins::sim;
namespace fs = std::filesystem;

namespace {

fs::path temp_dir(const std::string& name) {
  const fs::path p = fs::temp_directory_path() /
                     ("wheelins_test_sim_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  return p;
}

/// A short field-profile run: 2 s static, then 14 s of motion through the first turn of a
/// quarter-size T (so the skid acts).
SimConfig short_config() {
  SimConfig cfg;
  cfg.static_duration = 2.0;
  cfg.duration = 16.0;
  cfg.loop_scale = 0.25;
  cfg.path_sigma = 1.5;
  return cfg;
}

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Relative path -> contents of every file in a dataset.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> m;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) m[fs::relative(e.path(), dir).string()] = read_file(e.path());
  return m;
}

std::map<std::string, std::string> simulate(const SimConfig& cfg, const std::string& name) {
  const fs::path dir = temp_dir(name);
  Simulation(cfg).write(dir, false, false);
  auto snap = snapshot(dir);
  fs::remove_all(dir);
  return snap;
}

bool any_differs(const std::map<std::string, std::string>& a, const std::map<std::string, std::string>& b,
                 const std::string& prefix) {
  for (const auto& [k, v] : a)
    if (k.rfind(prefix, 0) == 0 && b.at(k) != v) return true;
  return false;
}

fs::path shared_dir() {
  if (const char* env = std::getenv("WHEELINS_SHARED_DIR")) return env;
  return fs::path(WHEELINS_SOURCE_DIR) / ".." / "shared";
}

}  // namespace

// (d) The same seed gives identical bytes (the three modules run in their own threads);
// another seed gives other data.
TEST(SimDataset, SameSeedSameBytesOtherSeedOtherData) {
  const SimConfig cfg = short_config();
  const auto a = simulate(cfg, "seed_a");
  const auto b = simulate(cfg, "seed_b");
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.size(), 33u);  // 12 chips, 3 ideal, 12 bias logs, GINS, odo, 2 manifests, 2 yaml
  for (const auto& [k, v] : a) EXPECT_TRUE(b.at(k) == v) << k << " differs between identical runs";
  // scenario.yaml holds every setting: feeding it back reproduces the bytes.
  SimConfig again;
  again.apply_yaml(YAML::Load(a.at("scenario.yaml")), "scenario.yaml");
  const auto r = simulate(again, "seed_r");
  for (const auto& [k, v] : a) EXPECT_TRUE(r.at(k) == v) << k << " differs when rerun from scenario.yaml";
  SimConfig other = cfg;
  other.seed = 2;
  const auto c = simulate(other, "seed_c");
  for (const char* f : {"left-wheel-imu/tri_C1_imu.bin", "right-wheel-imu/tri_C4_imu.bin",
                        "body-imu/tri_C2_imu.bin", "errors.yaml"})
    EXPECT_NE(a.at(f), c.at(f)) << f << " did not change with the seed";
  // The error-free streams do not depend on the seed in the datasheet profile.
  SimConfig ds = cfg, ds2 = cfg;
  ds.set_profile("datasheet");
  ds2.set_profile("datasheet");
  ds2.seed = 7;
  ds.effects.erase("radius");
  ds2.effects.erase("radius");
  const auto d1 = simulate(ds, "seed_d1"), d2 = simulate(ds2, "seed_d2");
  EXPECT_EQ(d1.at("ideal/body_imu.bin"), d2.at("ideal/body_imu.bin"));
  EXPECT_NE(d1.at("body-imu/tri_C1_imu.bin"), d2.at("body-imu/tri_C1_imu.bin"));
}

// The threaded writer and the single-threaded library path give the same samples.
TEST(SimDataset, WrittenIdealStreamEqualsLibrarySamples) {
  SimConfig cfg = short_config();
  const fs::path dir = temp_dir("ideal_eq");
  const Simulation sim(cfg);
  sim.write(dir, false, false);
  for (int g = 0; g < Simulation::kGroups; ++g) {
    const auto lib = sim.ideal_samples(g, 3200);
    BinaryRowReader rd(dir / "ideal" / (std::string(Simulation::group_name(g)) + "_imu.bin"), 7);
    ASSERT_EQ(rd.rows(), 3200u);
    for (const ImuSample& s : lib) {
      const double* r = rd.next();
      ASSERT_NE(r, nullptr);
      EXPECT_EQ(r[0], s.t);
      for (int i = 0; i < 3; ++i) {
        EXPECT_EQ(r[1 + i] * s.dt, s.dtheta[i]);
        EXPECT_EQ(r[4 + i] * s.dt, s.dvel[i]);
      }
    }
  }
  // The manifests load back and name the twelve chips and three ideal streams.
  const Manifest m = load_manifest(dir / "manifest.yaml");
  ASSERT_EQ(m.modules.size(), 12u);
  EXPECT_EQ(m.modules[0].name, "left-C1");
  EXPECT_EQ(m.modules[11].name, "body-C4");
  EXPECT_EQ(m.modules[11].group, "body");
  EXPECT_TRUE(fs::exists(m.resolve(m.modules[5].file)));
  EXPECT_NEAR(*m.gravity, earth::normal_gravity(m.origin.lat, m.origin.h), 1e-3);
  const Manifest mi = load_manifest(dir / "manifest-ideal.yaml");
  ASSERT_EQ(mi.modules.size(), 3u);
  EXPECT_EQ(mi.modules[0].wheel_radius, sim.module(0).radius);
  EXPECT_EQ(mi.modules[1].lever_arm_inB, sim.module(1).truth.lever_arm_inB);
  fs::remove_all(dir);
}

// (e) Every effect switch changes what it should: sensor errors change the chip files
// only; motion effects (vibration, slip, skid, radius) also change the error-free streams;
// calibration changes only the manifest; skid changes the truth.
TEST(SimDataset, EveryEffectSwitchChangesTheData) {
  SimConfig base = short_config();
  base.errors.gyro_range = 500.0 * kDeg;  // the wheels turn at ~800 deg/s: saturation acts
  ASSERT_EQ(base.effects.size(), kFieldEffects);
  base.effects.insert("wheel_noise");  // in no profile
  ASSERT_EQ(base.effects.size(), all_effects().size());
  const auto full = simulate(base, "eff_full");
  const std::set<std::string> motion = {"vibration", "slip", "skid", "radius"};
  for (const auto& e : all_effects()) {
    SimConfig cfg = base;
    cfg.disable({e});
    const auto v = simulate(cfg, "eff_" + e);
    const bool chips = any_differs(full, v, "left-wheel-imu/") || any_differs(full, v, "body-imu/");
    const bool ideal = any_differs(full, v, "ideal/");
    const bool manifest = full.at("manifest.yaml") != v.at("manifest.yaml");
    const bool truth = full.at("GINS.bin") != v.at("GINS.bin");
    if (e == "calibration") {
      EXPECT_TRUE(manifest) << e;
      EXPECT_FALSE(chips) << e;
    } else {
      EXPECT_TRUE(chips) << e << ": switching it off did not change the chip data";
      EXPECT_EQ(ideal, motion.count(e) > 0) << e << ": error-free streams";
    }
    EXPECT_EQ(truth, e == "skid") << e << ": truth";
    EXPECT_TRUE(full.at("scenario.yaml") != v.at("scenario.yaml")) << e;
  }
}

// wheel_noise: white noise on the Wheel-IMU accelerometers only, of the stated density at
// the cruise speed and none at rest (or the stated fraction), in no profile.
TEST(SimDataset, WheelNoiseHasItsDensityInMotionAndFollowsTheSpeed) {
  EXPECT_EQ(profile_effects("field").count("wheel_noise"), 0u);
  SimConfig cfg = short_config();
  cfg.chips = 1;
  cfg.only({"wheel_noise"});
  cfg.apply_setting("errors.wheel_accel_noise_m_s_sqrt_h=2.0");
  for (double rest : {0.0, 0.5}) {
    cfg.errors.wheel_accel_noise_rest = rest;
    const fs::path dir = temp_dir("wheel_noise");
    const Simulation sim(cfg);
    sim.write(dir, false, false);
    BinaryRowReader chip(dir / "left-wheel-imu" / "tri_C1_imu.bin", 7);
    BinaryRowReader ideal(dir / "ideal" / "left-wheel_imu.bin", 7);
    BinaryRowReader body(dir / "body-imu" / "tri_C1_imu.bin", 7);
    BinaryRowReader body_ideal(dir / "ideal" / "body_imu.bin", 7);
    const double *a, *b, *c, *d;
    double sum_rest = 0.0, sum_cruise = 0.0, body_diff = 0.0;
    int n_rest = 0, n_cruise = 0;
    while ((a = chip.next()) && (b = ideal.next()) && (c = body.next()) && (d = body_ideal.next())) {
      const double speed = sim.scenario().state(a[0]).v_inN.norm();
      for (int i = 1; i <= 3; ++i) EXPECT_EQ(a[i], b[i]);  // gyros untouched
      for (int i = 4; i <= 6; ++i) {
        const double e = a[i] - b[i];
        if (speed < 1e-6) sum_rest += e * e, ++n_rest;
        if (std::abs(speed - 1.4) < 0.02) sum_cruise += e * e, ++n_cruise;
      }
      for (int i = 1; i <= 6; ++i) body_diff = std::max(body_diff, std::abs(c[i] - d[i]));
    }
    fs::remove_all(dir);
    ASSERT_GT(n_rest, 300);
    ASSERT_GT(n_cruise, 1000);
    const double expected = 2.0 / 60.0 * std::sqrt(200.0);  // per-sample sigma at cruise speed
    const double at_cruise = std::sqrt(sum_cruise / n_cruise), at_rest = std::sqrt(sum_rest / n_rest);
    std::printf("[ measured ] rest fraction %.1f: per-sample sigma %.4f m/s^2 at 1.4 m/s (expected ~%.4f), "
                "%.4f at rest\n", rest, at_cruise, expected, at_rest);
    EXPECT_NEAR(at_cruise, expected, 0.05 * expected);
    EXPECT_NEAR(at_rest, rest * expected, 0.08 * expected);
    EXPECT_EQ(body_diff, 0.0);
  }
}

// --only switches single effects on; the rest stay off and the data equal the ideal streams.
TEST(SimDataset, OnlyOneEffect) {
  SimConfig cfg = short_config();
  cfg.only({});
  const auto none = simulate(cfg, "only_none");
  EXPECT_EQ(none.at("body-imu/tri_C3_imu.bin"), none.at("ideal/body_imu.bin"));
  EXPECT_EQ(none.at("left-wheel-imu/tri_C1_imu.bin"), none.at("ideal/left-wheel_imu.bin"));
  cfg.only({"arw"});
  const auto arw = simulate(cfg, "only_arw");
  EXPECT_NE(arw.at("body-imu/tri_C3_imu.bin"), arw.at("ideal/body_imu.bin"));
  EXPECT_THROW(cfg.only({"no-such-effect"}), InputError);
}

// (f) The real robot run: the KML path timed by odo.bin gives ~1.27 km over ~914 s.
TEST(SimDataset, RobotRunFromSharedData) {
  const fs::path robot = shared_dir() / "data" / "robot";
  if (!fs::exists(robot / "GINS.kml") || !fs::exists(robot / "odo.bin"))
    GTEST_SKIP() << "no shared robot data at " << robot;
  SimConfig cfg;
  cfg.scenario = (robot / "GINS.kml").string();
  cfg.speed_file = robot / "odo.bin";
  const Simulation sim(cfg);
  const Scenario& s = sim.scenario();
  const double dist = s.distance(s.end_time());
  std::printf("robot run: %.1f s, %.1f m (odometer scaled by %.5f)\n", s.end_time() - s.start_time(),
              dist, sim.speed_scale());
  EXPECT_NEAR(dist, 1270.0, 20.0);
  EXPECT_NEAR(s.end_time() - s.start_time(), 914.5 + 30.0 + 10.0, 1.0);
  EXPECT_NEAR(sim.speed_scale(), 1.0, 0.01);
  EXPECT_NEAR(s.start_time(), 132030.005 - 30.0, 1e-9);
  // Static before the odometer moves; the truth starts at the origin.
  EXPECT_LT(s.state(s.static_end()).v_inN.norm(), 1e-6);
  EXPECT_LT(s.state(s.start_time()).p_inN.norm(), 0.05);
  // Speeds and accelerations of a robot, and a short simulation writes.
  double vmax = 0.0, amax = 0.0;
  for (double t = s.start_time(); t < s.end_time(); t += 0.1) {
    const VehicleState st = s.state(t);
    vmax = std::max(vmax, st.v_inN.norm());
    amax = std::max(amax, st.a_inN.norm());
  }
  std::printf("robot run: max speed %.2f m/s, max |a| %.2f m/s^2\n", vmax, amax);
  EXPECT_LT(vmax, 2.0);
  EXPECT_LT(amax, 3.0);
  cfg.duration = 60.0;
  const auto snap = simulate(cfg, "robot");
  EXPECT_EQ(snap.at("left-wheel-imu/tri_C1_imu.bin").size(), 12000u * 56u);
}

// An error setting out of range is named with the value as given, in the key's unit.
TEST(SimDataset, ErrorSettingOutOfRangeIsNamedInItsUnit) {
  SimConfig cfg;
  cfg.apply_setting("errors.skid_deg_per_m_s2=-1");
  try {
    cfg.validate();
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("errors.skid_deg_per_m_s2: must be in [0, 1e+09], got -1"),
              std::string::npos)
        << e.what();
  }
  cfg.apply_setting("errors.skid_deg_per_m_s2=0.25");
  EXPECT_NO_THROW(cfg.validate());
  EXPECT_NEAR(cfg.errors.skid_angle, 0.25 * kDeg, 1e-15);
}

// draws_from: a module takes another module's draws (its radius, ..., and its chips' errors,
// chip by chip), its chips' noise stays their own, every other module's draws are unchanged,
// and scenario.yaml states the setting; names that are not the vehicle's modules are refused.
TEST(SimDataset, DrawsFromAnotherModuleAreThatModulesDraws) {
  SimConfig cfg = short_config();
  cfg.vehicle = VehicleConfig::preset_named("car-steered");
  cfg.chips = 1;
  cfg.write_ideal = false;
  const auto plain = simulate(cfg, "chips_own");
  cfg.apply_setting("draws_from.front-left-wheel=left-wheel");
  const auto copied = simulate(cfg, "chips_copied");
  auto chip = [](const std::map<std::string, std::string>& snap, const char* group, const char* name) {
    return YAML::Dump(YAML::Load(snap.at("errors.yaml"))["modules"][group]["chips"][name]);
  };
  EXPECT_EQ(chip(copied, "front-left-wheel", "front-left-C1"), chip(copied, "left-wheel", "left-C1"));
  EXPECT_NE(chip(plain, "front-left-wheel", "front-left-C1"), chip(plain, "left-wheel", "left-C1"));
  EXPECT_NE(chip(copied, "front-right-wheel", "front-right-C1"), chip(copied, "right-wheel", "right-C1"));
  auto radius = [](const std::map<std::string, std::string>& snap, const char* group) {
    return YAML::Load(snap.at("errors.yaml"))["modules"][group]["radius_true_m"].as<double>();
  };
  EXPECT_EQ(radius(copied, "front-left-wheel"), radius(copied, "left-wheel"));
  EXPECT_NE(radius(plain, "front-left-wheel"), radius(plain, "left-wheel"));
  EXPECT_NE(radius(copied, "front-right-wheel"), radius(copied, "right-wheel"));
  for (const char* g : {"left-wheel", "right-wheel", "front-right-wheel"}) {
    const std::string c = std::string(g).substr(0, std::string(g).size() - 6) + "-C1";
    EXPECT_EQ(chip(copied, g, c.c_str()), chip(plain, g, c.c_str())) << g;
  }
  EXPECT_EQ(copied.at("left-wheel-imu/tri_C1_imu.bin"), plain.at("left-wheel-imu/tri_C1_imu.bin"));
  EXPECT_NE(copied.at("front-left-wheel-imu/tri_C1_imu.bin"), plain.at("front-left-wheel-imu/tri_C1_imu.bin"));
  EXPECT_EQ(plain.at("scenario.yaml").find("draws_from"), std::string::npos);
  SimConfig again;
  again.apply_yaml(YAML::Load(copied.at("scenario.yaml")), "scenario.yaml");
  EXPECT_EQ(again.draws_from, cfg.draws_from);
  EXPECT_EQ(again.to_yaml(), copied.at("scenario.yaml"));

  auto refused = [&](const std::string& setting, const std::string& want) {
    SimConfig bad = cfg;
    bad.apply_setting(setting);
    try {
      bad.validate();
      ADD_FAILURE() << setting << ": no InputError";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(want), std::string::npos) << e.what();
    }
  };
  refused("draws_from.front-right-wheel=nowhere", "draws_from.front-right-wheel: 'nowhere' is not a module");
  refused("draws_from.left-wheel=left-wheel", "draws_from.left-wheel: a module's draws are its own");
  refused("draws_from.right-wheel=front-left-wheel", "'front-left-wheel' takes another module's draws");
  refused("draws_from.body=left-wheel", "draws_from.body: 'left-wheel' is a wheel, 'body' is not");
  SimConfig robot = short_config();
  robot.apply_setting("draws_from.front-left-wheel=left-wheel");
  EXPECT_THROW(robot.validate(), InputError);
}

// Bad path and speed files are rejected with the file and the record named.
TEST(SimDataset, BadInputNamesFileAndRecord) {
  const fs::path dir = temp_dir("bad");
  fs::create_directories(dir);
  {
    std::ofstream(dir / "bad.kml") << "<kml><LineString><coordinates>114.1,30.2,0 114.1,abc,0"
                                      "</coordinates></LineString></kml>";
    std::ofstream(dir / "none.kml") << "<kml><Point><coordinates>1,2</coordinates></Point></kml>";
    std::ofstream(dir / "ok.csv") << "north,east\n0,0\n10,0\n10,10\n";
    const double rows[6] = {1.0, 0.5, 2.0, 0.6, 1.5, 0.7};  // time goes back at record 2
    std::ofstream(dir / "odo.bin", std::ios::binary).write(reinterpret_cast<const char*>(rows), sizeof rows);
  }
  auto expect_error = [](const std::function<void()>& f, const std::string& a, const std::string& b) {
    try {
      f();
      ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
      const std::string w = e.what();
      EXPECT_NE(w.find(a), std::string::npos) << w;
      EXPECT_NE(w.find(b), std::string::npos) << w;
    }
  };
  PathFileOptions o;
  expect_error([&] { path_file_scenario_spec(dir / "bad.kml", o); }, "bad.kml", "coordinate 1");
  expect_error([&] { path_file_scenario_spec(dir / "none.kml", o); }, "none.kml", "LineString");
  o.speed_file = dir / "odo.bin";
  expect_error([&] { path_file_scenario_spec(dir / "ok.csv", o); }, "odo.bin", "record 2");
  o.speed_file.reset();
  const auto spec = path_file_scenario_spec(dir / "ok.csv", o);
  EXPECT_EQ(spec.path_ne.size(), 3u);
  fs::remove_all(dir);
}

// The CLI never writes into a directory with other files (not even with --force: the
// dataset replaces a directory as a whole), and replaces an earlier dataset only with --force.
TEST(SimDataset, CliRefusesNonEmptyDirectory) {
  const fs::path dir = temp_dir("cli");
  fs::create_directories(dir);
  std::ofstream(dir / "keep.txt") << "x";
  const std::string cmd = std::string(WHEELINS_BINARY) + " simulate -q --duration 3 --out " + dir.string();
  EXPECT_NE(std::system((cmd + " 2>/dev/null").c_str()), 0);
  EXPECT_NE(std::system((cmd + " --force 2>/dev/null").c_str()), 0);
  EXPECT_FALSE(fs::exists(dir / "manifest.yaml"));
  EXPECT_TRUE(fs::exists(dir / "keep.txt"));
  fs::remove(dir / "keep.txt");
  EXPECT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_TRUE(fs::exists(dir / "manifest.yaml"));
  EXPECT_NE(std::system((cmd + " --seed 2 2>/dev/null").c_str()), 0);
  EXPECT_EQ(std::system((cmd + " --seed 2 --force").c_str()), 0);
  EXPECT_TRUE(fs::exists(dir / "manifest.yaml"));
  fs::remove_all(dir);
}
