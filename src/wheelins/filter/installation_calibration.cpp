// The Wheel-IMU installation calibrator of installation_calibration.hpp: whole-turn,
// angle-weighted means of the rate and specific force, the axle from their rotation
// vectors, the lever arm by a chunk-centred least-squares fit, each with a prior.
#include "wheelins/filter/installation_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

namespace wheelins {

namespace {

constexpr double kTurn = 2.0 * kPi;
/// A sample interval longer than this is a gap in the data (a dropout, a removed stretch).
constexpr double kMaxGap = 0.1;

/// The 1 sigma of a mean over n samples from their sum and sum of squares (the sample
/// variance with n - 1), with a systematic term added in quadrature.
double std_of_mean(double sum, double sum_sq, double n, double systematic) {
  const double mean = sum / n;
  const double var = std::max(0.0, (sum_sq / n - mean * mean) * n / (n - 1.0));
  return std::sqrt(var / n + systematic * systematic);
}

/// A data estimate (value, sigma; sigma = inf: no data) combined with a zero-mean-offset
/// Gaussian prior around `prior`.
CalibratedValue with_prior(double prior, double prior_std, double data, double data_std,
                           double observed_ratio) {
  CalibratedValue v;
  if (!(data_std < 1e300) || !std::isfinite(data)) {
    v.value = prior;
    v.std = prior_std;
    return v;
  }
  const double wp = 1.0 / (prior_std * prior_std), wd = 1.0 / (data_std * data_std);
  v.value = (wp * prior + wd * data) / (wp + wd);
  v.std = std::sqrt(1.0 / (wp + wd));
  v.observed = v.std < observed_ratio * prior_std;
  return v;
}

/// The index of the rate-series bin a sample falls in (bins of `bin_s` from the static
/// period's end, by the sample's mid-time); -1 before the first bin or without bins.
std::ptrdiff_t rate_bin_index(const ImuSample& s, double static_end, double bin_s) {
  if (!(bin_s > 0.0)) return -1;
  const double k = std::floor((s.t - 0.5 * s.dt - static_end) / bin_s);
  return k >= 0.0 && k < 1e8 ? static_cast<std::ptrdiff_t>(k) : -1;
}

/// Room for the bins up to `expected_end`, at most 2^18 of them (a hint: the series grows
/// with the data; a time span alone never sizes memory).
template <class Bin>
void reserve_bins(BinSeries<Bin>& bins, double static_end, double expected_end, double bin_s) {
  const double span = expected_end - static_end;
  if (std::isfinite(span) && span > 0.0 && bin_s > 0.0)
    bins.reserve(static_cast<std::size_t>(std::min(span / bin_s, 262144.0)) + 2);
}

}  // namespace

WheelImuCalibrator::WheelImuCalibrator(const ImuModule& module, double static_start,
                                       double static_end, const InstallationCalibrationOptions& opt,
                                       double expected_end)
    : module_(module),
      opt_(opt),
      C_StoB_(wheel_sensor_to_body(module)),
      static_{static_start, static_end} {
  reserve_bins(bins_, static_end, expected_end, opt_.rate_bin_s);
  reserve_bins(axle_bins_, static_end, expected_end, opt_.yaw_bin_s);
}

void WheelImuCalibrator::add(const ImuSample& s) {
  if (!(s.dt > 0.0)) return;
  t_ = s.t;
  if (static_.take(s)) return;
  const Vec3 bias = static_.gyro_bias();
  const Vec3 w = C_StoB_ * (s.dtheta / s.dt - bias);
  const Vec3 f = C_StoB_ * (s.dvel / s.dt);
  const double wx = w.x();
  wheel_angle_ = std::fmod(wheel_angle_ + wx * s.dt, kTurn);
  if (s.dt <= kMaxGap) {
    const std::ptrdiff_t j = rate_bin_index(s, static_.end, opt_.yaw_bin_s);
    if (j >= 0) {  // the series of estimate_body_yaw()
      AxleBin& a = axle_bins_.at(static_cast<std::size_t>(j));
      a.dt += s.dt;
      a.f += f * s.dt;
    }
    // The rate series (RateBin::yaw_rate()).
    const std::ptrdiff_t k = rate_bin_index(s, static_.end, opt_.rate_bin_s);
    if (k >= 0) {
      RateBin& b = bins_.at(static_cast<std::size_t>(k));
      b.dt += s.dt;
      b.spin += -module_.axle_sign * wx * s.dt;
      b.wf += (w.y() * f.y() + w.z() * f.z()) * s.dt;
      b.w_y += w.y() * s.dt;
      b.w_z += w.z() * s.dt;
      b.f_y += f.y() * s.dt;
      b.f_z += f.z() * s.dt;
      const double a_mid = wheel_angle_ + 0.5 * wx * s.dt;
      b.cos_a += std::cos(a_mid) * s.dt;
      b.sin_a += std::sin(a_mid) * s.dt;
    }
  }
  const double alpha = have_prev_ ? (wx - prev_wx_) / s.dt : 0.0;
  prev_wx_ = wx;
  have_prev_ = true;
  const int sign = wx > 0.0 ? 1 : -1;
  if (std::abs(wx) < opt_.min_spin_rate || (spin_sign_ != 0 && sign != spin_sign_) ||
      s.dt > kMaxGap) {
    // Stopped, reversing, or a gap in the data: the partial turn is dropped (its rotating
    // terms do not cancel).
    reset_turns();
    spin_sign_ = std::abs(wx) < opt_.min_spin_rate ? 0 : sign;
    return;
  }
  spin_sign_ = sign;
  rolling_time_ += s.dt;
  const double angle = std::abs(wx) * s.dt;
  spin_angle_ += angle;
  // Each of the kPhases accumulators starts its turns at its own phase of the rolling
  // sequence and splits the sample at its turn boundaries, so each turn spans exactly 2 pi.
  const double a0 = sequence_angle_, a1 = a0 + angle;
  for (int k = 0; k < kPhases; ++k) {
    TurnSums& turn = turn_[k];
    double pos = std::max(a0, k * kTurn / kPhases);
    while (pos < a1) {
      const double take = std::min(a1 - pos, kTurn - turn.angle);
      const double frac = take / angle;
      turn.angle += take;
      turn.dt += frac * s.dt;
      turn.c += wx * wx * take;
      turn.s += alpha * take;
      turn.f += f * take;
      turn.rot += (sign * frac * s.dt) * w;
      pos += take;
      if (turn.angle >= kTurn * (1.0 - 1e-12)) close_turn(k);
    }
  }
  sequence_angle_ = a1;
}

void WheelImuCalibrator::close_turn(int phase) {
  const TurnSums& turn = turn_[phase];
  const double c = turn.c / kTurn, sa = turn.s / kTurn;
  const Vec3 m = turn.f / kTurn;
  RegressionSums& k = chunk_;
  k.n += 1.0;
  k.c += c;
  k.s += sa;
  k.cc += c * c;
  k.ss += sa * sa;
  k.m += m;
  k.cm += c * m;
  k.sm += sa * m;
  k.mm += m * m.transpose();
  if (phase == 0) {
    axle_sum_ += turn.rot;
    const double len = turn.rot.norm();
    if (len > 0.0) {
      const Vec3 d = turn.rot / len;
      dir_sum_ += d;
      dir_sq_ += d.cwiseProduct(d);
    }
    ++turns_;
  }
  turn_[phase] = TurnSums{};
  if (t_ - chunk_start_ >= opt_.chunk_s) close_chunk();
}

void WheelImuCalibrator::close_chunk() {
  const RegressionSums& k = chunk_;
  if (k.n >= 2.0) {
    Scc_ += k.cc - k.c * k.c / k.n;
    Sss_ += k.ss - k.s * k.s / k.n;
    Scm_ += k.cm - k.c * k.m / k.n;
    Ssm_ += k.sm - k.s * k.m / k.n;
    Smm_ += k.mm - k.m * k.m.transpose() / k.n;
    chunks_ += 1.0;
    rows_ += 2.0 * k.n;
  }
  chunk_ = RegressionSums{};
  chunk_start_ = t_;
}

WheelImuCalibration WheelImuCalibrator::result() const {
  WheelImuCalibration r;
  r.module = module_.name;
  r.turns = turns_;
  r.spin_angle = spin_angle_;
  r.manifest_mounting_rpy = module_.mounting_rpy;
  r.manifest_lever_arm = module_.lever_arm_inB;
  const double inf = std::numeric_limits<double>::infinity();
  const bool enough = turns_ >= opt_.min_turns;

  // Axle: the direction of the summed rotation vectors, and the small rotation
  // delta = a x e_x that carries it onto b x. Its sigma: the scatter of the per-turn
  // directions over sqrt(turns), and a residual gyro bias over the rolling time.
  double dy = 0.0, dz = 0.0, sy = inf, sz = inf;
  if (enough && axle_sum_.norm() > 0.0) {
    const Vec3 a = axle_sum_.normalized();
    dy = a.z();
    dz = -a.y();
    const double n = turns_;
    const double arw_static = static_.gyro_bias_noise(module_.noise.gyro_arw);
    const double bias_term = std::hypot(module_.noise.gyro_bias_std, arw_static) * rolling_time_ / spin_angle_;
    sy = std_of_mean(dir_sum_.z(), dir_sq_.z(), n, bias_term);  // delta_y is a_z
    sz = std_of_mean(dir_sum_.y(), dir_sq_.y(), n, bias_term);
  }
  r.axle_tilt_y = with_prior(0.0, opt_.mounting_prior_std, dy, sy, opt_.observed_ratio);
  r.axle_tilt_z = with_prior(0.0, opt_.mounting_prior_std, dz, sz, opt_.observed_ratio);
  const Mat3 R = dcm_from_rotvec(Vec3(0.0, r.axle_tilt_y.value, r.axle_tilt_z.value));
  r.mounting_rpy = euler_from_dcm(R * C_StoB_ * axle_axis_permutation(module_.axle_axis).transpose());

  // Lever arm, in the corrected frame: the chunk-centred sums (the open chunk included)
  // rotated by R; the normal matrix of (l_y, l_z) is (Scc + Sss) I.
  double Scc = Scc_, Sss = Sss_, rows = rows_, chunks = chunks_;
  Vec3 Scm = Scm_, Ssm = Ssm_;
  Mat3 Smm = Smm_;
  const RegressionSums& k = chunk_;
  if (k.n >= 2.0) {
    Scc += k.cc - k.c * k.c / k.n;
    Sss += k.ss - k.s * k.s / k.n;
    Scm += k.cm - k.c * k.m / k.n;
    Ssm += k.sm - k.s * k.m / k.n;
    Smm += k.mm - k.m * k.m.transpose() / k.n;
    chunks += 1.0;
    rows += 2.0 * k.n;
  }
  const Vec3 cm = R * Scm, sm = R * Ssm;
  const Mat3 mm = R * Smm * R.transpose();
  const double D = Scc + Sss;
  const double dof = rows - 2.0 * chunks - 2.0;
  double ly = 0.0, lz = 0.0, sl = inf;
  if (enough && D > 0.0 && dof > 0.0) {
    const double ry = cm.y() - sm.z(), rz = sm.y() + cm.z();
    ly = ry / D;
    lz = rz / D;
    const double rss = std::max(0.0, mm(1, 1) + mm(2, 2) - (ly * ry + lz * rz));
    const double s2 = rss / dof;
    r.accel_residual_rms = std::sqrt(s2);
    // The phases' turns overlap: kPhases times fewer independent rows. The accelerometer's
    // scale factor scales the centripetal term, and so the lever arm: a floor.
    const double sf = module_.noise.acc_sf_std * module_.lever_arm_inB.tail<2>().norm();
    sl = std::sqrt(kPhases * s2 / D + sf * sf);
  }
  const Vec3 prior = R * module_.lever_arm_inB;
  r.lever_arm[0] = CalibratedValue{prior.x(), opt_.lever_arm_prior_std, false};
  r.lever_arm[1] = with_prior(prior.y(), opt_.lever_arm_prior_std, ly, sl, opt_.observed_ratio);
  r.lever_arm[2] = with_prior(prior.z(), opt_.lever_arm_prior_std, lz, sl, opt_.observed_ratio);
  r.manifest_wheel_radius = module_.wheel_radius;
  r.wheel_radius = CalibratedValue{module_.wheel_radius, opt_.radius_prior_std * module_.wheel_radius, false};
  return r;
}

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

void estimate_relative_radius(const std::vector<const WheelImuCalibrator*>& cals,
                              const InstallationCalibrationOptions& opt,
                              std::vector<WheelImuCalibration>& results) {
  const std::size_t n_mod = cals.size();
  if (n_mod < 2 || results.size() != n_mod || !(opt.rate_bin_s > 0.0)) return;
  double ymin = std::numeric_limits<double>::infinity(), ymax = -ymin;
  for (const auto* c : cals) {
    ymin = std::min(ymin, c->module().p_inV.y());
    ymax = std::max(ymax, c->module().p_inV.y());
  }
  if (!(ymax - ymin > 0.05)) return;  // one side only (e.g. the chips of one wheel)
  const double mid = 0.5 * (ymin + ymax);
  std::vector<int> side(n_mod);
  double y_side[2] = {0.0, 0.0};
  int n_side[2] = {0, 0};
  std::size_t bins = std::numeric_limits<std::size_t>::max();
  for (std::size_t i = 0; i < n_mod; ++i) {
    side[i] = cals[i]->module().p_inV.y() < mid ? 0 : 1;  // 0: left (v-frame y is right)
    y_side[side[i]] += cals[i]->module().p_inV.y();
    ++n_side[side[i]];
    bins = std::min(bins, cals[i]->rate_bins().end_index());
  }
  // The bins any module has data in (below the shortest series' end), in order.
  std::vector<std::size_t> indices;
  for (const auto* c : cals)
    for (const auto& e : c->rate_bins().entries())
      if (e.index < bins) indices.push_back(e.index);
  std::sort(indices.begin(), indices.end());
  indices.erase(std::unique(indices.begin(), indices.end()), indices.end());
  y_side[0] /= n_side[0];
  y_side[1] /= n_side[1];

  // Per module i, against the other side's mean speed, the fit
  //   y = track psi_dot - (v_L - v_R) = g_i v_mean + kappa_i track psi_dot,
  // with g_i = eps_i - mean eps(right) for a left module, mean eps(left) - eps_i for a
  // right one (eps: a radius's relative error, the gyro's x scale factor included: the
  // speed the filter is given is r w_x). psi_dot: the mean yaw rate of every module.
  struct Fit {
    double S11 = 0, S12 = 0, S22 = 0, b1 = 0, b2 = 0, Syy = 0;
    int n = 0;
  };
  std::vector<Fit> fit(n_mod);
  std::vector<double> v(n_mod);
  std::vector<char> ok(n_mod);
  for (const std::size_t k : indices) {
    double v_side[2] = {0, 0}, yaw = 0;
    int m[2] = {0, 0};
    for (std::size_t i = 0; i < n_mod; ++i) {
      const RateBin* b = cals[i]->rate_bins().find(k);
      ok[i] = 0;
      if (!b || b->dt < 0.9 * opt.rate_bin_s) continue;  // a gap, or the last bin
      const double rate = b->yaw_rate(cals[i]->gravity());
      if (!std::isfinite(rate)) continue;  // too slow for a yaw rate
      v[i] = cals[i]->module().wheel_radius * b->spin / b->dt;
      v_side[side[i]] += v[i];
      yaw += rate;
      ++m[side[i]];
      ok[i] = 1;
    }
    if (m[0] == 0 || m[1] == 0) continue;
    const double psi_dot = yaw / (m[0] + m[1]);
    for (std::size_t i = 0; i < n_mod; ++i) {
      if (!ok[i]) continue;
      const int o = 1 - side[i];
      const double v_other = v_side[o] / m[o];
      const double vl = side[i] == 0 ? v[i] : v_other, vr = side[i] == 0 ? v_other : v[i];
      const double track = std::abs(cals[i]->module().p_inV.y() - y_side[o]);
      const double x1 = 0.5 * (vl + vr), x2 = track * psi_dot, y = x2 - (vl - vr);
      Fit& f = fit[i];
      f.S11 += x1 * x1;
      f.S12 += x1 * x2;
      f.S22 += x2 * x2;
      f.b1 += x1 * y;
      f.b2 += x2 * y;
      f.Syy += y * y;
      ++f.n;
    }
  }
  std::vector<double> g(n_mod, 0.0), sg(n_mod, std::numeric_limits<double>::infinity());
  double D = 0.0, var_D = 0.0;
  for (std::size_t i = 0; i < n_mod; ++i) {
    const Fit& f = fit[i];
    const double det = f.S11 * f.S22 - f.S12 * f.S12;
    if (f.n <= 30 || !(det > 1e-12 * f.S11 * f.S22)) return;  // too little rolling: not observed
    g[i] = (f.S22 * f.b1 - f.S12 * f.b2) / det;
    const double kappa = (f.S11 * f.b2 - f.S12 * f.b1) / det;
    const double s2 = std::max(0.0, f.Syy - g[i] * f.b1 - kappa * f.b2) / (f.n - 2);
    sg[i] = std::sqrt(s2 * f.S22 / det);
    D += g[i];
    var_D += sg[i] * sg[i];
  }
  // D = mean eps(left) - mean eps(right), from every module's fit; each radius is corrected
  // by its share about the two sides' mean: eps_i - (mean eps(left) + mean eps(right)) / 2.
  D /= static_cast<double>(n_mod);
  var_D /= static_cast<double>(n_mod * n_mod);
  for (std::size_t i = 0; i < n_mod; ++i) {
    const double c = side[i] == 0 ? g[i] - 0.5 * D : -g[i] + 0.5 * D;
    const double sc = std::sqrt(sg[i] * sg[i] + 0.25 * var_D);
    const CalibratedValue rel = with_prior(0.0, opt.radius_prior_std, c, sc, opt.observed_ratio);
    const double m0 = cals[i]->module().wheel_radius;
    results[i].wheel_radius = CalibratedValue{m0 * (1.0 + rel.value), m0 * rel.std, rel.observed};
  }
}

}  // namespace wheelins
