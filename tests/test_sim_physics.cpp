// Simulator physics: error-free data against the strapdown integrator and the
// wheel-speed relation; the jets against central differences.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "wheelins/nav/mechanization.hpp"
#include "wheelins/sim/simulator.hpp"

using namespace wheelins;
using namespace wheelins::sim;

namespace {

SimConfig ideal_config(double duration) {
  SimConfig cfg;
  cfg.set_profile("ideal");
  cfg.duration = duration;
  return cfg;
}

struct MechResult {
  double pos_err = 0.0, vel_err = 0.0, att_err = 0.0;
  Vec3 att_err_inW = Vec3::Zero();  ///< rotation vector, w-frame (z: heading)
  Vec3 pos_err_vec = Vec3::Zero();
};

/// Integrates module g's error-free samples from the true state at the start and
/// compares with the truth at the end.
MechResult integrate(const Simulation& sim, int g, double seconds,
                     MechanizationOptions::Method method, bool spin_about_x = false) {
  const auto count = static_cast<std::size_t>(std::llround(seconds * sim.config().rate_hz));
  std::vector<ImuSample> samples = sim.ideal_samples(g, count);
  // With spin_about_x (a Wheel-IMU), in the ideal wheel b-frame: x along the axle.
  const Mat3 C_StoB = spin_about_x ? dcm_from_euler(sim.module(g).truth.mounting_rpy) : Mat3::Identity();
  for (ImuSample& s : samples) {
    s.dtheta = C_StoB * s.dtheta;
    s.dvel = C_StoB * s.dvel;
  }
  const double t0 = sim.start_time();
  const ImuTruth s0 = sim.truth(g, t0);
  NavState st;
  st.t = t0;
  st.p_IinW = s0.p_inN;
  st.v_IinW = s0.v_inN;
  st.q_ItoW = Quat(s0.C_StoN * C_StoB.transpose()).normalized();
  MechanizationOptions opt;
  opt.spin_about_x = spin_about_x;
  opt.method = method;
  opt.gravity = sim.gravity();
  opt.omega_ie_inW = sim.earth_rate();
  for (std::size_t k = 0; k < samples.size(); ++k)
    mechanize(opt, k == 0 ? samples[0] : samples[k - 1], samples[k], st);
  const ImuTruth s1 = sim.truth(g, st.t);
  MechResult r;
  r.pos_err_vec = st.p_IinW - s1.p_inN;
  r.pos_err = r.pos_err_vec.norm();
  r.vel_err = (st.v_IinW - s1.v_inN).norm();
  const Quat q_true(s1.C_StoN * C_StoB.transpose());
  r.att_err = rotvec_from_quat(q_true.conjugate() * st.q_ItoW).norm();
  r.att_err_inW = rotvec_from_quat(st.q_ItoW * q_true.conjugate());
  return r;
}

/// Forward speed of wheel g's centre from the vehicle state: v_o + C_v^n (w x p_wheel).
double wheel_centre_speed(const Simulation& sim, int g, double t) {
  const VehicleState st = sim.scenario().state(t);
  const Vec3 v = st.v_inN + st.C_VtoN * st.omega_inV.cross(sim.module(g).truth.p_inV);
  return st.C_VtoN.col(0).dot(v);
}

}  // namespace

// (a) The Body-IMU's error-free data, integrated from the true initial state, reproduce
// the true trajectory: 30 s static, then 60 s of motion with turns (and vibration off).
TEST(SimPhysics, BodyImuMechanizationReproducesTruth) {
  const Simulation sim(ideal_config(100.0));
  const double moving = 90.0 - (sim.scenario().static_end() - sim.start_time());
  const MechResult r = integrate(sim, 2, 90.0, MechanizationOptions::Method::kRotationExact);
  const double dist = sim.scenario().distance(sim.start_time() + 90.0);
  std::printf("Body-IMU, %.0f s moving (%.1f m): position error %.3g m, velocity %.3g m/s, attitude %.3g deg\n",
              moving, dist, r.pos_err, r.vel_err, r.att_err / kDeg);
  EXPECT_GT(moving, 50.0);
  EXPECT_GT(dist, 70.0);
  EXPECT_LT(r.pos_err, 0.03);
  EXPECT_LT(r.att_err, 1e-4);
}

// The same with earth rotation off: the integrator and the simulator agree without it too.
TEST(SimPhysics, BodyImuMechanizationWithoutEarthRotation) {
  SimConfig cfg = ideal_config(100.0);
  cfg.earth_rotation = false;
  const Simulation sim(cfg);
  const MechResult r = integrate(sim, 2, 90.0, MechanizationOptions::Method::kRotationExact);
  EXPECT_LT(r.pos_err, 0.03);
}

// On terrain (slopes of a few degrees: roll, pitch and height change) the data stay exact.
TEST(SimPhysics, BodyImuMechanizationOnTerrain) {
  SimConfig cfg = ideal_config(100.0);
  cfg.terrain_slope_deg = 6.0;
  const Simulation sim(cfg);
  double max_tilt = 0.0, dh = 0.0;
  for (double t = sim.start_time(); t < sim.start_time() + 90.0; t += 0.5) {
    const VehicleState st = sim.scenario().state(t);
    max_tilt = std::max({max_tilt, std::abs(st.rpy().x()), std::abs(st.rpy().y())});
    dh = std::max(dh, std::abs(st.p_inN.z()));
  }
  const MechResult r = integrate(sim, 2, 90.0, MechanizationOptions::Method::kRotationExact);
  std::printf("terrain: max tilt %.2f deg, height change %.2f m, Body-IMU position error %.3g m\n",
              max_tilt / kDeg, dh, r.pos_err);
  EXPECT_GT(max_tilt, 0.5 * kDeg);
  EXPECT_LT(r.pos_err, 0.03);
}

// (b) A Wheel-IMU spinning at ~14.4 rad/s: the rotation-exact velocity increment keeps the
// position; the classic two-sample (sculling) form drifts metres, mostly vertically.
TEST(SimPhysics, WheelImuExactVersusClassicMechanization) {
  const Simulation sim(ideal_config(100.0));
  const ImuTruth mid = sim.truth(0, sim.start_time() + 60.0);
  std::printf("wheel rate at t0+60 s: %.2f rad/s\n", mid.wheel_rate);
  EXPECT_GT(std::abs(mid.wheel_rate), 13.0);
  const MechResult ex = integrate(sim, 0, 90.0, MechanizationOptions::Method::kRotationExact);
  const MechResult cl = integrate(sim, 0, 90.0, MechanizationOptions::Method::kClassicTwoSample);
  std::printf("Wheel-IMU, 90 s (60 s moving): exact %.4g m [%.3g %.3g %.3g], classic %.4g m [%.3g %.3g %.3g]\n",
              ex.pos_err, ex.pos_err_vec.x(), ex.pos_err_vec.y(), ex.pos_err_vec.z(), cl.pos_err,
              cl.pos_err_vec.x(), cl.pos_err_vec.y(), cl.pos_err_vec.z());
  EXPECT_LT(ex.pos_err * 10.0, cl.pos_err);
  EXPECT_GT(cl.pos_err, 1.0);
  EXPECT_GT(std::abs(cl.pos_err_vec.z()), cl.pos_err_vec.head<2>().norm());
}

// (b2) A car wheel at 15 m/s sampled at 100 Hz: 0.45 rad of spin per sample while the car
// turns. The two-sample coning term assumes a rate linear in time; the vehicle's yaw rate
// turns at the spin rate in the b-frame, and its error is a yaw-rate scale error of order
// (Omega dt)^4 (~700 ppm here). Splitting the spin off (spin_about_x, the Wheel-INS's own
// setting) is exact for a constant spin and turn rate.
TEST(SimPhysics, WheelImuSpinSplitAttitudeAtALowRateAndHighSpin) {
  SimConfig cfg = ideal_config(180.0);
  cfg.vehicle = VehicleConfig::preset_named("car");
  cfg.speed = 15.0;
  cfg.rate_hz = 100.0;
  const Simulation sim(cfg);
  const ImuTruth mid = sim.truth(0, sim.start_time() + 120.0);
  EXPECT_GT(std::abs(mid.wheel_rate) / cfg.rate_hz, 0.4);  // rad per sample
  const auto kExact = MechanizationOptions::Method::kRotationExact;
  const MechResult two = integrate(sim, 0, 180.0, kExact, false);
  const MechResult split = integrate(sim, 0, 180.0, kExact, true);
  std::printf("car wheel, 100 Hz, 150 s moving: attitude error (w-frame x y z, deg) two-sample %.4g %.4g %.4g, spin split %.4g %.4g %.4g\n",
              two.att_err_inW.x() / kDeg, two.att_err_inW.y() / kDeg, two.att_err_inW.z() / kDeg,
              split.att_err_inW.x() / kDeg, split.att_err_inW.y() / kDeg, split.att_err_inW.z() / kDeg);
  EXPECT_GT(std::abs(two.att_err_inW.z()), 0.05 * kDeg);
  EXPECT_LT(std::abs(split.att_err_inW.z()), 0.1 * std::abs(two.att_err_inW.z()));
}

// (c) -radius * gyro_x of the error-free Wheel-IMU data is the wheel-centre speed (flat
// ground, mounting angles zero, no earth rate: the identity is exact; means over the
// sample interval on both sides).
TEST(SimPhysics, WheelGyroGivesWheelCentreSpeed) {
  SimConfig cfg = ideal_config(80.0);
  cfg.earth_rotation = false;
  cfg.vehicle.left.mounting_rpy.setZero();
  cfg.vehicle.right.mounting_rpy.setZero();
  const Simulation sim(cfg);
  for (int g = 0; g < 2; ++g) {
    const auto samples = sim.ideal_samples(g, 16000);
    const double R = sim.module(g).radius;
    double max_err = 0.0, max_speed = 0.0;
    for (std::size_t k = 6000; k < samples.size(); k += 7) {
      const ImuSample& s = samples[k];
      const double a = s.t - s.dt;
      double mean_speed = 0.0;  // Gauss-Legendre mean of the wheel-centre speed
      const double x[4] = {-0.86113631159405257522, -0.33998104358485626480, 0.33998104358485626480,
                           0.86113631159405257522};
      const double w[4] = {0.34785484513745385737, 0.65214515486254614263, 0.65214515486254614263,
                           0.34785484513745385737};
      for (int i = 0; i < 4; ++i)
        mean_speed += 0.5 * w[i] * wheel_centre_speed(sim, g, a + 0.5 * s.dt * (1.0 + x[i]));
      const double from_gyro = -R * s.dtheta.x() / s.dt;
      max_err = std::max(max_err, std::abs(from_gyro - mean_speed));
      max_speed = std::max(max_speed, mean_speed);
    }
    // truth() integrates the wheel angle on its own: it gives the same wheel speed.
    const double t = sim.start_time() + 75.0;
    EXPECT_NEAR(sim.truth(g, t).wheel_centre_speed, wheel_centre_speed(sim, g, t), 1e-12);
    std::printf("%s: max | -R gyro_x - v_wheel | = %.3g m/s (speeds up to %.2f m/s)\n",
                Simulation::group_name(g), max_err, max_speed);
    EXPECT_GT(max_speed, 1.0);
    EXPECT_LT(max_err, 1e-9);
  }
}

namespace {
/// Module g's jets against fourth-order central differences of its truth at `times` [s since
/// the start] (the vibration reaches 60 Hz).
void check_jets_against_differences(const Simulation& sim, int g, const std::vector<double>& times) {
  const double h = 2e-5;
  for (double dt : times) {
    const double t = sim.start_time() + dt;
    const ImuTruth m2 = sim.truth(g, t - 2 * h), m = sim.truth(g, t - h), c = sim.truth(g, t),
                   p = sim.truth(g, t + h), p2 = sim.truth(g, t + 2 * h);
    const Vec3 v_fd = (-p2.p_inN + 8.0 * p.p_inN - 8.0 * m.p_inN + m2.p_inN) / (12 * h);
    const Vec3 a_fd = (-p2.v_inN + 8.0 * p.v_inN - 8.0 * m.v_inN + m2.v_inN) / (12 * h);
    // Angular rate from the attitude: log(C(t-h)^T C(t+h)) / 2h.
    const Vec3 w_fd = rotvec_from_quat(Quat(m.C_StoN.transpose() * p.C_StoN)) / (2 * h);
    EXPECT_LT((v_fd - c.v_inN).norm(), 1e-7) << "group " << g << " t " << dt;
    EXPECT_LT((a_fd - c.a_inN).norm(), 1e-6 * std::max(1.0, c.a_inN.norm())) << "group " << g << " t " << dt;
    EXPECT_LT((w_fd - c.omega_nb_inS).norm(), 1e-5 * std::max(1.0, c.omega_nb_inS.norm()))
        << "group " << g << " t " << dt;
  }
}
}  // namespace

// The jets' derivatives agree with central differences of the values (validates the
// chain rule through the path smoothing, the skid, terrain, vibration and the wheel spin).
TEST(SimPhysics, JetDerivativesMatchCentralDifferences) {
  SimConfig cfg;  // field: vibration, slip, skid on
  cfg.terrain_slope_deg = 3.0;
  cfg.duration = 120.0;
  cfg.start_time = 0.0;  // times of order 1e5 s would put 1e-11 s rounding into t +- h
  const Simulation sim(cfg);
  for (int g = 0; g < 3; ++g) check_jets_against_differences(sim, g, {45.3, 71.9, 96.2});
}

// The same for the steered front wheels of car-steered (and the others of that preset): the
// steering angle's jet (Ackermann of the path's curvature) in the attitude and the rolling
// rate; in the sharpest turns, while the steering turns and at rest with the wheels turned.
TEST(SimPhysics, JetDerivativesMatchCentralDifferencesOnSteeredWheels) {
  SimConfig cfg;  // field: vibration, slip, skid on
  cfg.vehicle = VehicleConfig::preset_named("car-steered");
  cfg.terrain_slope_deg = 3.0;
  cfg.duration = 90.0;
  cfg.static_duration = 5.0;
  cfg.start_time = 0.0;
  cfg.start_steering_deg = 25.0;
  const Simulation sim(cfg);
  ASSERT_EQ(sim.groups(), 5);
  // The sharpest turn and the fastest steering in the first corners of the T (after the
  // start's arc).
  double t_kappa = 0.0, t_rate = 0.0, best_kappa = 0.0, best_rate = 0.0;
  for (double t = 35.0; t < 90.0; t += 0.1) {
    const J k = sim.scenario().path_curvature(t);
    if (std::abs(k.value()) > best_kappa) best_kappa = std::abs(k.value()), t_kappa = t;
    if (std::abs(k.deriv(1)) > best_rate) best_rate = std::abs(k.deriv(1)), t_rate = t;
  }
  const ImuTruth r = sim.truth(4, t_rate);
  std::printf("steered jets: curvature %.3f 1/m at %.1f s, steering rate %.1f deg/s at %.1f s\n", best_kappa,
              t_kappa, r.steering_rate / kDeg, t_rate);
  EXPECT_GT(std::abs(r.steering_rate), 5.0 * kDeg);
  // At rest with the wheels turned, driving off along the start's arc, in the turns.
  for (int g : {0, 2, 3, 4}) check_jets_against_differences(sim, g, {3.0, 21.7, t_kappa, t_rate});
}

// The vehicle is at rest during the static period and the default scenario is the
// paper's: ~1.27 km in five laps at ~1.4 m/s with bounded accelerations and turns.
TEST(SimPhysics, DefaultScenarioShape) {
  SimConfig cfg;
  cfg.set_profile("ideal");
  const Simulation sim(cfg);
  const Scenario& s = sim.scenario();
  EXPECT_NEAR(s.static_end() - s.start_time(), 30.0, 1e-9);
  for (double t = s.start_time(); t <= s.static_end(); t += 1.0) {
    const VehicleState st = s.state(t);
    EXPECT_LT(st.v_inN.norm(), 1e-6);
    EXPECT_LT(st.a_inN.norm(), 1e-5);
  }
  double max_acc = 0.0, max_rate = 0.0, min_radius = 1e9;
  for (double t = s.start_time(); t < s.end_time(); t += 0.05) {
    const VehicleState st = s.state(t);
    max_acc = std::max(max_acc, st.a_inN.norm());
    max_rate = std::max(max_rate, std::abs(st.omega_inV.z()));
    const double v = st.v_inN.norm();
    if (v > 0.3) min_radius = std::min(min_radius, v / std::max(1e-9, std::abs(st.omega_inV.z())));
  }
  const double dist = s.distance(s.end_time());
  std::printf("default scenario: %.1f s, %.1f m, max |a| %.2f m/s^2, max yaw rate %.1f deg/s, "
              "min turn radius %.2f m\n",
              s.end_time() - s.start_time(), dist, max_acc, max_rate / kDeg, min_radius);
  EXPECT_NEAR(dist, 1240.0, 40.0);
  EXPECT_LT(max_acc, 0.8);
  EXPECT_GT(min_radius, 1.0);
  EXPECT_LT(min_radius, 3.0);
}

// errors.skid_deg_per_m_s2: the heading leaves the course by the slip angle k a_lat (a tyre's
// law, a_lat = v^2 kappa); the path and the speed stay those of the scenario without it.
TEST(SimPhysics, SkidAngleGrowsWithTheLateralAcceleration) {
  DefaultScenarioOptions plain_opt;
  plain_opt.speed = 6.0;
  plain_opt.scale = 4.0;
  DefaultScenarioOptions skid_opt = plain_opt;
  const double k = 0.25 * kDeg;  // per m/s^2
  skid_opt.skid_angle = k;
  const PathScenario plain(default_scenario_spec(plain_opt)), skid(default_scenario_spec(skid_opt));
  double largest = 0.0, largest_a_lat = 0.0;
  int moving = 0;
  for (double t = plain.static_end() + 1.0; t < plain.end_time(); t += 0.5) {
    const VehicleState a = plain.state(t), b = skid.state(t);
    ASSERT_LT((a.p_inN - b.p_inN).norm(), 1e-9) << t;
    ASSERT_LT((a.v_inN - b.v_inN).norm(), 1e-9) << t;
    const double v = a.v_inN.norm();
    if (v < 0.5) continue;
    ++moving;
    const double course = std::atan2(a.v_inN.y(), a.v_inN.x());
    EXPECT_NEAR(std::remainder(a.rpy().z() - course, 2.0 * kPi), 0.0, 1e-9) << t;
    const double a_lat = v * v * plain.path_curvature(t).value();
    const double beta = std::remainder(b.rpy().z() - course, 2.0 * kPi);
    EXPECT_NEAR(beta, k * a_lat, 1e-9) << t;
    largest = std::max(largest, std::abs(beta));
    largest_a_lat = std::max(largest_a_lat, std::abs(a_lat));
  }
  EXPECT_GT(moving, 100);
  EXPECT_GT(largest, 0.1 * kDeg);
  std::printf("skid angle: up to %.3f deg (lateral acceleration up to %.2f m/s^2)\n", largest / kDeg,
              largest_a_lat);
}

// A corrupt sample of a whole turn (2 pi) about the axle: the split's 1 / sinc(pi) would
// blow the in-plane part up by 1e16; beyond 2 rad per sample the update is the two-sample
// form's.
TEST(SimPhysics, WheelImuSpinSplitStaysFiniteOnACorruptSample) {
  MechanizationOptions opt, two;
  opt.spin_about_x = true;
  ImuSample s;
  s.dt = 0.01;
  s.dtheta = Vec3(2.0 * kPi, 0.01, -0.02);
  const AttitudeIncrement a = attitude_increment(opt, s, s);
  EXPECT_TRUE(a.q.coeffs().allFinite());
  EXPECT_TRUE(a.phi.isApprox(attitude_increment(two, s, s).phi)) << a.phi.transpose();
  s.dtheta.x() = 0.45;  // a car wheel at 100 Hz: the split, a unit quaternion
  const AttitudeIncrement b = attitude_increment(opt, s, s);
  EXPECT_NEAR(b.q.norm(), 1.0, 1e-15);
  EXPECT_TRUE(Quat(dcm_from_rotvec(b.phi)).isApprox(b.q) || Quat(dcm_from_rotvec(b.phi)).isApprox(Quat(-b.q.coeffs())));
}
