// Monte-Carlo consistency of the strapdown EKF (in the spirit of GTSAM's
// ScenarioRunner checks): the true motion of a Body-IMU and of a spinning
// Wheel-IMU comes from the simulator (error-free); on each of many seeds the test
// draws sensor errors exactly as the filter models them (turn-on values from P0,
// first-order Gauss-Markov biases and scale factors, white noise ARW/VRW) and the
// initial state error from P0, runs StrapdownEkf with velocity measurements
// (truth + white noise of the stated R, 2 Hz), and compares the error with the
// filter's covariance. The mean NEES over the seeds at each check epoch must lie
// in the two-sided 99.8 % band of chi^2(N d) / N. A covariance that is too small
// (a missing noise term, a wrong F block) or too large fails it.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "wheelins/filter/strapdown_ekf.hpp"
#include "wheelins/sim/simulator.hpp"

using namespace wheelins;

namespace {

/// Wilson-Hilferty approximation of the chi^2 quantile with k degrees of freedom at the
/// standard normal quantile z (relative error < 1e-3 for k > 100).
double chi2_quantile(double k, double z) {
  const double a = 2.0 / (9.0 * k);
  return k * std::pow(1.0 - a + z * std::sqrt(a), 3.0);
}

struct Truth {
  std::vector<ImuSample> samples;  ///< error-free, sensor axes, k = 1..n
  /// The true state at the end of sample k, for k a multiple of `state_every` (index
  /// k / state_every; [0] the start). Only there: each truth() integrates the wheel angle
  /// from the start of the scenario.
  std::vector<NavState> states;
  std::size_t state_every = 1;
  const NavState& at(std::size_t k) const { return states.at(k / state_every); }
};

/// The true motion of module g from the end of the static period (30 s) for `seconds`,
/// states every `state_interval` seconds.
Truth truth_of(const sim::Simulation& s, int g, double seconds, double state_interval) {
  const double rate = s.config().rate_hz;
  const std::size_t k0 = static_cast<std::size_t>(std::llround(30.0 * rate));
  const std::size_t n = static_cast<std::size_t>(std::llround(seconds * rate));
  const std::vector<ImuSample> all = s.ideal_samples(g, k0 + n);
  Truth t;
  t.samples.assign(all.begin() + static_cast<std::ptrdiff_t>(k0), all.end());
  t.state_every = static_cast<std::size_t>(std::llround(state_interval * rate));
  for (std::size_t k = 0; k <= n; k += t.state_every) {
    const double time = s.start_time() + static_cast<double>(k0 + k) / rate;
    const sim::ImuTruth it = s.truth(g, time);
    NavState st;
    st.t = time;
    st.p_IinW = it.p_inN;
    st.v_IinW = it.v_inN;
    st.q_ItoW = Quat(it.C_StoN).normalized();
    t.states.push_back(st);
  }
  return t;
}

ProcessNoise test_noise(double gyro_sf_std) {
  ProcessNoise q;
  q.gyro_arw = 1.0 * kDeg / 60.0;
  q.acc_vrw = 1.0 / 60.0;
  q.gyro_bias_std = 50.0 * kDeg / 3600.0;
  q.acc_bias_std = 0.02;
  q.gyro_sf_std = gyro_sf_std;
  q.acc_sf_std = 3000e-6;
  // Short correlation times so the Gauss-Markov driving noise matters over a minute.
  q.gyro_bias_tau = q.acc_bias_tau = 120.0;
  q.gyro_sf_tau = q.acc_sf_tau = 120.0;
  return q;
}

/// The error state of `ekf` against the truth (the filter's conventions, error_state.hpp).
Vec21 error_of(const StrapdownEkf& ekf, const NavState& truth, const ImuErrors& true_errors) {
  Vec21 e;
  const NavState& s = ekf.state();
  e.segment<3>(P) = s.p_IinW - truth.p_IinW;
  e.segment<3>(V) = s.v_IinW - truth.v_IinW;
  // C_hat = exp(-[phi x]) C  =>  phi = log(C C_hat^T).
  e.segment<3>(PHI) = rotvec_from_quat(truth.q_ItoW * s.q_ItoW.conjugate());
  e.segment<3>(BG) = true_errors.bg - ekf.errors().bg;
  e.segment<3>(BA) = true_errors.ba - ekf.errors().ba;
  e.segment<3>(SG) = true_errors.sg - ekf.errors().sg;
  e.segment<3>(SA) = true_errors.sa - ekf.errors().sa;
  return e;
}

struct McResult {
  std::vector<double> t;                 ///< check epochs [s since the start]
  std::vector<double> nees_nav, nees_all;  ///< mean over the runs (9 and 21 states)
  int runs = 0;
};

/// `runs` seeds on `truth`; velocity updates every `update_interval` s (0: none); the NEES
/// every `check_interval` s.
McResult monte_carlo(const Truth& truth, double gravity, int runs, double update_interval,
                     double check_interval, double covariance_interval, double gyro_sf_std = 3000e-6) {
  const ProcessNoise q = test_noise(gyro_sf_std);
  InitialUncertainty init;
  init.position = 0.05;
  init.velocity = 0.02;
  init.roll_pitch = 0.2 * kDeg;
  init.heading = 0.5 * kDeg;
  MechanizationOptions mech;
  mech.gravity = gravity;
  const double vel_std = 0.02;
  const double rate_dt = truth.samples.front().dt;
  const auto every = [&](double interval) {
    return static_cast<std::size_t>(std::llround(interval / rate_dt));
  };
  const std::size_t n = truth.samples.size();
  const std::size_t upd = update_interval > 0 ? every(update_interval) : 0, chk = every(check_interval);

  McResult res;
  res.runs = runs;
  for (std::size_t k = chk; k <= n; k += chk) res.t.push_back(static_cast<double>(k) * rate_dt);
  res.nees_nav.assign(res.t.size(), 0.0);
  res.nees_all.assign(res.t.size(), 0.0);

  for (int run = 0; run < runs; ++run) {
    std::mt19937_64 rng(1000 + static_cast<std::uint64_t>(run));
    std::normal_distribution<double> N01(0.0, 1.0);
    const auto draw3 = [&](double sigma) {
      Vec3 v;
      for (int i = 0; i < 3; ++i) v[i] = sigma * N01(rng);
      return v;
    };

    // The true sensor errors (turn-on values from P0) and the initial state error.
    ImuErrors err;
    err.bg = draw3(q.gyro_bias_std);
    err.ba = draw3(q.acc_bias_std);
    err.sg = draw3(q.gyro_sf_std);
    err.sa = draw3(q.acc_sf_std);
    NavState start = truth.at(0);
    start.p_IinW += draw3(init.position);
    start.v_IinW += draw3(init.velocity);
    Vec3 phi0 = draw3(init.roll_pitch);
    phi0.z() *= init.heading / init.roll_pitch;
    start.q_ItoW = (quat_from_rotvec(-phi0) * start.q_ItoW).normalized();

    StrapdownEkf ekf;
    ekf.initialize(start, ImuErrors{}, q, init, mech);
    ekf.set_covariance_interval(covariance_interval);

    std::size_t check = 0;
    for (std::size_t k = 1; k <= n; ++k) {
      const ImuSample& ideal = truth.samples[k - 1];
      const double dt = ideal.dt;
      // First-order Gauss-Markov over one sample, exact discretization.
      const auto gm = [&](Vec3& x, double sigma, double tau) {
        const double a = std::exp(-dt / tau);
        x = a * x + draw3(sigma * std::sqrt(1.0 - a * a));
      };
      gm(err.bg, q.gyro_bias_std, q.gyro_bias_tau);
      gm(err.ba, q.acc_bias_std, q.acc_bias_tau);
      gm(err.sg, q.gyro_sf_std, q.gyro_sf_tau);
      gm(err.sa, q.acc_sf_std, q.acc_sf_tau);
      ImuSample raw = ideal;
      raw.t = truth.samples[k - 1].t;
      raw.dtheta = ideal.dtheta + err.sg.cwiseProduct(ideal.dtheta) + err.bg * dt +
                   draw3(q.gyro_arw * std::sqrt(dt));
      raw.dvel = ideal.dvel + err.sa.cwiseProduct(ideal.dvel) + err.ba * dt +
                 draw3(q.acc_vrw * std::sqrt(dt));
      ekf.propagate(raw);

      if (upd > 0 && k % upd == 0) {
        const Vec3 z = truth.at(k).v_IinW + draw3(vel_std);
        Eigen::Matrix<double, 3, kStateDim> H = Eigen::Matrix<double, 3, kStateDim>::Zero();
        H.block<3, 3>(0, V).setIdentity();
        const Vec3 dz = ekf.state().v_IinW - z;
        ekf.update<3>(H, dz, Mat3::Identity() * vel_std * vel_std);
      }
      if (k % chk == 0) {
        ekf.flush_covariance();
        const Vec21 e = error_of(ekf, truth.at(k), err);
        const Mat21& Pk = ekf.covariance();
        const Eigen::Matrix<double, 9, 1> en = e.head<9>();
        res.nees_nav[check] += en.dot(Pk.topLeftCorner<9, 9>().ldlt().solve(en)) / runs;
        res.nees_all[check] += e.dot(Pk.ldlt().solve(e)) / runs;
        ++check;
      }
    }
  }
  return res;
}

/// Every check epoch's mean NEES within the two-sided band (z = 3.09 each side, 99.8 %).
void expect_consistent(const McResult& r, const std::string& what) {
  for (const auto& [d, nees] : {std::pair{9, &r.nees_nav}, std::pair{21, &r.nees_all}}) {
    const double k = static_cast<double>(d * r.runs);
    const double lo = chi2_quantile(k, -3.09) / r.runs, hi = chi2_quantile(k, 3.09) / r.runs;
    for (std::size_t i = 0; i < r.t.size(); ++i) {
      std::printf("[ measured ] %s, %2d states, t = %4.1f s: mean NEES %6.2f (band %.2f-%.2f)\n",
                  what.c_str(), d, r.t[i], (*nees)[i], lo, hi);
      EXPECT_GT((*nees)[i], lo) << what << ", " << d << " states at " << r.t[i] << " s";
      EXPECT_LT((*nees)[i], hi) << what << ", " << d << " states at " << r.t[i] << " s";
    }
  }
}

class FilterMonteCarlo : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    sim::SimConfig cfg;
    cfg.set_profile("ideal");
    cfg.earth_rotation = false;
    cfg.chips = 1;
    cfg.duration = 75.0;
    sim_ = new sim::Simulation(cfg);
    wheel_ = new Truth(truth_of(*sim_, 0, 40.0, 0.5));
    body_ = new Truth(truth_of(*sim_, 2, 40.0, 0.5));
  }
  static void TearDownTestSuite() {
    delete wheel_;
    delete body_;
    delete sim_;
  }
  static sim::Simulation* sim_;
  static Truth* wheel_;
  static Truth* body_;
  static constexpr int kRuns = 40;
};
sim::Simulation* FilterMonteCarlo::sim_ = nullptr;
Truth* FilterMonteCarlo::wheel_ = nullptr;
Truth* FilterMonteCarlo::body_ = nullptr;

}  // namespace

TEST_F(FilterMonteCarlo, BodyImuWithVelocityUpdatesIsConsistent) {
  expect_consistent(monte_carlo(*body_, sim_->gravity(), kRuns, 0.5, 10.0, 0.05), "body, 2 Hz updates");
}

TEST_F(FilterMonteCarlo, SpinningWheelImuWithVelocityUpdatesIsConsistent) {
  expect_consistent(monte_carlo(*wheel_, sim_->gravity(), kRuns, 0.5, 10.0, 0.05),
                    "wheel, 2 Hz updates");
}

TEST_F(FilterMonteCarlo, SpinningWheelImuFreeInertialIsConsistentAtEveryCovarianceRate) {
  // No updates for 10 s: the predicted covariance alone against the spread, with P
  // propagated every epoch and every 0.05 s (docs/filter.md section 12). The gyro scale
  // factor is 1000 ppm here: at 14 rad/s of spin, 3000 ppm turns the attitude by 0.4 rad
  // in 10 s, beyond what a linearized covariance can follow without updates.
  for (double interval : {0.0, 0.05}) {
    Truth short_truth = *wheel_;
    short_truth.samples.resize(10 * 200);
    short_truth.states.resize(10 * 2 + 1);
    expect_consistent(monte_carlo(short_truth, sim_->gravity(), kRuns, 0.0, 2.5, interval, 1000e-6),
                      "wheel, free inertial, covariance interval " + std::to_string(interval) + " s");
  }
}
