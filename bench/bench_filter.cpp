// Google Benchmark suite for the per-epoch hot path. Run: build/wheelins_bench
// (make bench). Figures go to BENCHMARKS.md with the command that produced them.
#include <benchmark/benchmark.h>

#include "wheelins/filter/error_model.hpp"
#include "wheelins/filter/wheel_velocity.hpp"
#include "wheelins/fusion/centralized.hpp"
#include "wheelins/nav/mechanization.hpp"

using namespace wheelins;

namespace {

ImuSample wheel_sample() {
  ImuSample s;
  s.dt = 0.005;
  s.t = 100.0;
  s.dtheta = Vec3(-14.4, 0.05, -0.02) * s.dt;
  s.dvel = Vec3(0.3, -4.1, -8.9) * s.dt;
  return s;
}

Mat21 some_covariance() {
  Mat21 A = Mat21::Random() * 0.01;
  return A * A.transpose() + Mat21::Identity() * 1e-6;
}

void BM_Mechanize(benchmark::State& state) {
  MechanizationOptions opt;
  opt.omega_ie_inW = Vec3(6.3e-5, 0, -3.7e-5);
  NavState nav;
  nav.q_ItoW = quat_from_euler(Vec3(0.3, 0.01, 1.2));
  const ImuSample s = wheel_sample();
  for (auto _ : state) {
    mechanize(opt, s, s, nav);
    benchmark::DoNotOptimize(nav);
  }
}
BENCHMARK(BM_Mechanize);

void BM_CovarianceDense(benchmark::State& state) {
  Mat21 P = some_covariance();
  const Mat21 F = error_dynamics(dcm_from_euler(Vec3(0.3, 0.01, 1.2)), Vec3(-14.4, 0.05, -0.02),
                                 Vec3(0.3, -4.1, -8.9), Vec3(6.3e-5, 0, -3.7e-5), ProcessNoise{});
  for (auto _ : state) {
    propagate_covariance(P, F, ProcessNoise{}, 0.005);
    benchmark::DoNotOptimize(P);
  }
}
BENCHMARK(BM_CovarianceDense);

void BM_CovarianceSparse(benchmark::State& state) {
  Mat21 P = some_covariance();
  const ErrorDynamics d = error_dynamics_blocks(dcm_from_euler(Vec3(0.3, 0.01, 1.2)),
                                                Vec3(-14.4, 0.05, -0.02), Vec3(0.3, -4.1, -8.9),
                                                Vec3(6.3e-5, 0, -3.7e-5), ProcessNoise{});
  for (auto _ : state) {
    propagate_covariance(P, d, ProcessNoise{}, 0.005);
    benchmark::DoNotOptimize(P);
  }
}
BENCHMARK(BM_CovarianceSparse);

void BM_WheelVelocityUpdate(benchmark::State& state) {
  WheelVelocityInput in;
  in.C_BtoW = dcm_from_euler(Vec3(0.3, 0.01, 1.2));
  in.v_IinW = Vec3(1.0, 0.9, 0.0);
  in.omega_ib_b = Vec3(-14.4, 0.05, -0.02);
  in.lever_arm_inB = Vec3(0.015, -0.004, 0.006);
  set_own_wheel_speed(in, 0.097, -14.3);
  const Mat21 P0 = some_covariance();
  const Mat3 R = Vec3(0.03, 0.02, 0.02).cwiseAbs2().asDiagonal();
  for (auto _ : state) {
    Mat21 P = P0;
    Vec21 dx = Vec21::Zero();
    const WheelVelocityModel m = wheel_velocity_model(in);
    benchmark::DoNotOptimize(ekf_update<3>(P, dx, m.H, m.innovation(), R));
    benchmark::DoNotOptimize(P);
  }
}
BENCHMARK(BM_WheelVelocityUpdate);

void BM_CentralizedPropagateTriple(benchmark::State& state) {
  auto joint = make_joint_covariance(3);
  for (int i = 0; i < 3; ++i) joint->set_block(i, some_covariance());
  const ErrorDynamics d = error_dynamics_blocks(dcm_from_euler(Vec3(0.3, 0.01, 1.2)),
                                                Vec3(-14.4, 0.05, -0.02), Vec3(0.3, -4.1, -8.9),
                                                Vec3(6.3e-5, 0, -3.7e-5), ProcessNoise{});
  for (auto _ : state) {
    for (int i = 0; i < 3; ++i) joint->propagate(i, d, ProcessNoise{}, 0.005);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_CentralizedPropagateTriple);

// One 3-row measurement update of the centralized filter's joint 63 x 63 covariance, with a
// block of H on every IMU (a position constraint of the Triple INS).
void BM_CentralizedUpdateTriple(benchmark::State& state) {
  auto joint = make_joint_covariance(3);
  for (int i = 0; i < 3; ++i) joint->set_block(i, some_covariance());
  std::array<H3, kMaxCentralized> H;
  std::array<const H3*, kMaxCentralized> blocks{};
  for (int i = 0; i < 3; ++i) {
    H[i] = H3::Zero();
    H[i].leftCols<9>().setRandom();
    blocks[i] = &H[i];
  }
  const Mat3 R = Mat3::Identity() * 0.04;
  const Vec3 dz(0.01, -0.02, 0.005);
  std::array<Vec21, kMaxCentralized> dx;
  for (auto _ : state) {
    benchmark::DoNotOptimize(joint->update(blocks, dz, R, 0.0, dx, nullptr));
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_CentralizedUpdateTriple);

// What a centralized filter costs when its 63 x 63 covariance is propagated as a dense
// product (the textbook form; the paper's Table 8 ratio of 8.6 comes from such a filter):
// P <- Phi P Phi^T with Phi = diag(Phi_1, Phi_2, Phi_3) held as a dense 63 x 63 matrix.
void BM_CentralizedPropagateTripleDense(benchmark::State& state) {
  using Mat63 = Eigen::Matrix<double, 63, 63>;
  Mat63 P = Mat63::Zero();
  for (int i = 0; i < 3; ++i) P.block<21, 21>(21 * i, 21 * i) = some_covariance();
  const Mat21 F = error_dynamics(dcm_from_euler(Vec3(0.3, 0.01, 1.2)), Vec3(-14.4, 0.05, -0.02),
                                 Vec3(0.3, -4.1, -8.9), Vec3(6.3e-5, 0, -3.7e-5), ProcessNoise{});
  Mat63 Phi = Mat63::Zero();
  for (int i = 0; i < 3; ++i) Phi.block<21, 21>(21 * i, 21 * i) = transition_matrix(F, 0.005);
  for (auto _ : state) {
    P = Phi * P * Phi.transpose();
    benchmark::DoNotOptimize(P);
  }
}
BENCHMARK(BM_CentralizedPropagateTripleDense);

}  // namespace

BENCHMARK_MAIN();
