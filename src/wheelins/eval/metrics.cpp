#include "wheelins/eval/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "wheelins/io/atomic_file.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins::eval {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kTimeSlack = 1e-6;  // [s] end-point tolerance of the time brackets

std::string quote(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

// The trajectory as evaluation needs it: positions in the evaluation frame.
struct Track {
  std::vector<double> t;
  std::vector<Vec3> p;
  std::vector<double> heading;
  std::vector<double> sn, se;  // north / east 1-sigma
};

Track make_track(const TrajectoryData& traj, const earth::LocalFrame& frame) {
  Track k;
  const std::size_t n = traj.records.size();
  k.t.reserve(n);
  k.p.reserve(n);
  if (traj.has_heading) k.heading.reserve(n);
  if (traj.has_pos_std) {
    k.sn.reserve(n);
    k.se.reserve(n);
  }
  for (const auto& r : traj.records) {
    k.t.push_back(r.t);
    k.p.push_back(traj.has_lla ? frame.ned_from_geodetic(r.lla) : r.p_inN);
    if (traj.has_heading) k.heading.push_back(r.rpy.z());
    if (traj.has_pos_std) {
      k.sn.push_back(r.p_std.x());
      k.se.push_back(r.p_std.y());
    }
  }
  return k;
}

double lerp(double a, double b, double f) { return a + (b - a) * f; }

}  // namespace

std::vector<double> drift_rate_curve(const std::vector<double>& s, const std::vector<double>& err,
                                     double segment_length) {
  std::vector<double> curve;
  if (s.empty() || s.size() != err.size() || !(segment_length > 0.0)) return curve;
  // Tiny slack so that a distance of exactly k*l computed by summation still counts.
  const double slack = 1e-9 * std::max(1.0, s.back());
  const auto K = static_cast<std::size_t>(std::floor((s.back() + slack) / segment_length));
  curve.reserve(K);
  std::size_t i = 0;
  double running_max = 0.0;
  for (std::size_t k = 1; k <= K; ++k) {
    const double limit = static_cast<double>(k) * segment_length;
    while (i < s.size() && s[i] <= limit + slack) running_max = std::max(running_max, err[i++]);
    curve.push_back(running_max / limit);
  }
  return curve;
}

EvalResult evaluate(const TruthData& truth, const TrajectoryData& traj,
                    const earth::LocalFrame& frame, const EvalOptions& opt) {
  if (!(opt.segment_length > 0.0) || !std::isfinite(opt.segment_length))
    throw InputError("segment length must be a positive number of metres");
  if (!(opt.max_gap > 0.0)) throw InputError("maximum interpolation gap must be positive");
  if (truth.records.empty()) throw InputError(quote(truth.file) + ": no truth records");
  if (traj.records.empty()) throw InputError(quote(traj.file) + ": no trajectory records");

  EvalResult res;
  res.truth_file = truth.file.string();
  res.traj_file = traj.file.string();
  res.traj_format = trajectory_format_name(traj.format);
  res.truth_records = truth.records.size();
  res.traj_records = traj.records.size();
  res.segment_length = opt.segment_length;
  res.has_heading = truth.has_velocity_attitude && traj.has_heading;
  res.has_sigma = traj.has_pos_std;

  const Track track = make_track(traj, frame);
  const std::size_t m = track.t.size();

  // Truth positions and cumulative horizontal distance over all records.
  const std::size_t n = truth.records.size();
  std::vector<Vec3> tp(n);
  std::vector<double> ts(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    tp[i] = frame.ned_from_geodetic(truth.records[i].lla);
    if (i > 0) ts[i] = ts[i - 1] + (tp[i] - tp[i - 1]).head<2>().norm();
  }

  // Alignment state, fixed at the first evaluated epoch.
  bool pivot_set = false;
  Vec3 pivot_traj = Vec3::Zero(), pivot_truth = Vec3::Zero();
  Mat3 R = Mat3::Identity();
  double dpsi = 0.0;
  Eigen::Matrix2d R2 = Eigen::Matrix2d::Identity();

  double s0 = 0.0, sum_e2 = 0.0, sum_h2 = 0.0, max_h = 0.0, sum_nees = 0.0;
  std::size_t heading_count = 0, within = 0;
  res.series.reserve(n);
  std::size_t j = 0;  // trajectory bracket: track.t[j] <= t < track.t[j+1]
  for (std::size_t i = 0; i < n; ++i) {
    const double t = truth.records[i].t;
    if (t < track.t.front() - kTimeSlack || t > track.t.back() + kTimeSlack) {
      ++res.skipped_outside;
      continue;
    }
    while (j + 1 < m && track.t[j + 1] <= t) ++j;
    std::size_t j1 = j;
    double f = 0.0;
    if (j + 1 < m && t > track.t[j]) {
      j1 = j + 1;
      const double span = track.t[j1] - track.t[j];
      if (span > opt.max_gap) {
        ++res.skipped_gap;
        continue;
      }
      f = std::clamp((t - track.t[j]) / span, 0.0, 1.0);
    }
    Vec3 p = track.p[j] + (track.p[j1] - track.p[j]) * f;
    double heading = kNaN;
    if (traj.has_heading)
      heading = track.heading[j] + wrap_pi(track.heading[j1] - track.heading[j]) * f;
    const double truth_heading =
        truth.has_velocity_attitude ? truth.records[i].rpy.z() : kNaN;

    if (!pivot_set) {
      pivot_set = true;
      s0 = ts[i];
      res.t_start = t;
      if (opt.align) {
        res.aligned = true;
        pivot_traj = p;
        pivot_truth = tp[i];
        res.align_offset = pivot_truth - pivot_traj;
        if (std::isfinite(heading) && std::isfinite(truth_heading)) {
          dpsi = wrap_pi(truth_heading - heading);
          res.align_rotated = true;
          res.align_yaw = dpsi;
          R = rot_z(dpsi);
          R2 = R.topLeftCorner<2, 2>();
        }
      }
    }
    if (opt.align) {
      p = R * (p - pivot_traj) + pivot_truth;
      heading += dpsi;
    }

    EpochError e;
    e.t = t;
    e.distance = ts[i] - s0;
    e.err_ned = p - tp[i];
    e.err_h = e.err_ned.head<2>().norm();
    e.heading_err = res.has_heading ? wrap_pi(heading - truth_heading) : kNaN;
    e.sigma_h = kNaN;
    e.nees_h = kNaN;
    if (res.has_sigma) {
      const double sn = lerp(track.sn[j], track.sn[j1], f);
      const double se = lerp(track.se[j], track.se[j1], f);
      if (sn > 0.0 && se > 0.0 && std::isfinite(sn) && std::isfinite(se)) {
        const Eigen::Matrix2d P =
            R2 * Eigen::Vector2d(sn * sn, se * se).asDiagonal() * R2.transpose();
        const Eigen::Vector2d d = e.err_ned.head<2>();
        e.sigma_h = std::sqrt(P.trace());
        e.nees_h = d.dot(P.ldlt().solve(d));
        ++res.sigma_epochs;
        if (e.err_h <= 3.0 * e.sigma_h) ++within;
        sum_nees += e.nees_h;
      }
    }
    sum_e2 += e.err_h * e.err_h;
    res.max_error = std::max(res.max_error, e.err_h);
    if (std::isfinite(e.heading_err)) {
      sum_h2 += e.heading_err * e.heading_err;
      max_h = std::max(max_h, std::abs(e.heading_err));
      ++heading_count;
    }
    res.series.push_back(e);
  }

  res.epochs = res.series.size();
  if (res.epochs == 0)
    throw InputError(quote(traj.file) + ": no truth epoch of " + quote(truth.file) +
                     " falls inside the trajectory (trajectory " + std::to_string(track.t.front()) +
                     " .. " + std::to_string(track.t.back()) + " s, truth " +
                     std::to_string(truth.records.front().t) + " .. " +
                     std::to_string(truth.records.back().t) + " s" +
                     (res.skipped_gap ? ", or only inside gaps longer than the maximum gap" : "") +
                     "); do both use the same time scale (GPS seconds of week)?");

  const auto& last = res.series.back();
  res.t_end = last.t;
  res.duration = res.t_end - res.t_start;
  res.distance = last.distance;
  res.final_error = last.err_h;
  res.rms_error = std::sqrt(sum_e2 / static_cast<double>(res.epochs));

  std::vector<double> s(res.epochs), err(res.epochs);
  for (std::size_t k = 0; k < res.epochs; ++k) {
    s[k] = res.series[k].distance;
    err[k] = res.series[k].err_h;
  }
  res.drift_curve = drift_rate_curve(s, err, opt.segment_length);
  if (res.drift_curve.empty()) {
    res.drift_rate = kNaN;
  } else {
    double sum = 0.0;
    for (double r : res.drift_curve) sum += r;
    res.drift_rate = sum / static_cast<double>(res.drift_curve.size());
  }

  if (heading_count > 0) {
    res.heading_rmse = std::sqrt(sum_h2 / static_cast<double>(heading_count));
    res.heading_max_abs = max_h;
  } else {
    res.has_heading = false;
    res.heading_rmse = res.heading_max_abs = kNaN;
  }
  if (res.sigma_epochs > 0) {
    res.within_3sigma = static_cast<double>(within) / static_cast<double>(res.sigma_epochs);
    res.mean_nees = sum_nees / static_cast<double>(res.sigma_epochs);
  } else {
    res.has_sigma = false;
    res.within_3sigma = res.mean_nees = kNaN;
  }
  return res;
}

namespace {

void json_string(std::string& o, const std::string& s) {
  o += '"';
  for (char c : s) {
    switch (c) {
      case '"': o += "\\\""; break;
      case '\\': o += "\\\\"; break;
      case '\n': o += "\\n"; break;
      case '\t': o += "\\t"; break;
      case '\r': o += "\\r"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          static const char* hex = "0123456789abcdef";
          o += "\\u00";
          o += hex[(c >> 4) & 0xf];
          o += hex[c & 0xf];
        } else {
          o += c;
        }
    }
  }
  o += '"';
}

void json_number(std::string& o, double v) {
  if (!std::isfinite(v)) {
    o += "null";
    return;
  }
  append_double(o, v, 10);
}

class JsonObject {
 public:
  explicit JsonObject(std::string& o) : o_(o) { o_ += "{\n"; }
  void key(const char* k) {
    if (!first_) o_ += ",\n";
    first_ = false;
    o_ += "  ";
    json_string(o_, k);
    o_ += ": ";
  }
  void num(const char* k, double v) {
    key(k);
    json_number(o_, v);
  }
  void count(const char* k, std::size_t v) {
    key(k);
    o_ += std::to_string(v);
  }
  void boolean(const char* k, bool v) {
    key(k);
    o_ += v ? "true" : "false";
  }
  void str(const char* k, const std::string& v) {
    key(k);
    json_string(o_, v);
  }
  void close() { o_ += "\n}\n"; }

 private:
  std::string& o_;
  bool first_ = true;
};

}  // namespace

std::string to_json(const EvalResult& r) {
  std::string o;
  JsonObject j(o);
  j.str("truth_file", r.truth_file);
  j.str("traj_file", r.traj_file);
  j.str("traj_format", r.traj_format);
  j.count("truth_records", r.truth_records);
  j.count("traj_records", r.traj_records);
  j.count("epochs", r.epochs);
  j.count("skipped_outside", r.skipped_outside);
  j.count("skipped_gap", r.skipped_gap);
  j.num("t_start_s", r.t_start);
  j.num("t_end_s", r.t_end);
  j.num("duration_s", r.duration);
  j.num("distance_m", r.distance);
  j.num("segment_m", r.segment_length);
  j.num("drift_rate_pct", r.drift_rate * 100.0);
  j.key("drift_curve_pct");
  o += '[';
  for (std::size_t k = 0; k < r.drift_curve.size(); ++k) {
    if (k) o += ", ";
    json_number(o, r.drift_curve[k] * 100.0);
  }
  o += ']';
  j.num("heading_rmse_deg", r.heading_rmse / kDeg);
  j.num("heading_max_abs_deg", r.heading_max_abs / kDeg);
  j.num("max_error_m", r.max_error);
  j.num("final_error_m", r.final_error);
  j.num("rms_error_m", r.rms_error);
  j.boolean("has_sigma", r.has_sigma);
  j.count("sigma_epochs", r.sigma_epochs);
  j.num("within_3sigma_fraction", r.within_3sigma);
  j.num("mean_nees_h", r.mean_nees);
  j.boolean("aligned", r.aligned);
  j.boolean("align_rotated", r.align_rotated);
  j.num("align_yaw_deg", r.align_yaw / kDeg);
  j.key("align_offset_ned_m");
  o += '[';
  for (int k = 0; k < 3; ++k) {
    if (k) o += ", ";
    json_number(o, r.align_offset[k]);
  }
  o += ']';
  j.close();
  return o;
}

}  // namespace wheelins::eval
