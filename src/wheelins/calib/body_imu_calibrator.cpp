// A Body-IMU's mounting (docs/filter.md section 15): the roll and pitch from the principal
// axis of its rates while turning, the yaw and the position by a chunk-centred
// least-squares fit of its lateral specific force against the Wheel-IMUs' axles, each with
// a prior.
#include "wheelins/calib/body_imu_calibrator.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "wheelins/calib/prior.hpp"

namespace wheelins {

using calib_detail::kMaxGap;
using calib_detail::rate_bin_index;
using calib_detail::reserve_bins;
using calib_detail::std_of_mean;
using calib_detail::with_prior;

BodyImuCalibrator::BodyImuCalibrator(const ImuModule& module, double static_start, double static_end,
                                     const InstallationCalibrationOptions& opt, double expected_end)
    : module_(module),
      opt_(opt),
      C_BtoV_(dcm_from_euler(module.mounting_rpy)),
      static_{static_start, static_end} {
  reserve_bins(bins_, static_end, expected_end, opt_.yaw_bin_s);
}

void BodyImuCalibrator::add(const ImuSample& s) {
  if (!(s.dt > 0.0)) return;
  t_ = s.t;
  if (static_.take(s)) return;
  if (s.dt > kMaxGap) return;
  if (chunk_start_ < 0.0) chunk_start_ = s.t;
  const Vec3 bias = static_.gyro_bias();
  const Vec3 w = C_BtoV_ * (s.dtheta / s.dt - bias);
  const std::ptrdiff_t k = rate_bin_index(s, static_.end, opt_.yaw_bin_s);
  if (k >= 0) {  // the series of estimate_body_yaw()
    BodyBin& b = bins_.at(static_cast<std::size_t>(k));
    b.dt += s.dt;
    b.w += w * s.dt;
    b.f += C_BtoV_ * s.dvel;
  }
  const double wz = std::abs(w.z());
  if (wz > opt_.min_yaw_rate) {
    turn_chunk_ += w * w.transpose() * s.dt;
    turn_chunk_time_ += s.dt;
    yaw_sum_ += w.z() * s.dt;
  }
  if (s.t - chunk_start_ >= opt_.chunk_s) close_chunk();
}

namespace {

/// The principal axis of a rate scatter matrix, with a positive z.
Vec3 principal_axis(const Mat3& M) {
  const Eigen::SelfAdjointEigenSolver<Mat3> es(M);
  Vec3 a = es.eigenvectors().col(2);  // eigenvalues ascending
  return a.z() < 0.0 ? Vec3(-a) : a;
}

}  // namespace

void BodyImuCalibrator::close_chunk() {
  if (turn_chunk_time_ > 2.0) {
    const Vec3 a = principal_axis(turn_chunk_);
    axis_sum_ += a;
    axis_sq_ += a.cwiseProduct(a);
    ++axis_chunks_;
  }
  turn_all_ += turn_chunk_;
  turn_time_ += turn_chunk_time_;
  turn_chunk_ = Mat3::Zero();
  turn_chunk_time_ = 0.0;
  chunk_start_ = t_;
}

BodyImuCalibration BodyImuCalibrator::result() const {
  BodyImuCalibration r;
  r.module = module_.name;
  r.manifest_mounting_rpy = module_.mounting_rpy;
  const double inf = std::numeric_limits<double>::infinity();
  // The open chunk counts in the estimates (not in their scatter).
  const Mat3 M = turn_all_ + turn_chunk_;
  r.turning_time = turn_time_ + turn_chunk_time_;
  double ex = 0.0, ey = 0.0, sx = inf, sy = inf;
  if (axis_chunks_ >= 3 && M(2, 2) > 0.0) {
    const Vec3 a = principal_axis(M);
    ex = a.x();
    ey = a.y();
    const double n = axis_chunks_;
    // A residual gyro bias b adds b_x * sum(w_z dt) to M_xz.
    const double arw_static = static_.gyro_bias_noise(module_.noise.gyro_arw);
    const double bias_term =
        std::hypot(module_.noise.gyro_bias_std, arw_static) * std::abs(yaw_sum_) / M(2, 2);
    sx = std_of_mean(axis_sum_.x(), axis_sq_.x(), n, bias_term);
    sy = std_of_mean(axis_sum_.y(), axis_sq_.y(), n, bias_term);
  }
  // The rotation that carries the turn axis a onto v z: phi_x = a_y, phi_y = -a_x.
  r.tilt_x = with_prior(0.0, opt_.body_mounting_prior_std, ey, sy, opt_.observed_ratio);
  r.tilt_y = with_prior(0.0, opt_.body_mounting_prior_std, -ex, sx, opt_.observed_ratio);
  r.yaw = CalibratedValue{0.0, opt_.body_mounting_prior_std, false};
  r.manifest_position = module_.p_inV;
  r.position_x = r.position_y = CalibratedValue{0.0, opt_.position_prior_std, false};

  const Mat3 R = dcm_from_rotvec(Vec3(r.tilt_x.value, r.tilt_y.value, 0.0));
  r.mounting_rpy = euler_from_dcm(R * C_BtoV_);
  return r;
}

void estimate_body_yaw(const BodyImuCalibrator& body, const std::vector<const WheelImuCalibrator*>& wheels,
                       const std::vector<WheelImuCalibration>& wheel_results,
                       const InstallationCalibrationOptions& opt, BodyImuCalibration& r) {
  r.yaw = CalibratedValue{0.0, opt.body_mounting_prior_std, false};
  r.manifest_position = body.module().p_inV;
  r.position_x = CalibratedValue{0.0, opt.position_prior_std, false};
  r.position_y = CalibratedValue{0.0, opt.position_prior_std, false};
  const Mat3 R_tilt = dcm_from_rotvec(Vec3(r.tilt_x.value, r.tilt_y.value, 0.0));
  const Mat3 C_BtoV = dcm_from_euler(body.module().mounting_rpy);
  auto finish = [&] { r.mounting_rpy = euler_from_dcm(dcm_from_rotvec(Vec3(0.0, 0.0, r.yaw.value)) * R_tilt * C_BtoV); };
  const double bin_s = opt.yaw_bin_s;
  if (wheels.empty() || wheel_results.size() != wheels.size() || !(bin_s > 0.0) || !(opt.chunk_s > 0.0))
    return finish();
  std::size_t n = body.bins().end_index();
  for (const auto* w : wheels) n = std::min(n, w->axle_bins().end_index());
  if (n < 3) return finish();

  // Each Wheel-IMU's axle, the estimated one, as a row in its manifest b-frame, signed to
  // point along v y; the wheels' mean position.
  std::vector<Vec3> axle(wheels.size());
  Vec3 p_wheels = Vec3::Zero();
  for (std::size_t i = 0; i < wheels.size(); ++i) {
    const ImuModule& w = wheels[i]->module();
    const Mat3 R = dcm_from_euler(wheel_results[i].mounting_rpy) * dcm_from_euler(w.mounting_rpy).transpose();
    axle[i] = w.axle_sign * (R.transpose() * Vec3::UnitX());
    p_wheels += w.p_inV / static_cast<double>(wheels.size());
  }
  const Vec3 dp = body.module().p_inV - p_wheels;  // the manifest's offset

  // Per full bin (every module sampled over 90 % of it), in index order: the Body-IMU's yaw
  // rate and specific force (tilt-corrected v-frame), the wheels' mean axle specific force.
  struct Bin {
    std::size_t k = 0;
    double yaw_rate = 0.0, f_x = 0.0, f_y = 0.0, f_axle = 0.0;
  };
  std::vector<Bin> bins;
  for (const auto& e : body.bins().entries()) {
    if (e.index >= n) break;
    const BodyBin& b = e.bin;
    if (b.dt < 0.9 * bin_s) continue;  // a gap, or the last bin
    Bin x;
    x.k = e.index;
    x.yaw_rate = (R_tilt * b.w).z() / b.dt;
    const Vec3 f = R_tilt * b.f / b.dt;
    x.f_x = f.x();
    x.f_y = f.y();
    bool ok = true;
    for (std::size_t i = 0; i < wheels.size() && ok; ++i) {
      const AxleBin* wb = wheels[i]->axle_bins().find(e.index);
      ok = wb && wb->dt >= 0.9 * bin_s;
      if (ok) x.f_axle += axle[i].dot(wb->f) / wb->dt / static_cast<double>(wheels.size());
    }
    if (ok) bins.push_back(x);
  }

  // Least squares with an intercept per chunk: the sums of each chunk, centred.
  struct Chunk {
    double n = 0.0, y = 0.0, yy = 0.0;
    Vec3 x = Vec3::Zero(), xy = Vec3::Zero();
    Mat3 xx = Mat3::Zero();
    Mat3 XX() const { return xx - x * x.transpose() / n; }
    Vec3 XY() const { return xy - x * y / n; }
    double YY() const { return yy - y * y / n; }
  };
  std::vector<Chunk> chunks;  // those with bins, in time order
  std::size_t last_chunk = 0;
  for (std::size_t j = 1; j + 1 < bins.size(); ++j) {
    const Bin &b0 = bins[j - 1], &b = bins[j], &b1 = bins[j + 1];
    if (b0.k + 1 != b.k || b.k + 1 != b1.k) continue;  // three consecutive full bins
    const std::size_t k = b.k;
    const double yaw_acc = (b1.yaw_rate - b0.yaw_rate) / (2.0 * bin_s);
    const double w2 = b.yaw_rate * b.yaw_rate;
    // The lateral specific force the Body-IMU reads beyond the wheels' axles: with the
    // manifest's offset taken out, delta f_x and the offset's correction are left.
    const double y = b.f_y - b.f_axle - (yaw_acc * dp.x() - w2 * dp.y());
    const Vec3 x(b.f_x, yaw_acc, -w2);
    const auto c = static_cast<std::size_t>(std::floor(static_cast<double>(k) * bin_s / opt.chunk_s));
    if (chunks.empty() || c != last_chunk) chunks.emplace_back();
    last_chunk = c;
    Chunk& ch = chunks.back();
    ch.n += 1.0;
    ch.y += y;
    ch.yy += y * y;
    ch.x += x;
    ch.xy += x * y;
    ch.xx += x * x.transpose();
  }
  Mat3 N = Mat3::Zero();
  Vec3 B = Vec3::Zero();
  double YY = 0.0, rows = 0.0, used = 0.0;
  for (const Chunk& ch : chunks) {
    if (ch.n < 3.0) continue;
    N += ch.XX();
    B += ch.XY();
    YY += ch.YY();
    rows += ch.n;
    used += 1.0;
  }
  r.yaw_bins = static_cast<int>(rows);
  const double dof = rows - used - 3.0;
  if (used < 3.0 || !(dof > 0.0) || !(N(0, 0) > 0.0)) return finish();
  r.yaw_excitation = std::sqrt(N(0, 0) / rows);
  const Eigen::LDLT<Mat3> ldlt(N);
  if (ldlt.info() != Eigen::Success || !(ldlt.rcond() > 1e-12)) return finish();
  const Vec3 theta = ldlt.solve(B);
  const double s2 = std::max(0.0, YY - theta.dot(B)) / dof;
  r.yaw_residual_rms = std::sqrt(s2);
  const Mat3 Ni = ldlt.solve(Mat3::Identity());
  // Its covariance: least squares (bins taken as independent), and the chunks' scores
  // (what is correlated between bins: the terrain, vibration, slow biases): the larger.
  Mat3 G = Mat3::Zero();
  for (const Chunk& ch : chunks) {
    if (ch.n < 3.0) continue;
    const Vec3 g = ch.XY() - ch.XX() * theta;
    G += g * g.transpose();
  }
  const Mat3 cov_chunks = Ni * G * Ni * (used / (used - 1.0));
  auto sigma = [&](int i) { return std::sqrt(std::max(s2 * Ni(i, i), cov_chunks(i, i))); };
  // The manifest frame is the true one turned by delta about v z: the correction is -delta.
  r.yaw = with_prior(0.0, opt.body_mounting_prior_std, -theta(0), sigma(0), opt.observed_ratio);
  r.position_x = with_prior(0.0, opt.position_prior_std, theta(1), sigma(1), opt.observed_ratio);
  r.position_y = with_prior(0.0, opt.position_prior_std, theta(2), sigma(2), opt.observed_ratio);
  finish();
}

}  // namespace wheelins
