// Simulator steering: the steered front Wheel-IMUs of preset car-steered (Ackermann angle
// of the path's curvature, no lateral slip, the steering rate in the gyro), the start with
// the wheels turned, and the preset's draws, manifests and settings.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "io_test_util.hpp"
#include "wheelins/io/manifest.hpp"
#include "wheelins/sim/simulator.hpp"

using namespace wheelins;
using namespace wheelins::sim;
namespace fs = std::filesystem;

namespace {

constexpr int kFrontLeft = 3, kFrontRight = 4;

/// car-steered, error-free, flat, no earth rate, 5 s static: the car's T from its start
/// (a left turn at ~44 s, right turns at ~64 s and ~72 s).
SimConfig steered_config(double duration) {
  SimConfig cfg;
  cfg.vehicle = VehicleConfig::preset_named("car-steered");
  cfg.set_profile("ideal");
  cfg.earth_rotation = false;
  cfg.duration = duration;
  cfg.static_duration = 5.0;
  cfg.start_time = 0.0;
  return cfg;
}

/// A wheel module's frame and rates at t, from the same jets as Simulation::truth() but at
/// wheel angle 0 (truth() integrates the angle from the start: slow for many instants; the
/// axle's direction and the rates in the n-frame do not depend on the angle).
struct WheelFrame {
  Mat3 C_BtoN;       ///< the wheel's b-frame (x: the axle, -y: the heading at angle 0)
  Vec3 omega_inN;    ///< its angular rate w.r.t. the n-frame
};
WheelFrame wheel_frame(const Simulation& sim, int g, double t) {
  const GroupStepper st = sim.stepper(g, 0.0);
  JV p_o, p;
  JM C_v, C_s;
  sim.scenario().evaluate(t, p_o, C_v);
  st.imu_jets(t, p_o, C_v, GroupStepper::integrate(0.0, st.rate_at(t)), st.steering_at(t), p, C_s);
  WheelFrame w;
  w.C_BtoN = C_s.value() * dcm_from_euler(sim.module(g).truth.mounting_rpy).transpose();
  w.omega_inN = C_s.value() * body_rate(C_s);
  return w;
}

/// The steering angle of a wheel from its attitude alone: the axle (b_x) is
/// C_v Rz(delta) e_y = C_v (-sin delta, cos delta, 0).
double steering_of(const Simulation& sim, const Mat3& C_BtoN, double t) {
  const Vec3 axle = sim.scenario().state(t).C_VtoN.transpose() * C_BtoN.col(0);
  return std::atan2(-axle.x(), axle.y());
}
double steering_from_attitude(const Simulation& sim, int g, double t) {
  return steering_of(sim, wheel_frame(sim, g, t).C_BtoN, t);
}

/// Exact Ackermann angle of a hub at (x, y) for the curvature kappa.
double ackermann(double kappa, const Vec3& hub) { return std::atan2(kappa * hub.x(), 1.0 - kappa * hub.y()); }

/// The time of the sharpest turn to the right (sign +1) or left (-1) in [t0, t1].
double sharpest_turn(const Simulation& sim, double sign, double t0, double t1) {
  double best = 0.0, at = t0;
  for (double t = t0; t < t1; t += 0.1) {
    const double k = sign * sim.scenario().path_curvature(t).value();
    if (k > best) best = k, at = t;
  }
  return at;
}

std::string error_of(const SimConfig& cfg) {
  try {
    cfg.validate();
    const Simulation sim(cfg);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// The path curvature jet is the exact derivative of its values, and equals yaw rate / speed
// on flat ground without skid.
TEST(SimSteering, PathCurvatureJetIsExact) {
  const Simulation sim(steered_config(100.0));
  const Scenario& s = sim.scenario();
  const double h = 1e-3;
  double worst_rate = 0.0, worst_kappa = 0.0, max_kappa = 0.0;
  for (double t = 15.0; t < 100.0; t += 0.37) {
    const J k = s.path_curvature(t);
    const double fd = (s.path_curvature(t - 2 * h).value() * 1.0 - 8.0 * s.path_curvature(t - h).value() +
                       8.0 * s.path_curvature(t + h).value() - s.path_curvature(t + 2 * h).value()) /
                      (12 * h);
    worst_rate = std::max(worst_rate, std::abs(fd - k.deriv(1)));
    const VehicleState st = s.state(t);
    if (st.forward_speed() > 1.0)
      worst_kappa = std::max(worst_kappa, std::abs(st.omega_inV.z() / st.forward_speed() - k.value()));
    max_kappa = std::max(max_kappa, std::abs(k.value()));
  }
  std::printf("curvature: max %.4f 1/m, | d/dt - central difference | %.2g 1/(m s), | yaw rate / speed - "
              "kappa | %.2g 1/m\n",
              max_kappa, worst_rate, worst_kappa);
  EXPECT_GT(max_kappa, 0.1);  // the car's corners: turn radius ~7 m
  EXPECT_LT(worst_rate, 1e-8);
  EXPECT_LT(worst_kappa, 1e-10);
}

// Right turn: both front wheels turned right (delta > 0), the inner (right) one more, as
// Ackermann says; left turn: the mirror image. The angle read from the attitude alone equals
// the Ackermann angle of the vehicle's own curvature (yaw rate / speed), and the wheels' axles
// meet the rear axle's line in one point.
TEST(SimSteering, SteeringSignAndAckermann) {
  const Simulation sim(steered_config(100.0));
  ASSERT_EQ(sim.groups(), 5);
  EXPECT_STREQ(Simulation::group_name(kFrontLeft), "front-left-wheel");
  EXPECT_STREQ(Simulation::group_name(kFrontRight), "front-right-wheel");
  const Vec3 hl = sim.module(kFrontLeft).truth.p_inV, hr = sim.module(kFrontRight).truth.p_inV;
  EXPECT_EQ(hl, Vec3(2.6, -0.8, 0.0));
  EXPECT_EQ(hr, Vec3(2.6, 0.8, 0.0));
  int right_turns = 0, left_turns = 0;
  for (double t = 20.0; t < 100.0; t += 0.25) {
    const VehicleState st = sim.scenario().state(t);
    if (st.forward_speed() < 1.0) continue;
    const double kappa = st.omega_inV.z() / st.forward_speed();
    const double dl = steering_from_attitude(sim, kFrontLeft, t), dr = steering_from_attitude(sim, kFrontRight, t);
    EXPECT_NEAR(dl, ackermann(kappa, hl), 1e-9) << "t " << t;
    EXPECT_NEAR(dr, ackermann(kappa, hr), 1e-9) << "t " << t;
    // The axles meet at the turn's centre (0, 1/kappa) on the rear axle's line.
    if (std::abs(kappa) > 0.01) {
      EXPECT_NEAR(hl.y() + hl.x() / std::tan(dl), 1.0 / kappa, 1e-6);
      EXPECT_NEAR(hr.y() + hr.x() / std::tan(dr), 1.0 / kappa, 1e-6);
    }
    if (kappa > 0.05) {
      ++right_turns;
      EXPECT_GT(dl, 0.0);
      EXPECT_GT(dr, dl) << "the inner (right) wheel turns more in a right turn";
    } else if (kappa < -0.05) {
      ++left_turns;
      EXPECT_LT(dr, 0.0);
      EXPECT_LT(dl, dr) << "the inner (left) wheel turns more in a left turn";
    }
  }
  EXPECT_GT(right_turns, 3);
  EXPECT_GT(left_turns, 3);
  // At rest and on the straights the wheels are straight; the rear wheels never steer.
  EXPECT_NEAR(steering_from_attitude(sim, kFrontLeft, 3.0), 0.0, 1e-12);
  const double tr = sharpest_turn(sim, 1.0, 20.0, 100.0);
  EXPECT_NEAR(steering_from_attitude(sim, 0, tr), 0.0, 1e-12);
  // Simulation::truth() (the wheel angle integrated from the start) has the same frame.
  for (int g : {kFrontLeft, kFrontRight}) {
    const ImuTruth r = sim.truth(g, tr);
    const double d = steering_from_attitude(sim, g, tr);
    EXPECT_NEAR(steering_of(sim, r.C_StoN * dcm_from_euler(sim.module(g).truth.mounting_rpy).transpose(), tr), d,
                1e-12);
    EXPECT_NEAR(r.steering_angle, d, 1e-12);
  }
  std::printf("sharpest right turn at %.1f s: front-left %.2f deg, front-right %.2f deg\n", tr,
              steering_from_attitude(sim, kFrontLeft, tr) / kDeg, steering_from_attitude(sim, kFrontRight, tr) / kDeg);
}

// No lateral slip: the steered hub's velocity has no component along the steered wheel's
// axle (skid off), and its component along the wheel's heading is the speed that rolls it.
// The gyro sees the steering rate about the vehicle's vertical.
TEST(SimSteering, NoLateralSlipAndTheSteeringRateInTheGyro) {
  const Simulation sim(steered_config(100.0));
  const double h = 1e-4;
  for (int g : {kFrontLeft, kFrontRight}) {
    const ModuleModel& m = sim.module(g);
    double max_lateral = 0.0, max_speed = 0.0, max_roll = 0.0, max_rate = 0.0, worst_gyro = 0.0, worst_rate = 0.0;
    for (double t = 15.0; t < 100.0; t += 0.23) {
      const VehicleState st = sim.scenario().state(t);
      const WheelFrame w = wheel_frame(sim, g, t);
      const Vec3 v_hub = st.v_inN + st.C_VtoN * st.omega_inV.cross(m.truth.p_inV);
      max_lateral = std::max(max_lateral, std::abs(w.C_BtoN.col(0).dot(v_hub)));
      max_speed = std::max(max_speed, v_hub.norm());
      // The hub's velocity along the wheel's heading (-b_y at wheel angle 0) rolls it (slip off).
      max_roll = std::max(max_roll, std::abs(m.radius * sim.wheel_rate(g, t) + w.C_BtoN.col(1).dot(v_hub)));
      // The wheel's rate about the vehicle's vertical: the vehicle's yaw rate + d delta / dt.
      const double rate = sim.stepper(g, 0.0).steering_at(t).deriv(1);
      const double rate_fd = (steering_from_attitude(sim, g, t + h) - steering_from_attitude(sim, g, t - h)) / (2 * h);
      const Vec3 w_inV = st.C_VtoN.transpose() * w.omega_inN;
      worst_gyro = std::max(worst_gyro, std::abs(w_inV.z() - (st.omega_inV.z() + rate)));
      worst_rate = std::max(worst_rate, std::abs(rate_fd - rate));
      max_rate = std::max(max_rate, std::abs(rate));
    }
    // truth() says the same (the wheel angle integrated from the start).
    const double t = sharpest_turn(sim, 1.0, 20.0, 100.0);
    const ImuTruth r = sim.truth(g, t);
    const VehicleState st = sim.scenario().state(t);
    const Vec3 v_hub = st.v_inN + st.C_VtoN * st.omega_inV.cross(m.truth.p_inV);
    EXPECT_NEAR(r.wheel_centre_speed, v_hub.norm(), 1e-9);
    EXPECT_NEAR(m.radius * r.wheel_rate, r.wheel_centre_speed, 1e-9);
    EXPECT_NEAR(r.steering_rate, sim.stepper(g, 0.0).steering_at(t).deriv(1), 1e-15);
    EXPECT_LT((r.C_StoN * r.omega_nb_inS - wheel_frame(sim, g, t).omega_inN).norm(), 1e-12);
    std::printf("%s: max | lateral hub velocity | %.2g m/s (speeds to %.1f m/s), | R alpha_dot - v | %.2g m/s, "
                "steering rate to %.1f deg/s, gyro z - (yaw rate + steering rate) %.2g rad/s, steering rate - "
                "central difference %.2g rad/s\n",
                Simulation::group_name(g), max_lateral, max_speed, max_roll, max_rate / kDeg, worst_gyro, worst_rate);
    EXPECT_GT(max_speed, 4.0);
    EXPECT_LT(max_lateral, 1e-9);
    EXPECT_LT(max_roll, 1e-9);
    EXPECT_GT(max_rate, 5.0 * kDeg);
    EXPECT_LT(worst_gyro, 1e-9);
    EXPECT_LT(worst_rate, 1e-6);
  }
}

// A start with the wheels turned: at rest, the front axle's centre is turned by D (the two
// wheels by their Ackermann angles of the curvature tan(D) / wheelbase), and the vehicle
// drives off along the arc before it joins the loop.
TEST(SimSteering, StartWithTheWheelsTurned) {
  for (double D : {20.0, -20.0}) {
    SimConfig cfg = steered_config(80.0);
    cfg.start_steering_deg = D;
    const Simulation sim(cfg);
    const double kappa = std::tan(D * kDeg) / 2.6;
    const double t0 = sim.start_time() + 1.0;  // in the static period
    EXPECT_LT(sim.scenario().state(t0).v_inN.norm(), 1e-9);
    EXPECT_NEAR(sim.scenario().path_curvature(t0).value(), kappa, 1e-9 * std::abs(kappa));
    const double dl = steering_from_attitude(sim, kFrontLeft, t0), dr = steering_from_attitude(sim, kFrontRight, t0);
    EXPECT_NEAR(dl, ackermann(kappa, sim.module(kFrontLeft).truth.p_inV), 1e-9);
    EXPECT_NEAR(dr, ackermann(kappa, sim.module(kFrontRight).truth.p_inV), 1e-9);
    // The front axle's centre (the bicycle model's wheel): cot = the mean of the two cots.
    const double centre = std::atan(2.0 / (1.0 / std::tan(dl) + 1.0 / std::tan(dr)));
    std::printf("start steering %+.0f deg: front-left %.3f deg, front-right %.3f deg, axle centre %.9f deg\n", D,
                dl / kDeg, dr / kDeg, centre / kDeg);
    EXPECT_NEAR(centre / kDeg, D, 0.5);
    EXPECT_NEAR(centre / kDeg, D, 1e-6);
    EXPECT_NEAR(0.5 * (dl + dr) / kDeg, D, 0.5);
    // At rest the steering holds (its rate is zero).
    EXPECT_LT(std::abs(sim.truth(kFrontLeft, t0).steering_rate), 1e-9);
    // Driving off: the first 5 m are on the arc (the smoothing into the loop comes later).
    const Scenario& s = sim.scenario();
    double t = s.static_end(), low = 1.0, high = 1.0;
    for (double d = 0.0; d <= 5.0; d += 0.5) {
      while (s.distance(t) < d) t += 0.05;
      const double r = s.path_curvature(t).value() / kappa;
      low = std::min(low, r), high = std::max(high, r);
    }
    std::printf("  the first 5 m: curvature %.3f to %.3f of the start's\n", low, high);
    EXPECT_GT(low, 0.95);
    EXPECT_LT(high, 1.05);
  }
}

// The arc joins the loop: after it, the vehicle drives the T as without the option (the same
// curvature and heading at the same place on the loop), the arc's length later.
TEST(SimSteering, StartArcJoinsTheLoop) {
  SimConfig plain = steered_config(1e4), turned = plain;
  turned.start_steering_deg = 20.0;
  const Simulation a(plain), b(turned);
  const auto& pa = dynamic_cast<const PathScenario&>(a.scenario());
  const auto& pb = dynamic_cast<const PathScenario&>(b.scenario());
  EXPECT_EQ(pa.spec().profile_u.front(), 0.0);
  const double u0 = pb.spec().profile_u.front();             // o starts here on the polyline
  const double lead = (pb.end_time() - pa.end_time()) * 6.0;  // the arc, driven at 6 m/s
  auto time_at = [](const PathScenario& s, double u) {
    double lo = s.start_time(), hi = s.end_time();
    for (int i = 0; i < 60; ++i) (s.arc(0.5 * (lo + hi)).value() < u ? lo : hi) = 0.5 * (lo + hi);
    return hi;
  };
  std::printf("start arc: o starts %.1f m into the polyline, %.2f m of arc to the loop\n", u0, lead);
  EXPECT_GT(lead, 5.0);
  EXPECT_LT(lead, 30.0);
  for (double ua : {100.0, 160.0, 170.0, 400.0, 2000.0}) {
    const double ub = u0 + lead + ua;
    EXPECT_NEAR(pb.curvature_at(ub), pa.curvature_at(ua), 1e-9) << ua;
    const double ha = a.scenario().state(time_at(pa, ua)).rpy().z(), hb = b.scenario().state(time_at(pb, ub)).rpy().z();
    EXPECT_NEAR(std::remainder(hb - ha, 2 * kPi), 0.0, 1e-9) << ua;
  }
}

// The preset's front wheels append modules and draws: the modules of the car are those of the
// car-steered preset, draw for draw and sample for sample.
TEST(SimSteering, FrontWheelsLeaveTheOtherModulesUnchanged) {
  SimConfig car;
  car.vehicle = VehicleConfig::preset_named("car");
  car.duration = 60.0;
  SimConfig steered = car;
  steered.vehicle = VehicleConfig::preset_named("car-steered");
  const Simulation a(car), b(steered);
  ASSERT_EQ(a.groups(), 3);
  ASSERT_EQ(b.groups(), 5);
  for (int g = 0; g < 3; ++g) {
    EXPECT_EQ(a.module(g).radius, b.module(g).radius);
    EXPECT_EQ(a.module(g).time_offset, b.module(g).time_offset);
    EXPECT_EQ(a.module(g).manifest.p_inV, b.module(g).manifest.p_inV);
    ASSERT_EQ(a.chips(g).size(), b.chips(g).size());
    for (std::size_t c = 0; c < a.chips(g).size(); ++c) {
      EXPECT_EQ(a.chips(g)[c].name, b.chips(g)[c].name);
      EXPECT_EQ(a.chips(g)[c].gyro_bias, b.chips(g)[c].gyro_bias);
      EXPECT_EQ(a.chips(g)[c].accel_T, b.chips(g)[c].accel_T);
    }
    const auto sa = a.ideal_samples(g, 2000), sb = b.ideal_samples(g, 2000);
    for (std::size_t k = 0; k < sa.size(); k += 97) {
      EXPECT_EQ(sa[k].dtheta, sb[k].dtheta);
      EXPECT_EQ(sa[k].dvel, sb[k].dvel);
    }
  }
  EXPECT_EQ(b.chips(kFrontLeft)[0].name, "front-left-C1");
  EXPECT_EQ(b.chips(kFrontRight)[3].name, "front-right-C4");
  EXPECT_NE(b.chips(kFrontLeft)[0].gyro_bias, b.chips(0)[0].gyro_bias);
  EXPECT_NE(b.module(kFrontLeft).radius, b.module(kFrontRight).radius);
  EXPECT_TRUE(b.module(kFrontLeft).truth.steered);
  EXPECT_FALSE(b.module(0).truth.steered);
}

// The dataset of car-steered: five module directories, the manifests state the steered
// wheels and the wheelbase and load back; scenario.yaml reproduces the bytes.
TEST(SimSteering, DatasetAndManifests) {
  SimConfig cfg;
  cfg.vehicle = VehicleConfig::preset_named("car-steered");
  cfg.duration = 8.0;
  cfg.static_duration = 2.0;
  cfg.start_steering_deg = 15.0;
  cfg.faults.push_back(parse_fault_spec("dropout:front-left-C2:4:5"));
  const iotest::ScratchDir scratch;
  const fs::path dir = scratch / "ds";
  Simulation(cfg).write(dir, false, false);
  const Manifest m = load_manifest(dir / "manifest.yaml");
  ASSERT_EQ(m.modules.size(), 20u);
  EXPECT_DOUBLE_EQ(m.wheelbase, 2.6);
  for (const auto& s : m.modules) {
    const bool front = s.name.rfind("front-", 0) == 0;
    EXPECT_EQ(s.steered, front) << s.name;
    if (front) {
      EXPECT_TRUE(fs::exists(m.resolve(s.file))) << s.name;
    }
  }
  EXPECT_EQ(m.modules[12].name, "front-left-C1");
  EXPECT_EQ(m.modules[12].group, "front-left-wheel");
  EXPECT_EQ(m.modules[12].chip, "C1");
  EXPECT_EQ(m.modules[12].file.filename(), "tri_C1_imu.bin");
  EXPECT_EQ(m.modules[12].file.parent_path().filename(), "front-left-wheel-imu");
  const Manifest mi = load_manifest(dir / "manifest-ideal.yaml");
  ASSERT_EQ(mi.modules.size(), 5u);
  EXPECT_EQ(mi.modules[3].name, "front-left-ideal");
  EXPECT_TRUE(mi.modules[4].steered);
  EXPECT_EQ(mi.modules[4].p_inV, Vec3(2.6, 0.8, 0.0));
  EXPECT_DOUBLE_EQ(mi.wheelbase, 2.6);
  EXPECT_TRUE(fs::exists(dir / "ideal" / "front-right-wheel_imu.bin"));
  // The dropout removed one second of front-left-C2 only.
  EXPECT_EQ(fs::file_size(dir / "front-left-wheel-imu" / "tri_C2_imu.bin") + 200 * 7 * 8,
            fs::file_size(dir / "front-left-wheel-imu" / "tri_C1_imu.bin"));
  const std::string yaml = iotest::read_text_file(dir / "scenario.yaml");
  EXPECT_NE(yaml.find("start_steering_deg: 15\n"), std::string::npos);
  EXPECT_NE(yaml.find("  wheelbase_m: 2.6\n"), std::string::npos);
  SimConfig again;
  again.apply_yaml(YAML::Load(yaml), "scenario.yaml");
  EXPECT_EQ(again.to_yaml(), yaml);
  const fs::path dir2 = scratch / "ds2";
  Simulation(again).write(dir2, false, false);
  for (const char* f : {"front-left-wheel-imu/tri_C1_imu.bin", "front-right-wheel-imu/tri_C4_imu.bin",
                        "GINS.bin", "manifest.yaml", "errors.yaml"})
    EXPECT_TRUE(iotest::read_text_file(dir / f) == iotest::read_text_file(dir2 / f)) << f;
}

// The settings: the wheelbase moves the front wheels and is checked; the start steering needs
// a wheelbase and the default scenario; the front wheels' keys and fault targets need the preset.
TEST(SimSteering, SettingsAreChecked) {
  SimConfig cfg;
  cfg.vehicle = VehicleConfig::preset_named("car-steered");
  cfg.apply_setting("vehicle.wheelbase_m=2.9");
  cfg.apply_setting("vehicle.track_m=1.5");
  EXPECT_EQ(cfg.vehicle.front[0].p_inV, Vec3(2.9, -0.75, 0.0));
  EXPECT_EQ(cfg.vehicle.front[1].p_inV, Vec3(2.9, 0.75, 0.0));
  cfg.apply_setting("vehicle.front-right-wheel.lever_arm_m=[0.01, 0, 0]");
  EXPECT_EQ(cfg.vehicle.front[1].lever_arm_inB, Vec3(0.01, 0.0, 0.0));
  EXPECT_NO_THROW(cfg.validate());
  SimConfig bad = cfg;
  bad.apply_setting("vehicle.wheelbase_m=0.2");
  EXPECT_NE(error_of(bad).find("vehicle.wheelbase_m"), std::string::npos) << error_of(bad);
  bad = cfg;
  bad.start_steering_deg = 45.0;
  EXPECT_NE(error_of(bad).find("--start-steering-deg"), std::string::npos);
  SimConfig robot;
  robot.start_steering_deg = 10.0;
  EXPECT_NE(error_of(robot).find("vehicle.wheelbase_m"), std::string::npos) << error_of(robot);
  robot.apply_setting("vehicle.wheelbase_m=0.6");  // any vehicle: the arc of its front axle
  robot.duration = 5.0;
  EXPECT_EQ(error_of(robot), "");
  SimConfig file = cfg;
  file.start_steering_deg = 10.0;
  file.scenario = "path.csv";
  EXPECT_NE(error_of(file).find("only with the default scenario"), std::string::npos) << error_of(file);
  SimConfig car;
  car.vehicle = VehicleConfig::preset_named("car");
  EXPECT_THROW(car.apply_setting("vehicle.front-left-wheel.mounting_deg=[0, 0, 1]"), InputError);
  car.duration = 10.0;
  car.faults.push_back(parse_fault_spec("slip:front-left-wheel:2:3:ratio=0.5"));
  EXPECT_NE(error_of(car).find("has no module front-left-wheel"), std::string::npos) << error_of(car);
  EXPECT_THROW(VehicleConfig::preset_named("truck"), InputError);
  // The existing presets state no wheelbase and no start steering.
  SimConfig plain;
  plain.vehicle = VehicleConfig::preset_named("car");
  EXPECT_EQ(plain.to_yaml().find("wheelbase"), std::string::npos);
  EXPECT_EQ(plain.to_yaml().find("start_steering"), std::string::npos);
}

// A slip fault on a front wheel: the steered wheel turns (1 + s) times its rolling rate.
TEST(SimSteering, SlipFaultOnASteeredWheel) {
  SimConfig cfg = steered_config(80.0);
  const Simulation plain(cfg);
  const double tr = sharpest_turn(plain, 1.0, 20.0, 80.0);
  cfg.faults.push_back(parse_fault_spec("slip:front-right-wheel:" + std::to_string(tr - 1.0) + ":" +
                                        std::to_string(tr + 1.0) + ":ratio=0.5"));
  const Simulation sim(cfg);
  const ImuTruth a = plain.truth(kFrontRight, tr), b = sim.truth(kFrontRight, tr);
  EXPECT_NEAR(b.wheel_rate, 1.5 * a.wheel_rate, 1e-9 * std::abs(a.wheel_rate));
  EXPECT_EQ(sim.truth(kFrontLeft, tr).wheel_rate, plain.truth(kFrontLeft, tr).wheel_rate);
  EXPECT_GT(std::abs(sim.slip_extra_angle(kFrontRight, sim.module(kFrontRight).slip_events.at(0))), 1.0);
}
