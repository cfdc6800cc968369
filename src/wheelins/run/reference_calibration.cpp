// Calibration against a reference track (reference_calibration.hpp).
#include "wheelins/run/reference_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "wheelins/io/text_util.hpp"
#include "wheelins/io/truth.hpp"
#include "wheelins/run/run.hpp"
#include "wheelins/survey/dataset.hpp"

namespace wheelins {
namespace {

using io_detail::quote;

std::string fmt(const char* f, double a, double b = 0.0, double c = 0.0, double d = 0.0) {
  char buf[240];
  std::snprintf(buf, sizeof buf, f, a, b, c, d);
  return buf;
}

/// A series' per-bin signal at time t (linear; clamped).
struct Sampled {
  const survey::Series* s;
  std::vector<double> x;
  double at(double t) const { return survey::sample_at(*s, x, t); }
};

struct Fit2 {
  double a = 0.0, b = 0.0;       ///< v = a * x + b * y
  double sigma_a = 0.0, corr = 0.0;
  std::size_t n = 0;
};

/// Least squares v = a x + b y over the rows kept; sigma of a from the residuals.
Fit2 ls2(const std::vector<double>& v, const std::vector<double>& x, const std::vector<double>& y,
         const std::vector<std::uint8_t>& keep) {
  Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  double sv = 0.0, svv = 0.0;
  Fit2 f;
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (!keep[k]) continue;
    const Eigen::Vector2d r(x[k], y[k]);
    A += r * r.transpose();
    b += r * v[k];
    sv += v[k];
    svv += v[k] * v[k];
    ++f.n;
  }
  if (f.n < 10 || std::abs(A.determinant()) < 1e-12) return f;
  const Eigen::Vector2d c = A.ldlt().solve(b);
  f.a = c(0), f.b = c(1);
  double ss = 0.0;
  for (std::size_t k = 0; k < v.size(); ++k)
    if (keep[k]) ss += std::pow(v[k] - f.a * x[k] - f.b * y[k], 2);
  const double n = static_cast<double>(f.n);
  f.sigma_a = std::sqrt(ss / std::max(1.0, n - 2.0) * A.inverse()(0, 0));
  const double var = svv - sv * sv / n;
  f.corr = var > 0.0 ? std::sqrt(std::max(0.0, 1.0 - ss / var)) : 0.0;
  return f;
}


/// `floor`, or the standard deviation of the mean of three or more estimates from parts of
/// the drive where that is larger.
double sigma_of_parts(const std::vector<double>& parts, double floor) {
  double sd = floor;
  if (parts.size() >= 3) {
    double mean = 0.0, ss = 0.0;
    for (double a : parts) mean += a;
    mean /= static_cast<double>(parts.size());
    for (double a : parts) ss += (a - mean) * (a - mean);
    sd = std::max(sd, std::sqrt(ss / static_cast<double>(parts.size() - 1) / static_cast<double>(parts.size())));
  }
  return sd;
}

using survey::Signal;
using eval::Vec2;

/// The least-squares scale k of v_ref(t) = k * x(t) + c * yaw(t) over the epochs after `from`
/// faster than `min_speed` (both sides smoothed over 1 s; a second pass without residuals
/// beyond 4 MADs); its 1 sigma from five parts of the drive or the fit's own, the larger.
struct SpeedScale {
  bool observed = false;
  double scale = 0.0, sigma = 0.0, correlation = 0.0;
  std::size_t epochs = 0;
};

template <class RefSpeed>
SpeedScale fit_speed_scale(const RefSpeed& ref_speed, const Signal& x_sig, const Signal& yaw, double from_t,
                           double min_speed) {
  SpeedScale out;
  const double step = 0.05;
  const int smooth = static_cast<int>(std::lround(1.0 / step));
  std::vector<double> v, x, y;
  const double from = std::max(from_t, x_sig.start()), to = x_sig.end();
  for (double t = from; t <= to; t += step) {
    const double vr = ref_speed(t);
    if (!std::isfinite(vr)) continue;
    v.push_back(vr);
    x.push_back(x_sig.at(t));
    y.push_back(yaw.t.empty() ? 0.0 : yaw.at(t));
  }
  v = survey::moving_average(v, smooth);
  x = survey::moving_average(x, smooth);
  y = survey::moving_average(y, smooth);
  std::vector<std::uint8_t> keep(v.size());
  for (std::size_t k = 0; k < v.size(); ++k) keep[k] = v[k] >= min_speed;
  Fit2 f = ls2(v, x, y, keep);
  if (f.n >= 10) {
    std::vector<double> res;
    for (std::size_t k = 0; k < v.size(); ++k)
      if (keep[k]) res.push_back(std::abs(v[k] - f.a * x[k] - f.b * y[k]));
    std::nth_element(res.begin(), res.begin() + static_cast<std::ptrdiff_t>(res.size() / 2), res.end());
    const double mad = res[res.size() / 2];
    for (std::size_t k = 0; k < v.size(); ++k)
      if (keep[k] && std::abs(v[k] - f.a * x[k] - f.b * y[k]) > 4.0 * 1.4826 * mad) keep[k] = 0;
    f = ls2(v, x, y, keep);
  }
  out.epochs = f.n;
  out.correlation = f.corr;
  if (!(f.n >= 100 && f.a > 0.0)) return out;
  std::vector<double> parts;
  const std::size_t len = v.size() / 5;
  for (std::size_t p = 0; p < 5 && len > 0; ++p) {
    std::vector<std::uint8_t> kp(v.size(), 0);
    for (std::size_t k = p * len; k < (p + 1) * len; ++k) kp[k] = keep[k];
    const Fit2 fp = ls2(v, x, y, kp);
    if (fp.n >= 40 && fp.a > 0.0) parts.push_back(fp.a);
  }
  out.observed = true;
  out.scale = f.a;
  out.sigma = sigma_of_parts(parts, f.sigma_a);
  return out;
}

/// The horizontal speed a single Wheel-INS of `module` gives (its own Wheel-INS, the
/// manifest's geometry as it is, no data checks) [m/s] at its records.
Signal wheel_ins_speed(const Manifest& m, const std::string& module) {
  RunRequest req = calibration_run_request(m, {module}, 0.02);
  Signal s;
  req.on_record = [&](const TrajectoryRecord& r) {
    s.t.push_back(r.t);
    s.x.push_back(r.v_inN.head<2>().norm());
  };
  run_navigation(req);
  return s;
}

/// The antenna l (forward, right) from velocities, over the whole drive: the reference
/// moves as the antenna does, v_ref = v_o + psi_dot R(psi) S l (S turns by 90 deg), so in
/// turns its velocity departs from the dead reckoning's reference point's by an amount linear
/// in l -- and velocities carry no accumulated drift, unlike positions. The dead reckoning's
/// velocity and heading are turned by `yaw` (its start alignment) onto the reference's frame.
/// Epochs turning faster than 0.05 rad/s at over 1 m/s; 1 sigma from the residuals, counted
/// over the turns' correlation time (one second's epochs as one).
struct AntennaFit {
  bool found = false;
  Vec2 antenna = Vec2::Zero(), sigma = Vec2::Zero();
};

AntennaFit fit_antenna(const eval::PlanarTrack& ref, const eval::PlanarTrack& traj, double yaw) {
  AntennaFit out;
  auto rot2 = [](double a) {
    Eigen::Matrix2d R;
    R << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
    return R;
  };
  Eigen::Matrix2d S;
  S << 0.0, -1.0, 1.0, 0.0;
  const Eigen::Matrix2d Ry = rot2(yaw);
  Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  std::vector<std::pair<Eigen::Matrix2d, Vec2>> rows;
  std::vector<double> times;
  for (std::size_t k = 1; k + 1 < ref.t.size(); ++k) {
    const double dt = ref.t[k + 1] - ref.t[k - 1];
    if (!(dt > 0.0 && dt < 2.0)) continue;
    const Vec2 v_ref = (ref.p_ne[k + 1] - ref.p_ne[k - 1]) / dt;
    const double t = ref.t[k];
    const auto it = std::lower_bound(traj.t.begin(), traj.t.end(), t);
    if (it == traj.t.begin() || it == traj.t.end()) continue;
    const std::size_t j = static_cast<std::size_t>(it - traj.t.begin());
    // The dead reckoning over the same interval: its mean velocity and its turn rate.
    const auto at = [&](double tt) {
      const auto i2 = std::lower_bound(traj.t.begin(), traj.t.end(), tt);
      return std::min<std::size_t>(static_cast<std::size_t>(i2 - traj.t.begin()), traj.t.size() - 1);
    };
    const std::size_t a0 = at(ref.t[k - 1]), a1 = at(ref.t[k + 1]);
    if (a1 <= a0) continue;
    const double span = traj.t[a1] - traj.t[a0];
    if (!(span > 0.5 * dt)) continue;
    const Vec2 v_o = Ry * (traj.p_ne[a1] - traj.p_ne[a0]) / span;
    const double psi_dot = wrap_pi(traj.heading[a1] - traj.heading[a0]) / span;
    const double psi = traj.heading[j] + yaw;
    if (std::abs(psi_dot) < 0.05 || v_o.norm() < 1.0) continue;
    const Eigen::Matrix2d J = psi_dot * rot2(psi) * S;
    rows.push_back({J, v_ref - v_o});
    times.push_back(t);
    A += J.transpose() * J;
    b += J.transpose() * (v_ref - v_o);
  }
  if (rows.size() < 20 || std::abs(A.determinant()) < 1e-9) return out;
  out.antenna = A.ldlt().solve(b);
  double ss = 0.0;
  for (const auto& r : rows) ss += (r.second - r.first * out.antenna).squaredNorm();
  const double span_turning = static_cast<double>(rows.size()) * (times.size() > 1 ? (times.back() - times.front()) / static_cast<double>(times.size() - 1) : 0.2);
  const double per_second = std::max(1.0, static_cast<double>(rows.size()) / std::max(1.0, span_turning));
  const double sigma2 = ss / std::max(1.0, 2.0 * static_cast<double>(rows.size()) - 2.0) * per_second;
  const Eigen::Matrix2d P = A.inverse() * sigma2;
  out.sigma = Vec2(std::sqrt(P(0, 0)), std::sqrt(P(1, 1)));
  out.found = true;
  return out;
}

/// The reference track on the manifest's local frame, with its speed at its records.
struct ReferenceTrack {
  eval::PlanarTrack track;
  std::vector<double> v;  ///< [m/s] at the records (central differences)
  /// [m/s] at t: linear between the records, NaN outside them.
  double speed(double t) const {
    const auto it = std::lower_bound(track.t.begin(), track.t.end(), t);
    if (it == track.t.begin() || it == track.t.end()) return std::nan("");
    const std::size_t k = static_cast<std::size_t>(it - track.t.begin());
    const double a = (t - track.t[k - 1]) / (track.t[k] - track.t[k - 1]);
    return (1.0 - a) * v[k - 1] + a * v[k];
  }
};

/// The manifest's truth on its local frame, on the manifest's clock; InputError without one or
/// for one too short.
ReferenceTrack read_reference(const Manifest& m) {
  if (!m.truth_file)
    throw InputError(quote(m.path) + ": names no truth: calibrating against a reference needs one (truth: FILE)");
  const TruthData truth = read_truth(m.resolve(*m.truth_file));
  const earth::LocalFrame frame(m.origin);
  ReferenceTrack out;
  eval::PlanarTrack& ref = out.track;
  for (const TruthRecord& r : truth.records) {
    ref.t.push_back(r.t + m.truth_time_offset);
    ref.p_ne.push_back(frame.ned_from_geodetic(r.lla).head<2>());
  }
  if (ref.t.size() < 10) throw InputError(quote(truth.file) + ": fewer than 10 records: too short a reference");
  // The reference's speed at its records (central differences).
  out.v.assign(ref.t.size(), 0.0);
  for (std::size_t k = 1; k + 1 < ref.t.size(); ++k) {
    const double dt = ref.t[k + 1] - ref.t[k - 1];
    if (dt > 0.0) out.v[k] = (ref.p_ne[k + 1] - ref.p_ne[k - 1]).norm() / dt;
  }
  return out;
}

/// What the calibration works from: the manifest as given and with the installation applied,
/// the reference, the modules' series (manifest clocks) and what the data say of them, each
/// module's gyro bias and the vehicle's yaw rate.
struct Drive {
  const Manifest& m0;
  const Manifest& m;
  const std::vector<std::string>& modules;
  const ReferenceCalibrationOptions& o;
  ReferenceTrack ref;
  std::vector<survey::Series> S;
  survey::DatasetSurvey sv;
  std::vector<Vec3> bias;
  Signal yaw;
};

std::vector<survey::Series> read_module_series(const Manifest& m, const std::vector<std::string>& modules) {
  std::vector<survey::Series> S;
  for (const auto& name : modules) {
    const ModuleSpec* spec = m.find(name);
    if (!spec) throw InputError(quote(m.path) + ": no module named '" + name + "'");
    ImuReadOptions ro = imu_read_options(*spec);
    ro.pass_nonfinite = true;
    S.push_back(survey::read_series(name, m.resolve(spec->file), ro));
  }
  return S;
}

std::vector<Vec3> static_gyro_bias(const Drive& drive) {
  const Manifest& m = drive.m;
  const std::vector<survey::Series>& S = drive.S;
  std::vector<Vec3> bias(S.size());
  for (std::size_t i = 0; i < S.size(); ++i) {
    Vec3 sum = Vec3::Zero();
    double n = 0.0;
    for (std::size_t k = S[i].index(m.static_start); k < S[i].size() && S[i].time(k) <= m.static_end; ++k)
      if (S[i].time(k) >= m.static_start) sum += S[i].gyro[k], n += 1.0;
    bias[i] = n >= 50.0 ? Vec3(sum / n) : drive.sv.modules[i].traits.gyro_bias;
  }
  return bias;
}

/// The sources of the vehicle's yaw rate (up positive): a Body-IMU, else the unsteered wheels.
std::vector<Sampled> yaw_sources(const Drive& drive) {
  const std::vector<survey::Series>& S = drive.S;
  const survey::DatasetSurvey& sv = drive.sv;
  std::vector<Sampled> sources;
  for (std::size_t i = 0; i < drive.modules.size(); ++i) {
    const ModuleSpec& spec = *drive.m.find(drive.modules[i]);
    if (spec.kind != ModuleKind::kBody) continue;
    const Mat3 C = dcm_from_euler(spec.mounting_rpy);
    Sampled y{&S[i], std::vector<double>(S[i].size())};
    for (std::size_t k = 0; k < S[i].size(); ++k) y.x[k] = -(C * (S[i].gyro[k] - drive.bias[i])).z();
    sources.push_back(std::move(y));
    break;
  }
  if (sources.empty())
    for (std::size_t i = 0; i < drive.modules.size(); ++i)
      if (sv.modules[i].kind == ModuleKind::kWheel && !sv.modules[i].steered)
        sources.push_back({&S[i], survey::yaw_rate(S[i], sv.modules[i].traits)});
  return sources;
}

/// The yaw rate as one signal on the first source's bins (the mean of the sources).
Signal mean_yaw_rate(const std::vector<Sampled>& sources) {
  Signal yaw;
  if (!sources.empty()) {
    const survey::Series& base = *sources.front().s;
    for (std::size_t k = 0; k < base.size(); ++k) {
      double y = 0.0;
      for (const Sampled& src : sources) y += src.at(base.time(k));
      yaw.t.push_back(base.time(k));
      yaw.x.push_back(y / static_cast<double>(sources.size()));
    }
    yaw.step = base.dt;
  }
  return yaw;
}

/// Module i is an unsteered wheel, by both the survey and the manifest.
bool unsteered_wheel(const Drive& drive, std::size_t i) {
  const survey::DatasetSurvey& sv = drive.sv;
  return sv.modules[i].kind == ModuleKind::kWheel && !sv.modules[i].steered &&
         drive.m.find(drive.modules[i])->kind == ModuleKind::kWheel;
}

/// A wheel's speed in turns of its axle (rad/s, forward positive), from the raw rate.
Signal axle_rate(const Drive& drive, std::size_t i) {
  const std::vector<survey::Series>& S = drive.S;
  const ModuleSpec& spec = *drive.m.find(drive.modules[i]);
  const Mat3 C = wheel_sensor_to_body(spec);
  Signal omega;
  for (std::size_t k = 0; k < S[i].size(); ++k) {
    omega.t.push_back(S[i].time(k));
    omega.x.push_back(-spec.axle_sign * (C * (S[i].gyro[k] - drive.bias[i])).x());
  }
  omega.step = S[i].dt;
  return omega;
}

/// The shift of the reference's times within +-0.25 s that best fits its speed to the wheel's
/// turn rate `omega` between `from` and `to` (refined by a parabola); NaN: none.
double best_shift(const Drive& drive, const Signal& omega, double from, double to) {
  const double step = 0.01;
  std::vector<double> corr;
  for (int k = -25; k <= 25; ++k) {
    const double d = k * step;
    const auto shifted = [&](double t) { return drive.ref.speed(t - d); };
    Signal part = omega;
    std::vector<double> keep_t, keep_x;
    for (std::size_t q = 0; q < omega.t.size(); ++q)
      if (omega.t[q] >= from && omega.t[q] <= to) keep_t.push_back(omega.t[q]), keep_x.push_back(omega.x[q]);
    part.t = keep_t;
    part.x = keep_x;
    const SpeedScale f = fit_speed_scale(shifted, part, drive.yaw, drive.m.static_end, drive.o.min_speed);
    corr.push_back(f.observed ? f.correlation : -1.0);
  }
  std::size_t b = 0;
  for (std::size_t k = 1; k < corr.size(); ++k)
    if (corr[k] > corr[b]) b = k;
  if (corr[b] < 0.0 || b == 0 || b + 1 == corr.size()) return std::nan("");
  const double den = corr[b - 1] - 2.0 * corr[b] + corr[b + 1];
  const double frac = den < 0.0 ? std::clamp(0.5 * (corr[b - 1] - corr[b + 1]) / den, -0.5, 0.5) : 0.0;
  return (static_cast<double>(b) - 25.0 + frac) * step;
}

/// The reference's clock, refined: the shift of its times that best fits its speed to an
/// unsteered wheel's with the yaw term (its antenna's speed departs from the wheels' in
/// turns, which pulls a plain correlation of the speeds, as the import's); scanned over
/// +-0.25 s, refined by a parabola; 1 sigma from five parts of the drive. The reference's
/// times are moved onto the refined clock.
CalibratedValue refine_clock(Drive& drive) {
  const Manifest& m = drive.m;
  for (std::size_t i = 0; i < drive.modules.size(); ++i) {
    if (!unsteered_wheel(drive, i)) continue;
    const Signal omega = axle_rate(drive, i);
    const double d = best_shift(drive, omega, -1e300, 1e300);
    if (!std::isfinite(d)) break;
    std::vector<double> parts;
    const double t0 = std::max(m.static_end, omega.start()), len = (omega.end() - t0) / 5.0;
    for (int p = 0; p < 5; ++p) {
      const double dp = best_shift(drive, omega, t0 + p * len, t0 + (p + 1) * len);
      if (std::isfinite(dp)) parts.push_back(dp);
    }
    const double sd = sigma_of_parts(parts, 0.005);
    for (double& t : drive.ref.track.t) t += d;  // everything below on the refined clock
    return CalibratedValue{m.truth_time_offset + d, sd, true};
  }
  return CalibratedValue{m.truth_time_offset, 0.0, false};
}

/// The speed the filter gives with the radius of the wheel `spec` set to `radius`.
Signal filter_speed(const Manifest& m, const ModuleSpec& spec, double radius) {
  Manifest one = m;
  for (auto& x : one.modules)
    if (x.name == spec.name) x.wheel_radius = radius;
  one.heading_known = false;
  return wheel_ins_speed(one, spec.name);
}

/// The radius of wheel i: first from its turn rate, then from the speed its own Wheel-INS
/// gives with that radius; a note for one not observed goes to `notes`.
WheelRadiusFit fit_wheel_radius(const Drive& drive, std::size_t i, std::vector<std::string>& notes) {
  const Manifest& m = drive.m;
  const ReferenceCalibrationOptions& o = drive.o;
  const auto ref_speed = [&drive](double t) { return drive.ref.speed(t); };
  const ModuleSpec& spec = *m.find(drive.modules[i]);
  WheelRadiusFit w;
  w.module = spec.name;
  w.manifest_radius = drive.m0.find(spec.name)->wheel_radius;
  w.manifest_yaw_scale = drive.m0.find(spec.name)->yaw_scale;
  w.yaw.yaw_scale = CalibratedValue{spec.yaw_scale, 0.0, false};
  w.radius = CalibratedValue{spec.wheel_radius, 0.0, false};
  const Signal omega = axle_rate(drive, i);
  const SpeedScale first = fit_speed_scale(ref_speed, omega, drive.yaw, m.static_end, o.min_speed);
  w.epochs = first.epochs;
  w.correlation = first.correlation;
  if (!first.observed) {
    notes.push_back(spec.name + fmt(": %.0f epochs faster than %.1f m/s against the reference: the radius is not observed",
                                    static_cast<double>(first.epochs), o.min_speed));
    return w;
  }
  w.radius = CalibratedValue{first.scale, first.sigma, true};
  w.odometry_radius = w.radius;
  // The second pass: the filter's speed with the first radius.
  const SpeedScale second =
      fit_speed_scale(ref_speed, filter_speed(m, spec, first.scale), drive.yaw, m.static_end, o.min_speed);
  if (second.observed) {
    w.radius = CalibratedValue{first.scale * second.scale, first.scale * second.sigma, true};
    w.correlation = second.correlation;
    w.epochs = second.epochs;
  }
  if (!(w.radius.std < 0.05 * w.radius.value)) w.radius = CalibratedValue{spec.wheel_radius, w.radius.std, false};
  return w;
}

/// The manifest of the dead reckoning: the radii observed, in a local frame (heading 0).
Manifest dead_reckoning_manifest(const Manifest& m, const std::vector<WheelRadiusFit>& wheels) {
  Manifest dr = m;
  for (const WheelRadiusFit& w : wheels)
    if (w.radius.observed)
      for (auto& s : dr.modules)
        if (s.name == w.module) s.wheel_radius = w.radius.value;
  dr.heading_known = false;
  dr.initial_heading = 0.0;
  return dr;
}

/// The modules to dead-reckon with: the unsteered wheels, else every wheel.
std::vector<std::string> navigation_modules(const Drive& drive) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < drive.modules.size(); ++i)
    if (unsteered_wheel(drive, i)) out.push_back(drive.modules[i]);
  if (out.empty())
    for (const auto& name : drive.modules)
      if (drive.m.find(name)->kind == ModuleKind::kWheel) out.push_back(name);
  return out;
}

/// The track of a dead reckoning of `modules` with the manifest `dr`.
eval::PlanarTrack dead_reckon(const Manifest& dr, const std::vector<std::string>& modules, bool progress) {
  RunRequest req;
  req.manifest = dr;
  req.modules = modules;
  req.calibration = CalibrationMode::kManifest;
  req.data_checks = false;
  req.progress = progress;
  req.warn = [&](const std::string&) {};  // the run's own warnings belong to the run, not here
  eval::PlanarTrack traj;
  req.on_record = [&](const TrajectoryRecord& r) {
    traj.t.push_back(r.t);
    traj.p_ne.push_back(r.p_inN.head<2>());
    traj.heading.push_back(r.rpy.z());
  };
  run_navigation(req);
  return traj;
}

eval::StartAlignmentOptions alignment_options(const ReferenceCalibrationOptions& o) {
  eval::StartAlignmentOptions ao;
  ao.length = o.align_length;
  ao.estimate_antenna = false;
  return ao;
}

/// The antenna of the alignment `a` (found) taken where the drive determines it, and the start
/// fitted again with it; a note where it is not determined.
void take_antenna(const Drive& drive, const eval::PlanarTrack& traj, const eval::StartAlignment& a,
                  ReferenceCalibration& out) {
  const Manifest& m = drive.m;
  // Observed only where the drive's turns determine it, and on the vehicle: a drive
  // without turns trades the antenna for the start (the fit then lands metres off).
  const double reach_x = std::max(2.0, m.wheelbase + 1.5), reach_y = std::max(1.0, 0.5 * m.track_width + 0.5);
  const bool on_vehicle = std::abs(a.antenna.x()) <= reach_x && std::abs(a.antenna.y()) <= reach_y;
  const bool sharp = a.antenna_sigma.maxCoeff() < drive.o.max_antenna_sigma;
  out.antenna_forward = CalibratedValue{a.antenna.x(), a.antenna_sigma.x(), on_vehicle && sharp};
  out.antenna_right = CalibratedValue{a.antenna.y(), a.antenna_sigma.y(), on_vehicle && sharp};
  // The start again with the antenna where it is (the heading no longer absorbs it).
  if (on_vehicle && sharp) {
    eval::StartAlignmentOptions ao = alignment_options(drive.o);
    ao.antenna = a.antenna;
    const eval::StartAlignment again = eval::fit_start_alignment(drive.ref.track, traj, ao);
    if (again.found) {
      out.alignment = again;
      out.alignment.antenna = a.antenna;
      out.alignment.antenna_sigma = a.antenna_sigma;
      out.initial_heading = CalibratedValue{again.yaw, again.yaw_sigma, again.yaw_sigma < 5.0 * kDeg};
    }
  }
  if (!on_vehicle || !sharp)
    out.notes.push_back(fmt("the antenna (forward %.2f +- %.2f m, right %.2f +- %.2f m) is not determined by this drive",
                            a.antenna.x(), a.antenna_sigma.x(), a.antenna.y(), a.antenna_sigma.y()) +
                        (on_vehicle ? " (too few turns): the manifest's kept" : " (off the vehicle): the manifest's kept"));
}

/// The dead reckoning's track `traj` aligned onto the reference: the start, and the antenna.
void align_onto_reference(const Drive& drive, const eval::PlanarTrack& traj, ReferenceCalibration& out) {
  const ReferenceCalibrationOptions& o = drive.o;
  out.alignment = eval::fit_start_alignment(drive.ref.track, traj, alignment_options(o));
  eval::StartAlignment a = out.alignment;
  if (a.found && o.estimate_antenna) {
    const AntennaFit af = fit_antenna(drive.ref.track, traj, a.yaw);
    a.antenna = af.antenna;
    a.antenna_sigma = af.sigma;
    if (!af.found) a.antenna_sigma = Vec2::Constant(std::numeric_limits<double>::infinity());
  }
  if (a.found) {
    out.initial_heading = CalibratedValue{a.yaw, a.yaw_sigma, a.yaw_sigma < 5.0 * kDeg};
    if (o.estimate_antenna) take_antenna(drive, traj, a, out);
  } else {
    out.notes.push_back("the dead reckoning could not be aligned onto the reference (too few common epochs)");
  }
}

/// A dead reckoning with the radii in a local frame, aligned onto the reference.
void align_dead_reckoning(const Drive& drive, ReferenceCalibration& out) {
  const Manifest& m = drive.m;
  const Manifest dr = dead_reckoning_manifest(m, out.wheels);
  out.navigation_modules = navigation_modules(drive);
  out.initial_heading = CalibratedValue{m.initial_heading, 0.0, false};
  out.antenna_forward = CalibratedValue{m.antenna_inV ? m.antenna_inV->x() : 0.0, 0.0, false};
  out.antenna_right = CalibratedValue{m.antenna_inV ? m.antenna_inV->y() : 0.0, 0.0, false};
  if (!out.navigation_modules.empty())
    align_onto_reference(drive, dead_reckon(dr, out.navigation_modules, drive.o.progress), out);
}

/// Each wheel's yaw scale factor: its own Wheel-INS with the radii, the clock and the antenna
/// found above, against the reference's course (yaw_scale_fit.hpp); one note naming those not
/// observed.
void fit_yaw_scales(const Drive& drive, ReferenceCalibration& out) {
  const Manifest cal = apply_reference_calibration(drive.m, out);
  std::string unobserved;
  double turned = 0.0;
  for (WheelRadiusFit& w : out.wheels) {
    w.yaw = fit_yaw_scale(cal, w.module, drive.o.yaw_scale);
    if (w.yaw.yaw_scale.observed) continue;
    unobserved += (unobserved.empty() ? "" : ", ") + w.module;
    turned = std::max(turned, w.yaw.turn_span);
  }
  if (!unobserved.empty())
    out.notes.push_back("the yaw scale factor of " + unobserved +
                        fmt(" is not told from the manifest's by this drive (%.0f deg of heading turned; the "
                            "estimates above): the manifest's kept",
                            turned / kDeg));
}

}  // namespace

ReferenceCalibration calibrate_against_reference(const Manifest& m0, const std::vector<std::string>& modules,
                                                 const InstallationCalibration& installation,
                                                 const ReferenceCalibrationOptions& o, const WarningSink& warn) {
  ReferenceCalibration out;
  const Manifest m = installation.empty() ? m0 : apply_calibration(m0, installation);
  Drive drive{m0, m, modules, o, read_reference(m), {}, {}, {}, {}};

  // The modules' series (manifest clocks) and what the data say of them.
  drive.S = read_module_series(m, modules);
  drive.sv = survey::survey_series(drive.S);
  // Each module's gyro bias over the manifest's static period (the survey's where it has no data).
  drive.bias = static_gyro_bias(drive);
  // The vehicle's yaw rate (up positive): a Body-IMU's, else the unsteered wheels' mean.
  drive.yaw = mean_yaw_rate(yaw_sources(drive));

  out.truth_time_offset = refine_clock(drive);

  // Each wheel's radius: first from its turn rate, then from the speed its own Wheel-INS
  // gives with that radius (the filter refines the axle gyro's scale factor against gravity,
  // so the radius that makes the filter's speed right is what the run needs).
  for (std::size_t i = 0; i < modules.size(); ++i)
    if (m.find(modules[i])->kind == ModuleKind::kWheel) out.wheels.push_back(fit_wheel_radius(drive, i, out.notes));

  align_dead_reckoning(drive, out);
  if (o.estimate_yaw_scale) fit_yaw_scales(drive, out);
  if (warn)
    for (const auto& n : out.notes) warn(quote(m.path) + ": " + n);
  return out;
}

Manifest apply_reference_calibration(Manifest m, const ReferenceCalibration& cal) {
  if (cal.truth_time_offset.observed) m.truth_time_offset = cal.truth_time_offset.value;
  for (const WheelRadiusFit& w : cal.wheels)
    if (w.radius.observed)
      for (auto& s : m.modules)
        if (s.name == w.module) s.wheel_radius = w.radius.value;
  for (const WheelRadiusFit& w : cal.wheels)
    if (w.yaw.yaw_scale.observed)
      for (auto& s : m.modules)
        if (s.name == w.module) s.yaw_scale = w.yaw.yaw_scale.value;
  for (const WheelRadiusFit& w : cal.wheels)
    if (w.odometry_radius.observed)
      for (auto& s : m.modules)
        if (s.name == w.module) s.odometry_radius = w.odometry_radius.value;
  if (cal.initial_heading.observed) {
    m.initial_heading = wrap_pi(cal.initial_heading.value);
    m.heading_known = true;
  }
  if (cal.antenna_forward.observed || cal.antenna_right.observed) {
    Vec3 a = m.antenna_inV ? *m.antenna_inV : Vec3::Zero();
    if (cal.antenna_forward.observed) a.x() = cal.antenna_forward.value;
    if (cal.antenna_right.observed) a.y() = cal.antenna_right.value;
    m.antenna_inV = a;
  }
  return m;
}

std::string reference_calibration_report(const ReferenceCalibration& c) {
  std::string s = "against the reference (estimate +- 1 sigma, manifest):\n";
  for (const WheelRadiusFit& w : c.wheels)
    s += "  " + w.module + fmt(std::string(std::max<int>(1, 12 - static_cast<int>(w.module.size())), ' ').append("wheel radius %.4f +- %.4f m (%.4f)").c_str(),
                               w.radius.value, w.radius.std, w.manifest_radius) +
         (w.radius.observed ? fmt("  %.0f epochs, correlation %.4f; raw axle rate %.4f m\n", static_cast<double>(w.epochs),
                                  w.correlation, w.odometry_radius.value)
                            : std::string("  not observed: manifest kept\n"));
  for (const WheelRadiusFit& w : c.wheels)
    if (w.yaw.epochs > 0)
      s += "  " + w.module + std::string(std::max<int>(1, 12 - static_cast<int>(w.module.size())), ' ') +
           fmt("yaw scale %+.0f +- %.0f ppm (%+.0f)", w.yaw.yaw_scale.value * 1e6, w.yaw.yaw_scale.std * 1e6,
               w.manifest_yaw_scale * 1e6) +
           (w.yaw.yaw_scale.observed ? fmt("  over %.0f deg turned, heading residual %.2f deg\n", w.yaw.turn_span / kDeg,
                                           w.yaw.residual / kDeg)
                                     : std::string("  not observed: manifest kept\n"));
  const auto& a = c.alignment;
  s += fmt("  initial heading  %.3f +- %.3f deg", c.initial_heading.value / kDeg, c.initial_heading.std / kDeg) +
       (c.initial_heading.observed ? fmt("  (dead reckoning of %.0f wheel(s) aligned over %.0f m, residual %.3f m)\n",
                                         static_cast<double>(c.navigation_modules.size()), a.length, a.rms)
                                   : std::string("  not observed\n"));
  s += fmt("  reference clock  %+.4f +- %.4f s (truth_time_offset_s; the speeds with the turns' term)\n",
           c.truth_time_offset.value, c.truth_time_offset.std);
  s += fmt("  antenna          forward %.3f +- %.3f m, right %.3f +- %.3f m", c.antenna_forward.value, c.antenna_forward.std,
           c.antenna_right.value, c.antenna_right.std) +
       (c.antenna_forward.observed ? "\n" : "  (not observed)\n");
  for (const auto& n : c.notes) s += "  note: " + n + "\n";
  return s;
}

std::string reference_calibration_yaml(const ReferenceCalibration& c, const Manifest& m) {
  auto val = [](const CalibratedValue& v, double scale, double manifest) {
    return fmt("{estimate: %.6g, std: %.3g, manifest: %.6g, observed: ", v.value * scale, v.std * scale, manifest * scale) +
           (v.observed ? "true}" : "false}");
  };
  std::string s = "reference:\n  wheels:\n";
  for (const WheelRadiusFit& w : c.wheels)
    s += "    " + io_detail::json_quote(w.module) + ":\n      wheel_radius_m: " + val(w.radius, 1.0, w.manifest_radius) +
         "\n      odometry_radius_m: " + val(w.odometry_radius, 1.0, w.manifest_radius) +
         "\n      yaw_scale_ppm: " + val(w.yaw.yaw_scale, 1e6, w.manifest_yaw_scale) + "\n";
  s += "  truth_time_offset_s: " + val(c.truth_time_offset, 1.0, m.truth_time_offset) + "\n";
  s += "  initial:\n    heading_deg: " + val(c.initial_heading, 1.0 / kDeg, m.initial_heading) + "\n";
  s += "  vehicle:\n    antenna_forward_m: " + val(c.antenna_forward, 1.0, m.antenna_inV ? m.antenna_inV->x() : 0.0) + "\n";
  s += "    antenna_right_m: " + val(c.antenna_right, 1.0, m.antenna_inV ? m.antenna_inV->y() : 0.0) + "\n";
  return s;
}

}  // namespace wheelins
