// The manifest draft of manifest_draft.hpp: finding the layout's files, reading their rate,
// static period and initial pose, and listing what the user must still measure.
#include "wheelins/io/manifest_draft.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

#include "wheelins/io/binary.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/odometer.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/io/truth.hpp"

namespace wheelins {
namespace fs = std::filesystem;
using io_detail::format_double;
using io_detail::quote;

namespace {

constexpr const char* kTodo = "TODO: measure";
constexpr double kMoveSpeed = 0.1;       // [m/s] truth/odometer speed that counts as moving
constexpr double kMoveWheelRate = 0.5;   // [rad/s] wheel gyro rate that counts as rolling
constexpr double kStaticMargin = 0.5;    // [s] kept clear of the first motion
constexpr double kScanSeconds = 900.0;   // how far into the data the static period is sought

// Typical values for the geometry nobody can read from the data: the Wheel-INS robot
// (Pioneer 3DX) that recorded these layouts. Every one of them is marked TODO.
constexpr double kRobotWheelRadius = 0.097;
constexpr double kRobotTrack = 0.33;
const Vec3 kRobotLeverArm(-0.015, 0.005, 0.005);

std::string seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f s", s);
  return buf;
}

struct Found {
  std::string name, group, chip;
  ModuleKind kind;
  fs::path file;  // absolute
};

struct Probe {
  double first_t = 0.0;
  std::optional<double> rate_hz;
  std::uint64_t intervals = 0;
};

/// First record time and nominal rate (median of the first intervals) of an IMU file.
Probe probe_imu(const fs::path& file) {
  ImuReadOptions o;
  o.gap_factor = std::numeric_limits<double>::infinity();
  ImuFileReader r(file, o);
  Probe p;
  p.first_t = r.first_time();
  std::vector<double> dts;
  ImuSample s;
  while (dts.size() < 401 && r.next(s))
    if (r.index() > 0) dts.push_back(s.dt);
  p.intervals = dts.size();
  if (dts.empty()) return p;
  std::nth_element(dts.begin(), dts.begin() + static_cast<std::ptrdiff_t>(dts.size() / 2), dts.end());
  const double rate = 1.0 / dts[dts.size() / 2];
  const double whole = std::round(rate);
  p.rate_hz = (whole > 0.0 && std::abs(rate - whole) <= 1e-3 * rate) ? whole : std::round(rate * 100.0) / 100.0;
  return p;
}


std::optional<double> motion_from_odometer(const fs::path& file, double t_from) {
  OdoReader r(file);
  OdoSample s;
  while (r.next(s)) {
    if (s.t < t_from) continue;
    if (s.t > t_from + kScanSeconds) return std::nullopt;
    if (std::abs(s.speed) > kMoveSpeed) return s.t;
  }
  return std::nullopt;
}

struct TruthStart {
  std::uint64_t record = 0;
  double t = 0.0;
  double lat_deg = 0.0, lon_deg = 0.0, h = 0.0;
  std::optional<double> yaw_deg;
  std::optional<double> motion_t;  // first record after t_from moving faster than kMoveSpeed
  bool starts_late = false;        // the truth begins after t_from
};

/// The truth record at (or first after) `t_from`, and when the truth starts moving.
TruthStart truth_start(const fs::path& file, TruthLayout layout, double t_from) {
  const bool gins = layout == TruthLayout::kGins11;
  BinaryRowReader rows(file, gins ? 11 : 5);
  TruthStart ts;
  bool have = false;
  double last_t = -std::numeric_limits<double>::infinity();
  while (const double* v = rows.next()) {
    const double t = gins ? v[1] : v[0];
    const int used = gins ? 11 : 4;
    for (int c = 0; c < used; ++c)
      if (!std::isfinite(v[c]))
        throw InputError(quote(file) + ": record " + std::to_string(rows.index()) + " (0-based), column " +
                         std::to_string(c) + ": value is not finite");
    if (!(t > last_t))
      throw InputError(quote(file) + ": record " + std::to_string(rows.index()) +
                       " (0-based): time " + format_double(t) + " is not after the previous record's");
    last_t = t;
    if (!have) {
      if (t < t_from && rows.index() + 1 < rows.rows()) continue;
      have = true;
      ts.record = rows.index();
      ts.t = t;
      ts.starts_late = rows.index() == 0 && t > t_from;
      ts.lat_deg = gins ? v[2] : v[1];
      ts.lon_deg = gins ? v[3] : v[2];
      ts.h = gins ? v[4] : v[3];
      if (gins) ts.yaw_deg = v[10];
      if (!gins) return ts;
    }
    if (t > ts.t + kScanSeconds) break;
    if (std::hypot(v[5], v[6]) > kMoveSpeed) {
      ts.motion_t = t;
      break;
    }
  }
  if (!have) throw InputError(quote(file) + ": contains no records (empty file)");
  return ts;
}

std::string rel(const fs::path& abs, const fs::path& manifest_dir) {
  fs::path r = abs.lexically_normal().lexically_relative(manifest_dir);
  return (r.empty() ? abs : r).generic_string();
}

std::vector<Found> find_multi(const fs::path& dir) {
  struct Group {
    const char* sub;
    const char* name;
    const char* group;
    ModuleKind kind;
  };
  const Group groups[] = {{"left-wheel-imu", "left", "left-wheel", ModuleKind::kWheel},
                          {"right-wheel-imu", "right", "right-wheel", ModuleKind::kWheel},
                          {"body-imu", "body", "body", ModuleKind::kBody}};
  std::vector<Found> out;
  for (const auto& g : groups) {
    for (int c = 1; c <= 9; ++c) {
      const std::string chip = "C" + std::to_string(c);
      const fs::path f = dir / g.sub / ("tri_" + chip + "_imu.bin");
      if (fs::is_regular_file(f))
        out.push_back({std::string(g.name) + "-" + chip, g.group, chip, g.kind, f});
    }
  }
  return out;
}

std::vector<Found> find_single(const fs::path& dir) {
  std::vector<Found> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string fname = e.path().filename().string();
    const std::string suffix = "_imu.bin";
    if (!e.is_regular_file() || fname.size() <= suffix.size() ||
        fname.compare(fname.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    const std::string stem = fname.substr(0, fname.size() - suffix.size());
    out.push_back({stem, "wheel", stem, ModuleKind::kWheel, e.path()});
  }
  std::sort(out.begin(), out.end(), [](const Found& a, const Found& b) { return a.file < b.file; });
  if (out.size() > 1)
    for (auto& f : out) f.group = f.name;  // separate modules unless the user says otherwise
  return out;
}

/// A folder name as the public dataset spells it, compared without case, blanks, '-' and '_'
/// ("Wheel-IMU", "wheel_imu", "Ground Truth", "ground_truth").
std::string folder_key(const std::string& name) {
  std::string k;
  for (unsigned char c : name)
    if (c != '-' && c != '_' && c != ' ') k += static_cast<char>(std::tolower(c));
  return k;
}

/// The subfolder of `dir` whose folder_key() is `key` (empty if none).
fs::path subfolder(const fs::path& dir, const std::string& key) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.is_directory(ec) && folder_key(e.path().filename().string()) == key) return e.path();
  return {};
}

/// The public Wheel-INS layout: Wheel-IMU/<chip>_imu.bin, Body-IMU/<chip>_imu.bin,
/// Ground Truth/GINS.bin, Odometer/odo.bin (a Body/Wheel pair).
std::vector<Found> find_public(const fs::path& dir) {
  std::vector<Found> out;
  const struct {
    const char* key;
    const char* prefix;
    const char* group;
    ModuleKind kind;
  } groups[] = {{"wheelimu", "wheel", "wheel", ModuleKind::kWheel},
                {"bodyimu", "body", "body", ModuleKind::kBody}};
  for (const auto& g : groups) {
    const fs::path sub = subfolder(dir, g.key);
    if (sub.empty()) continue;
    std::vector<Found> here;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(sub, ec)) {
      const std::string fname = e.path().filename().string();
      const std::string suffix = "_imu.bin";
      if (!e.is_regular_file(ec) || fname.size() <= suffix.size() ||
          fname.compare(fname.size() - suffix.size(), suffix.size(), suffix) != 0)
        continue;
      const std::string chip = fname.substr(0, fname.size() - suffix.size());
      here.push_back({std::string(g.prefix) + "-" + chip, g.group, chip, g.kind, e.path()});
    }
    std::sort(here.begin(), here.end(), [](const Found& a, const Found& b) { return a.file < b.file; });
    out.insert(out.end(), here.begin(), here.end());
  }
  return out;
}

}  // namespace

std::optional<double> motion_from_wheel(const fs::path& file, double t_from) {
  ImuReadOptions o;
  o.gap_factor = std::numeric_limits<double>::infinity();
  ImuFileReader r(file, o);
  ImuSample s;
  while (r.next(s)) {
    if (s.t < t_from) continue;
    if (s.t > t_from + kScanSeconds) return std::nullopt;
    if (r.row().gyro.norm() > kMoveWheelRate) return s.t;
  }
  return std::nullopt;
}

ManifestDraft draft_manifest(const fs::path& dir_in, const fs::path& manifest_file) {
  std::error_code ec;
  if (!fs::exists(dir_in, ec)) throw InputError(quote(dir_in) + ": directory not found");
  if (!fs::is_directory(dir_in, ec))
    throw InputError(quote(dir_in) + ": is a file, expected the directory that holds the recordings");
  const fs::path dir = fs::absolute(dir_in).lexically_normal();
  const fs::path mdir = fs::absolute(manifest_file).lexically_normal().parent_path();

  ManifestDraft d;
  Manifest& m = d.manifest;
  m.path = fs::absolute(manifest_file).lexically_normal();
  m.name = dir.filename().string();
  auto& note = d.notes.comments;

  std::vector<Found> found = find_multi(dir);
  fs::path truth;
  fs::path odo = dir / "odo.bin";
  const std::vector<Found> pub = found.empty() ? find_public(dir) : std::vector<Found>{};
  if (!pub.empty()) {
    found = pub;
    d.layout = "public Wheel-INS";
    const fs::path gt = subfolder(dir, "groundtruth");
    for (const fs::path& t : {gt.empty() ? fs::path() : gt / "GINS.bin", dir / "GINS.bin"})
      if (!t.empty() && fs::is_regular_file(t)) {
        truth = t;
        break;
      }
    const fs::path od = subfolder(dir, "odometer");
    if (!od.empty() && fs::is_regular_file(od / "odo.bin")) odo = od / "odo.bin";
  } else if (!found.empty()) {
    d.layout = "multi-IMU";
    for (const fs::path& t : {dir / "ground_truth" / "GINS-body.bin", dir / "GINS-body.bin", dir / "GINS.bin"})
      if (fs::is_regular_file(t)) {
        truth = t;
        break;
      }
  } else {
    found = find_single(dir);
    if (found.empty())
      throw InputError(quote(dir_in) +
                       ": no recordings found; expected <name>_imu.bin (+ GINS.bin, odo.bin), "
                       "or Wheel-IMU/ and Body-IMU/ with <chip>_imu.bin (+ 'Ground Truth'/GINS.bin, "
                       "Odometer/odo.bin: the public Wheel-INS layout), or body-imu/, left-wheel-imu/, "
                       "right-wheel-imu/ with tri_C1_imu.bin ... tri_C4_imu.bin (+ ground_truth/GINS-body.bin)");
    d.layout = "single-IMU";
    if (fs::is_regular_file(dir / "GINS.bin")) truth = dir / "GINS.bin";
  }
  const bool has_odo = fs::is_regular_file(odo);

  // Modules: files, rates, start times.
  double start = -std::numeric_limits<double>::infinity();
  double earliest = std::numeric_limits<double>::infinity();
  bool any_left = false, any_right = false;
  for (std::size_t i = 0; i < found.size(); ++i) {
    const Found& f = found[i];
    const Probe p = probe_imu(f.file);
    start = std::max(start, p.first_t);
    earliest = std::min(earliest, p.first_t);
    ModuleSpec s;
    s.name = f.name;
    s.kind = f.kind;
    s.group = f.group;
    s.chip = f.chip;
    s.file = rel(f.file, mdir);
    const std::string key = "modules[" + std::to_string(i) + "].";
    if (p.rate_hz) {
      s.rate_hz = *p.rate_hz;
      note[key + "rate_hz"] = "median of the first " + std::to_string(p.intervals) + " intervals";
    } else {
      note[key + "rate_hz"] = "TODO: the file has a single record; set the rate";
      d.todo.push_back(f.name + ": the sample rate (the file has one record)");
    }
    if (f.kind == ModuleKind::kWheel) {
      const bool left = f.group.rfind("left", 0) == 0;
      const bool right = f.group.rfind("right", 0) == 0;
      any_left |= left;
      any_right |= right;
      s.wheel_radius = kRobotWheelRadius;
      s.lever_arm_inB = kRobotLeverArm;
      s.p_inV = Vec3(0.0, left ? -kRobotTrack / 2 : (right ? kRobotTrack / 2 : 0.0), 0.0);
      s.axle_sign = 1;
      note[key + "wheel_radius_m"] = kTodo;
      note[key + "lever_arm_b_m"] = kTodo;
      note[key + "position_v_m"] = std::string(kTodo) + " (wheel centre in the v-frame)";
      note[key + "mounting_deg"] = kTodo;
      note[key + "axle_sign"] = std::string(kTodo) + " (+1: sensor x-axis points to the vehicle's right)";
      if (found.size() == 1) note[key + "kind"] = "TODO: check (the public Wheel-INS IMU is on a wheel)";
      if (!left && !right) {
        // Which wheel the data cannot tell: on the vehicle's centre line (y = 0), which every
        // configuration with one wheel accepts as its wheel; the side only matters with two.
        note[key + "position_v_m"] = std::string(kTodo) +
                                     " (wheel centre in the v-frame; y < 0 left wheel, y > 0 right; "
                                     "y = 0: side unknown)";
        d.todo.push_back(f.name + ": position_v_m (which wheel: y = 0 written)");
      }
    } else {
      note[key + "position_v_m"] = std::string(kTodo) + " (IMU centre in the v-frame)";
      note[key + "mounting_deg"] = std::string(kTodo) + " (C_b^v as roll, pitch, yaw)";
    }
    // No noise figures: wheelins identifies them from the data (docs/filter.md section 13);
    // a user who knows the IMUs' figures may state them as priors (docs/manifest.md).
    s.noise_stated = 0;
    m.modules.push_back(s);
  }
  d.facts.push_back(d.layout + " layout: " + std::to_string(m.modules.size()) + " IMU module(s) in " + quote(dir_in));
  if (start - earliest > 1.0)
    d.facts.push_back("the modules start " + seconds(start - earliest) +
                      " apart; the static period begins when all have data");

  // The static period: from the truth velocity, else the odometer, else a wheel gyro.
  std::optional<double> motion;
  std::string motion_source;

  // Truth: origin and heading at the start.
  std::optional<TruthStart> ts;
  if (!truth.empty()) {
    const TruthLayout layout = detect_truth_layout(truth);
    if (layout != TruthLayout::kGins11 && layout != TruthLayout::kPos5)
      throw InputError(quote(truth) + ": a text truth file (" + truth_layout_name(layout) +
                       "); the manifest draft reads the binary GINS.bin layouts");
    m.truth_file = rel(truth, mdir);
    ts = truth_start(truth, layout, start);
    const std::string tname = truth.filename().string();
    d.facts.push_back("truth " + quote(rel(truth, mdir)) + ": " +
                      (layout == TruthLayout::kGins11 ? "11 columns (position, velocity, attitude)"
                                                      : "5 columns (position only)"));
    m.origin = {ts->lat_deg * kDeg, ts->lon_deg * kDeg, ts->h};
    const std::string from = "from " + tname + " record " + std::to_string(ts->record) +
                             " (the reference system's position; the origin is the mid rear axle)";
    note["initial.lat_deg"] = from;
    if (ts->yaw_deg) {
      m.initial_heading = wrap_pi(*ts->yaw_deg * kDeg);
      note["initial.heading_deg"] = "from " + tname + " record " + std::to_string(ts->record);
    } else {
      note["initial.heading_deg"] = "TODO: the truth has no attitude; set the start heading";
      d.todo.push_back("initial.heading_deg: the vehicle heading at the start (the truth has no attitude)");
    }
    if (ts->starts_late)
      d.facts.push_back("the truth starts " + seconds(ts->t - start) + " after the IMU data");
    if (ts->t < start)
      d.facts.push_back("the truth ends before the IMU data start (different time bases?); "
                        "its last record was used");
    if (ts->motion_t) {
      motion = ts->motion_t;
      motion_source = "truth velocity";
    }
  } else {
    note["initial.lat_deg"] = "TODO: set the start position (gravity, earth rate)";
    note["initial.heading_deg"] = "TODO: set the start heading";
    d.todo.push_back("initial: the start position and heading (no truth file found)");
  }
  if (has_odo) {
    m.odometer_file = rel(odo, mdir);
    d.facts.push_back("odometer " + quote(rel(odo, mdir)));
    if (!motion) {
      motion = motion_from_odometer(odo, start);
      if (motion) motion_source = "odometer speed";
    }
  }
  if (!motion)
    for (const Found& f : found)
      if (f.kind == ModuleKind::kWheel) {
        motion = motion_from_wheel(f.file, start);
        if (motion) motion_source = "wheel gyro of " + f.name;
        break;
      }

  m.static_start = start;
  m.static_end = start;
  if (motion && *motion - kStaticMargin - start >= 1.0) {
    m.static_end = *motion - kStaticMargin;
    note["static_period_s"] = "until " + format_double(kStaticMargin) + " s before the first motion (" +
                              motion_source + ")";
    d.facts.push_back("static period " + seconds(m.static_end - m.static_start) + " (" + motion_source + ")");
  } else {
    note["static_period_s"] = "TODO: no static period found at the start; set one";
    d.todo.push_back("static_period_s: no static period found at the start of the data");
  }

  m.earth_rotation = true;
  m.track_width = any_left && any_right ? kRobotTrack : 0.0;
  if (any_left && any_right) note["vehicle.track_m"] = kTodo;

  // What the user must measure.
  d.todo.insert(d.todo.begin(), {
      "wheel modules: wheel_radius_m, lever_arm_b_m (IMU centre -> wheel centre), position_v_m, "
      "mounting_deg, axle_sign (typical Pioneer 3DX values written)",
  });
  bool any_body = std::any_of(found.begin(), found.end(), [](const Found& f) { return f.kind == ModuleKind::kBody; });
  bool any_wheel = std::any_of(found.begin(), found.end(), [](const Found& f) { return f.kind == ModuleKind::kWheel; });
  if (!any_wheel) d.todo.erase(d.todo.begin());
  if (any_body)
    d.todo.insert(d.todo.begin() + (any_wheel ? 1 : 0),
                  "body modules: position_v_m and mounting_deg (C_b^v; zero written)");
  if (any_left && any_right) d.todo.push_back("vehicle.track_m (0.33 written)");

  d.notes.header = {"drafted by `wheelins manifest` from " + dir.string(),
                    "values marked 'TODO' are guesses: measure them before trusting results",
                    "no noise figures: they are identified from the data (noise.yaml of a run); "
                    "state your IMUs' figures under noise: to give priors (docs/manifest.md)"};
  return d;
}

}  // namespace wheelins
