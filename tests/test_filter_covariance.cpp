// The covariance arithmetic behind the speed work: the block-sparse time update against
// the dense one, the multiplied-out Joseph update against the textbook form, and the
// lower-rate covariance propagation against the per-epoch one on a spinning wheel.
#include <gtest/gtest.h>

#include "wheelins/filter/ekf_update.hpp"
#include "wheelins/filter/error_model.hpp"
#include "wheelins/filter/strapdown_ekf.hpp"
#include "wheelins/math/rotation.hpp"

using namespace wheelins;

namespace {

Mat21 random_covariance(unsigned seed) {
  std::srand(seed);
  const Mat21 A = Mat21::Random() * 0.05;
  return A * A.transpose() + Mat21::Identity() * 1e-4;
}

double rel_diff(const Mat21& a, const Mat21& b) { return (a - b).norm() / b.norm(); }

}  // namespace

TEST(FilterCovariance, SparseTimeUpdateEqualsDenseTransition) {
  // Without process noise both forms are Phi P Phi^T with Phi = I + F dt + (F dt)^2 / 2
  // (eq. 2 to second order), over one epoch and over ten (the lower-rate update).
  ProcessNoise q;
  q.gyro_arw = q.acc_vrw = q.gyro_bias_std = q.acc_bias_std = q.gyro_sf_std = q.acc_sf_std = 0.0;
  q.gyro_bias_tau = 100.0;
  q.acc_bias_tau = 200.0;
  q.gyro_sf_tau = 300.0;
  q.acc_sf_tau = 400.0;
  const Mat3 C = dcm_from_euler(Vec3(0.3, -0.2, 1.2));
  const Vec3 w(-14.4, 0.05, -0.02), f(0.3, -4.1, -8.9), wie(6.3e-5, 0.0, -3.7e-5);
  for (double dt : {0.005, 0.05}) {
    Mat21 P_dense = random_covariance(1);
    Mat21 P_sparse = P_dense;
    const Mat21 F = error_dynamics(C, w, f, wie, q);
    propagate_covariance(P_dense, F, q, dt);
    propagate_covariance(P_sparse, error_dynamics_blocks(C, w, f, wie, q), q, dt);
    EXPECT_LT(rel_diff(P_sparse, P_dense), 1e-13);
    // And the second-order term is there: a first-order Phi differs.
    Mat21 Phi1 = Mat21::Identity() + F * dt;
    const Mat21 P_first = Phi1 * random_covariance(1) * Phi1.transpose();
    EXPECT_GT(rel_diff(P_first, P_dense), 1e-6);
  }
}

TEST(FilterCovariance, MultipliedOutJosephEqualsTextbookForm) {
  const Mat21 P0 = random_covariance(2);
  Eigen::Matrix<double, 3, kStateDim> H = Eigen::Matrix<double, 3, kStateDim>::Random();
  const Vec3 dz(0.03, -0.01, 0.02);
  const Mat3 R = Vec3(0.02, 0.03, 0.01).cwiseAbs2().asDiagonal();
  Mat21 P = P0;
  Vec21 dx = Vec21::Zero();
  const UpdateReport rep = ekf_update<3>(P, dx, H, dz, R);
  ASSERT_TRUE(rep.accepted);
  const Mat3 S = H * P0 * H.transpose() + R;
  const Eigen::Matrix<double, kStateDim, 3> K = P0 * H.transpose() * S.inverse();
  Mat21 IKH = Mat21::Identity() - K * H;
  const Mat21 joseph = IKH * P0 * IKH.transpose() + K * R * K.transpose();
  EXPECT_LT(rel_diff(P, joseph), 1e-12);
  EXPECT_LT(rel_diff(P, Mat21(P0 - K * H * P0)), 1e-10);
  EXPECT_LT((dx - K * dz).norm(), 1e-12 * (K * dz).norm());
  EXPECT_NEAR(rep.nis, dz.dot(S.inverse() * dz), 1e-12 * rep.nis);
  EXPECT_EQ((P - P.transpose()).cwiseAbs().maxCoeff(), 0.0);
}

TEST(FilterCovariance, ConsiderStatesOfAnUpdateKeepTheirEstimateAndCovariance) {
  // A gain mask (ProcessNoise::velocity_gain) makes states Schmidt "consider" states of one
  // update: their rows of K are zero, so their estimate and their own covariance block do
  // not move, the other states' gains are the optimal ones (they see the consider states'
  // covariance), and P is the Joseph covariance of that suboptimal K. Also for the stacked
  // states of the centralized filter.
  const Mat21 P0 = random_covariance(3);
  const Eigen::Matrix<double, 3, kStateDim> H = Eigen::Matrix<double, 3, kStateDim>::Random();
  const Vec3 dz(0.03, -0.01, 0.02);
  const Mat3 R = Vec3(0.02, 0.03, 0.01).cwiseAbs2().asDiagonal();
  Vec21 mask = Vec21::Ones();
  mask(PHI + 2) = mask(SG + 1) = mask(SG + 2) = 0.0;
  Mat21 P = P0;
  Vec21 dx = Vec21::Zero();
  ASSERT_TRUE((ekf_update<3, kStateDim>(P, dx, H, dz, R, 0.0, nullptr, &mask).accepted));
  const Mat3 S = H * P0 * H.transpose() + R;
  const Eigen::Matrix<double, kStateDim, 3> K_opt = P0 * H.transpose() * S.inverse();
  const Eigen::Matrix<double, kStateDim, 3> K = mask.asDiagonal() * K_opt;
  const Mat21 IKH = Mat21::Identity() - K * H;
  const Mat21 joseph = IKH * P0 * IKH.transpose() + K * R * K.transpose();
  EXPECT_LT(rel_diff(P, joseph), 1e-12);
  EXPECT_LT((dx - K * dz).norm(), 1e-12 * (K * dz).norm());
  for (int k : {PHI + 2, SG + 1, SG + 2}) {
    EXPECT_EQ(dx(k), 0.0);
    EXPECT_NEAR(P(k, k), P0(k, k), 1e-15 * P0(k, k));
  }
  EXPECT_NE(dx(V), 0.0);
  // The masked update is no better than the optimal one (trace), and the same where nothing
  // is masked.
  Mat21 P_opt = P0;
  Vec21 dx_opt = Vec21::Zero();
  ekf_update<3>(P_opt, dx_opt, H, dz, R);
  EXPECT_GE(P.trace(), P_opt.trace());
  Mat21 P_all = P0;
  Vec21 dx_all = Vec21::Zero();
  const Vec21 ones = Vec21::Ones();
  ekf_update<3, kStateDim>(P_all, dx_all, H, dz, R, 0.0, nullptr, &ones);
  EXPECT_LT(rel_diff(P_all, P_opt), 1e-14);

  using Mat63 = Eigen::Matrix<double, 63, 63>;
  using Vec63 = Eigen::Matrix<double, 63, 1>;
  Mat63 A = Mat63::Random();
  const Mat63 Q0 = A * A.transpose() * 1e-3 + Mat63::Identity() * 1e-4;
  const Eigen::Matrix<double, 3, 63> Hb = Eigen::Matrix<double, 3, 63>::Random();
  Vec63 mb = Vec63::Ones();
  mb(SG + 1) = mb(kStateDim + SG + 2) = mb(2 * kStateDim + SG + 2) = 0.0;
  Mat63 Q = Q0;
  Vec63 db = Vec63::Zero();
  ASSERT_TRUE((ekf_update<3, 63>(Q, db, Hb, dz, R, 0.0, nullptr, &mb).accepted));
  const Eigen::Matrix<double, 63, 3> Kb = mb.asDiagonal() * (Q0 * Hb.transpose() * (Hb * Q0 * Hb.transpose() + R).inverse());
  const Mat63 IKHb = Mat63::Identity() - Kb * Hb;
  const Mat63 jb = IKHb * Q0 * IKHb.transpose() + Kb * R * Kb.transpose();
  EXPECT_LT((Q - jb).cwiseAbs().maxCoeff(), 1e-12 * jb.cwiseAbs().maxCoeff());
  EXPECT_EQ(db(kStateDim + SG + 2), 0.0);
}

TEST(FilterCovariance, StackedStateUpdateEqualsTextbookJoseph) {
  // The centralized filter's update over 3 x 21 stacked states (ekf_update<3, 63>, which
  // updates the lower triangle and mirrors it) against the textbook Joseph form.
  using Mat63 = Eigen::Matrix<double, 63, 63>;
  Mat63 A = Mat63::Random();
  const Mat63 P0 = A * A.transpose() * 1e-3 + Mat63::Identity() * 1e-4;
  const Eigen::Matrix<double, 3, 63> H = Eigen::Matrix<double, 3, 63>::Random();
  const Vec3 dz(0.03, -0.01, 0.02);
  const Mat3 R = Vec3(0.02, 0.03, 0.01).cwiseAbs2().asDiagonal();
  Mat63 P = P0;
  Eigen::Matrix<double, 63, 1> dx = Eigen::Matrix<double, 63, 1>::Zero();
  ASSERT_TRUE((ekf_update<3, 63>(P, dx, H, dz, R).accepted));
  const Mat3 S = H * P0 * H.transpose() + R;
  const Eigen::Matrix<double, 63, 3> K = P0 * H.transpose() * S.inverse();
  const Mat63 IKH = Mat63::Identity() - K * H;
  const Mat63 joseph = IKH * P0 * IKH.transpose() + K * R * K.transpose();
  EXPECT_LT((P - joseph).cwiseAbs().maxCoeff(), 1e-12 * joseph.cwiseAbs().maxCoeff());
  EXPECT_LT((dx - K * dz).norm(), 1e-12 * (K * dz).norm());
  EXPECT_EQ((P - P.transpose()).cwiseAbs().maxCoeff(), 0.0);
}

TEST(FilterCovariance, LowerRateTimeUpdateFollowsThePerEpochOne) {
  // A Wheel-IMU spinning at 14 rad/s about its x-axis (the axle) while the vehicle turns
  // slowly: C_b^w turns by 0.7 rad within one 0.05 s covariance interval, which the
  // integrated F must capture. 20 s at 200 Hz without updates; the P of both runs must
  // agree to 1e-3 (with a first-order Phi the gap was 1 %, growing with the interval).
  const auto run = [](double interval) {
    StrapdownEkf ekf;
    ekf.set_covariance_interval(interval);
    NavState s;
    s.q_ItoW = quat_from_euler(Vec3(0.0, 0.0, 0.5));
    MechanizationOptions mech;
    mech.omega_ie_inW = Vec3(6.3e-5, 0.0, -3.7e-5);
    ekf.initialize(s, ImuErrors{}, ProcessNoise{}, InitialUncertainty{}, mech);
    const double dt = 0.005, spin = 14.0, yaw_rate = 0.2;
    double angle = 0.0;
    for (int k = 1; k <= 4000; ++k) {
      ImuSample x;
      x.t = k * dt;
      x.dt = dt;
      x.dtheta = Vec3(spin, yaw_rate * std::sin(angle), yaw_rate * std::cos(angle)) * dt;
      // Gravity seen by the spinning IMU (the vehicle level, no acceleration).
      x.dvel = Vec3(0.0, -9.8 * std::sin(angle), -9.8 * std::cos(angle)) * dt;
      angle += spin * dt;
      ekf.propagate(x);
    }
    ekf.flush_covariance();
    return ekf.covariance();
  };
  const Mat21 P_epoch = run(0.0), P_20hz = run(0.05);
  for (int i = 0; i < kStateDim; ++i)
    EXPECT_NEAR(std::sqrt(P_20hz(i, i)), std::sqrt(P_epoch(i, i)), 1e-3 * std::sqrt(P_epoch(i, i)))
        << "state " << i;
  EXPECT_LT(rel_diff(P_20hz, P_epoch), 1e-3);
}
