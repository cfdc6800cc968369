// Loading, checking and saving manifests (manifest.hpp): human units <-> SI with exact
// round trips, every key checked with the file and line named; Manifest -> VehicleSetup.
#include "wheelins/io/manifest.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>
#include <system_error>

#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/table_import.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/io/yaml_reader.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins {
namespace fs = std::filesystem;
using io_detail::format_double;
using io_detail::quote;

namespace {

constexpr const char* kFormatId = "wheelins-manifest-1";

// Human units on disk, SI in memory. A number as people write it (up to 17 significant
// digits) converts as si = x * mul / div in double arithmetic -- the same expression
// as the defaults in ImuNoise (0.24 * kDeg / 60.0), so defaults print as written.
// Not every double is reachable that way; for those save_manifest writes a longer
// text (more than 17 significant digits), which converts in long double precision
// (si = round(x * factor)), so that save -> load is always bit-identical.
struct Unit {
  double mul, div;
  long double factor;
};
constexpr long double kPiL = 3.141592653589793238462643383279502884L;
constexpr Unit kOne{1.0, 1.0, 1.0L};                                // m, s, Hz, m/s^2
constexpr Unit kDegU{kDeg, 1.0, kPiL / 180.0L};                     // deg -> rad
constexpr Unit kArwU{kDeg, 60.0, kPiL / 180.0L / 60.0L};            // deg/sqrt(h) -> rad/sqrt(s)
constexpr Unit kVrwU{1.0, 60.0, 1.0L / 60.0L};                      // m/s/sqrt(h) -> m/s/sqrt(s)
constexpr Unit kDegPerHourU{kDeg, 3600.0, kPiL / 180.0L / 3600.0L};  // deg/h -> rad/s
constexpr Unit kPpmU{1.0, 1e6, 1e-6L};                              // ppm -> [-]
constexpr Unit kHourU{3600.0, 1.0, 3600.0L};                        // h -> s

int significant_digits(std::string_view text) {
  int n = 0;
  bool started = false;
  for (char c : text) {
    if (c == 'e' || c == 'E') break;
    if (c < '0' || c > '9') continue;
    if (c != '0') started = true;
    if (started) ++n;
  }
  return n;
}

/// The SI value of a human-unit text, or nullopt if the text is not a number.
std::optional<double> human_to_si(std::string_view text, Unit u) {
  if (u.factor == 1.0L) return io_detail::parse_double(text);
  if (significant_digits(text) > 17) {
    const auto x = io_detail::parse_long_double(text);
    if (!x) return std::nullopt;
    return static_cast<double>(*x * u.factor);
  }
  const auto x = io_detail::parse_double(text);
  if (!x) return std::nullopt;
  return *x * u.mul / u.div;
}

/// The shortest human-unit text that human_to_si() maps back to exactly `si`.
std::string si_to_human(double si, Unit u) {
  if (u.factor == 1.0L || si == 0.0 || !std::isfinite(si)) return format_double(si);
  // Prefer the shortest text among the doubles next to the quotient.
  const double h = si * u.div / u.mul;
  std::string best;
  double up = h, down = h;
  for (int i = 0; i < 8; ++i) {
    for (double c : {up, down}) {
      std::string t = format_double(c);
      if ((best.empty() || t.size() < best.size()) && human_to_si(t, u) == si) best = std::move(t);
    }
    up = std::nextafter(up, HUGE_VAL);
    down = std::nextafter(down, -HUGE_VAL);
  }
  if (!best.empty()) return best;
  // Otherwise a long text, converted in long double precision (always reaches si).
  const long double hl = static_cast<long double>(si) / u.factor;
  long double lup = hl, ldown = hl;
  char buf[96];
  for (int i = 0; i < 64; ++i) {
    for (long double c : {lup, ldown}) {
      std::snprintf(buf, sizeof buf, "%.*Le", LDBL_DECIMAL_DIG - 1, c);
      if (human_to_si(buf, u) == si) return buf;
    }
    lup = std::nextafter(lup, HUGE_VALL);
    ldown = std::nextafter(ldown, -HUGE_VALL);
  }
  return format_double(h);  // within an ulp of si; not reached in practice
}

const std::vector<std::string> kTopKeys = {"format",         "name",         "truth",
                                           "truth_time_offset_s", "odometer", "static_period_s",
                                           "initial",        "gravity_m_s2", "earth_rotation",
                                           "vehicle",        "modules"};
const std::vector<std::string> kInitialKeys = {"lat_deg", "lon_deg", "h_m", "heading_deg"};
const std::vector<std::string> kVehicleKeys = {"track_m", "wheelbase_m", "antenna_v_m"};
const std::vector<std::string> kModuleKeys = {
    "name",          "kind",          "group",        "chip",      "file",
    "format",        "layout",        "rate_hz",      "time_offset_s", "position_v_m",
    "lever_arm_b_m", "mounting_deg",  "axle_sign",    "axle_axis",  "wheel_radius_m", "odometry_radius_m", "yaw_scale_ppm", "steered", "gyro_range_dps",
    "accel_range_m_s2", "noise"};

/// One noise key: its name, its unit factor and the ImuNoise member it fills.
struct NoiseKey {
  const char* key;
  Unit unit;
  double ImuNoise::*member;
  double lo, hi;  ///< the physical range, in the key's unit (docs/manifest.md)
  const char* unit_name;
};
const NoiseKey kNoiseKeys[] = {
    {"gyro_arw_deg_sqrt_h", kArwU, &ImuNoise::gyro_arw, 1e-4, 100.0, "deg/sqrt(h)"},
    {"acc_vrw_m_s_sqrt_h", kVrwU, &ImuNoise::acc_vrw, 1e-4, 100.0, "m/s/sqrt(h)"},
    {"gyro_bias_deg_h", kDegPerHourU, &ImuNoise::gyro_bias_std, 1e-3, 1e5, "deg/h"},
    {"acc_bias_m_s2", kOne, &ImuNoise::acc_bias_std, 1e-6, 10.0, "m/s^2"},
    {"gyro_sf_ppm", kPpmU, &ImuNoise::gyro_sf_std, 1e-3, 2e5, "ppm"},
    {"acc_sf_ppm", kPpmU, &ImuNoise::acc_sf_std, 1e-3, 2e5, "ppm"},
    {"gyro_bias_tau_h", kHourU, &ImuNoise::gyro_bias_tau, 1e-3, 1e4, "h"},
    {"acc_bias_tau_h", kHourU, &ImuNoise::acc_bias_tau, 1e-3, 1e4, "h"},
    {"gyro_sf_tau_h", kHourU, &ImuNoise::gyro_sf_tau, 1e-3, 1e4, "h"},
    {"acc_sf_tau_h", kHourU, &ImuNoise::acc_sf_tau, 1e-3, 1e4, "h"},
};

std::vector<std::string> noise_key_names() {
  std::vector<std::string> v;
  for (const auto& k : kNoiseKeys) v.emplace_back(k.key);
  return v;
}

/// Reads one manifest: the generic YAML checks come from YamlReader; the manifest adds
/// its exact human-unit conversion (Unit) and its own structure.
class Loader : public YamlReader {
 public:
  Loader(const fs::path& file, const WarningSink& warn)
      : YamlReader(file, warn, "manifest", " (create one with `wheelins manifest DIR`)"),
        file_(file) {}

  double number(const YAML::Node& v, const std::string& path, Unit u = kOne) const {
    if (!v.IsScalar()) fail(path, "expected a number, got " + describe(v), &v);
    const auto x = human_to_si(v.Scalar(), u);
    if (!x) fail(path, "expected a number, got " + describe(v), &v);
    if (!std::isfinite(*x)) fail(path, "expected a finite number, got " + describe(v), &v);
    return *x;
  }

  Vec3 vec3(const YAML::Node& v, const std::string& path, Unit u = kOne) const {
    if (!v.IsSequence() || v.size() != 3)
      fail(path, "expected a list of 3 numbers [x, y, z], got " +
                     (v.IsSequence() ? "a list of " + std::to_string(v.size()) : describe(v)),
           &v);
    Vec3 out;
    for (std::size_t i = 0; i < 3; ++i) out[static_cast<int>(i)] = number(v[i], index_path(path, i), u);
    return out;
  }

  void positive(double x, const std::string& path, const YAML::Node& at, const char* what) const {
    if (!(x > 0.0))
      fail(path, std::string("must be > 0 (") + what + "), got " + format_double(x), &at);
  }

  Manifest load();

 private:
  ModuleSpec module(const YAML::Node& n, const std::string& path) const;
  void noise(const YAML::Node& n, const std::string& path, ModuleSpec& out) const;

  fs::path file_;
};

Manifest Loader::load() {
  const YAML::Node& root = this->root();
  check_keys(root, "", kTopKeys);

  Manifest m;
  m.path = fs::absolute(file_).lexically_normal();

  const YAML::Node fmt = required(root, "", "format");
  if (text(fmt, "format") != kFormatId)
    fail("format", std::string("unsupported manifest format ") + describe(fmt) +
                       " (this build reads '" + kFormatId + "')",
         &fmt);

  if (auto v = get(root, "name"); v.IsDefined()) m.name = text(v, "name");
  if (auto v = get(root, "truth"); v.IsDefined()) m.truth_file = fs::path(text(v, "truth"));
  if (auto v = get(root, "truth_time_offset_s"); v.IsDefined()) {
    m.truth_time_offset = number(v, "truth_time_offset_s");
    range(m.truth_time_offset, -1e7, 1e7, "truth_time_offset_s", v, "s");
  }
  if (auto v = get(root, "odometer"); v.IsDefined()) m.odometer_file = fs::path(text(v, "odometer"));

  if (auto v = get(root, "static_period_s"); v.IsDefined()) {
    if (!v.IsSequence() || v.size() != 2)
      fail("static_period_s", "expected a list of 2 times [start, end], got " +
                                  (v.IsSequence() ? "a list of " + std::to_string(v.size())
                                                  : describe(v)),
           &v);
    m.static_start = number(v[0], "static_period_s[0]");
    m.static_end = number(v[1], "static_period_s[1]");
    if (m.static_end < m.static_start)
      fail("static_period_s", "end " + format_double(m.static_end) + " is before start " +
                                  format_double(m.static_start),
           &v);
    if (m.static_end - m.static_start > 3600.0)
      fail("static_period_s", "lasts " + format_double(m.static_end - m.static_start) +
                                  " s; a static period lasts at most 3600 s (is it in seconds?)",
           &v);
  }

  {
    const YAML::Node init = required(root, "", "initial");
    require_map(init, "initial");
    check_keys(init, "initial", kInitialKeys);
    const YAML::Node lat = required(init, "initial", "lat_deg");
    const YAML::Node lon = required(init, "initial", "lon_deg");
    const YAML::Node h = required(init, "initial", "h_m");
    const YAML::Node hd = get(init, "heading_deg");
    const double lat_deg = number(lat, "initial.lat_deg");
    const double lon_deg = number(lon, "initial.lon_deg");
    if (std::abs(lat_deg) > 90.0)
      fail("initial.lat_deg", "latitude must be within [-90, 90] deg, got " + format_double(lat_deg), &lat);
    if (std::abs(lon_deg) > 360.0)
      fail("initial.lon_deg", "longitude must be within [-360, 360] deg, got " + format_double(lon_deg), &lon);
    m.origin.lat = number(lat, "initial.lat_deg", kDegU);
    m.origin.lon = number(lon, "initial.lon_deg", kDegU);
    range(number(h, "initial.h_m"), -1000.0, 10000.0, "initial.h_m", h, "m (ellipsoidal)");
    m.origin.h = number(h, "initial.h_m");
    m.heading_known = hd.IsDefined();
    if (m.heading_known) {
      range(number(hd, "initial.heading_deg"), -360.0, 360.0, "initial.heading_deg", hd, "deg");
      m.initial_heading = number(hd, "initial.heading_deg", kDegU);
    }
  }

  if (auto v = get(root, "gravity_m_s2"); v.IsDefined()) {
    const double g = number(v, "gravity_m_s2");
    range(g, 9.7, 9.9, "gravity_m_s2", v, "m/s^2 (gravity on the earth's surface)");
    m.gravity = g;
  }
  if (auto v = get(root, "earth_rotation"); v.IsDefined()) m.earth_rotation = boolean(v, "earth_rotation");
  if (auto veh = get(root, "vehicle"); veh.IsDefined()) {
    require_map(veh, "vehicle");
    check_keys(veh, "vehicle", kVehicleKeys);
    if (auto v = get(veh, "track_m"); v.IsDefined()) {
      m.track_width = number(v, "vehicle.track_m");
      range(m.track_width, 0.0, 10.0, "vehicle.track_m", v, "m (0: unknown)");
    }
    if (auto v = get(veh, "wheelbase_m"); v.IsDefined()) {
      m.wheelbase = number(v, "vehicle.wheelbase_m");
      range(m.wheelbase, 0.0, 20.0, "vehicle.wheelbase_m", v, "m (0: unknown)");
    }
    if (auto v = get(veh, "antenna_v_m"); v.IsDefined()) {
      const Vec3 a = vec3(v, "vehicle.antenna_v_m");
      for (std::size_t i = 0; i < 3; ++i)
        range(a[static_cast<int>(i)], -20.0, 20.0, index_path("vehicle.antenna_v_m", i), v, "m");
      m.antenna_inV = a;
    }
  }

  const YAML::Node mods = required(root, "", "modules");
  if (!mods.IsSequence())
    fail("modules", "expected a list of modules ('- name: ...' entries), got " + describe(mods), &mods);
  if (mods.size() == 0) fail("modules", "no IMU module listed; a manifest needs at least one", &mods);
  for (std::size_t i = 0; i < mods.size(); ++i) {
    const std::string path = YamlReader::index_path("modules", i);
    const YAML::Node entry = mods[i];
    m.modules.push_back(module(entry, path));
    for (std::size_t j = 0; j < i; ++j) {
      if (m.modules[j].name == m.modules[i].name)
        fail(join(path, "name"), "duplicate module name '" + m.modules[i].name +
                                     "' (also modules[" + std::to_string(j) + "])",
             &entry);
      // (A recording that is not there is an error of its own when read; a manifest of
      // pushed samples, the Python Navigator's, names the same placeholder for every module.)
      std::error_code ec;
      const fs::path fi = m.resolve(m.modules[i].file), fj = m.resolve(m.modules[j].file);
      if (fs::exists(fi, ec) && fs::exists(fj, ec) && same_file(fi, fj))
        fail(join(path, "file"), "module '" + m.modules[i].name + "' reads the same file as module '" +
                                     m.modules[j].name + "' (modules[" + std::to_string(j) +
                                     "]); each module is one IMU's own recording",
             &entry);
    }
  }
  return m;
}

ModuleSpec Loader::module(const YAML::Node& n, const std::string& path) const {
  require_map(n, path);
  check_keys(n, path, kModuleKeys);
  ModuleSpec s;
  s.name = text(required(n, path, "name"), join(path, "name"));
  // A module's name names its output files (NAME.csv in a run's directory): checked here,
  // where the manifest is read, not when a file cannot be written after the run.
  try {
    check_module_name(s.name);
  } catch (const InputError& e) {
    fail(join(path, "name"), e.what(), &n);
  }
  for (const char* reserved : kReservedModuleNames)
    if (s.name == reserved)
      fail(join(path, "name"), "'" + s.name + "' is the name of a run's own output (" + s.name +
                                   ".csv); choose another module name", &n);
  s.kind = choice<ModuleKind>(required(n, path, "kind"), join(path, "kind"),
                              {{"wheel", ModuleKind::kWheel}, {"body", ModuleKind::kBody}});
  s.group = s.name;
  if (auto v = get(n, "group"); v.IsDefined()) s.group = text(v, join(path, "group"));
  if (auto v = get(n, "chip"); v.IsDefined()) s.chip = text(v, join(path, "chip"));
  s.file = fs::path(text(required(n, path, "file"), join(path, "file")));
  if (auto v = get(n, "format"); v.IsDefined())
    s.format = choice<SampleFormat>(v, join(path, "format"),
                                    {{"rate", SampleFormat::kRate},
                                     {"increment", SampleFormat::kIncrement}});
  if (auto v = get(n, "layout"); v.IsDefined())
    s.layout = choice<FileLayout>(v, join(path, "layout"),
                                  {{"binary", FileLayout::kBinary}, {"text", FileLayout::kText}});
  if (auto v = get(n, "rate_hz"); v.IsDefined()) {
    s.rate_hz = number(v, join(path, "rate_hz"));
    range(s.rate_hz, 1.0, 10000.0, join(path, "rate_hz"), v, "Hz");
  }
  if (auto v = get(n, "time_offset_s"); v.IsDefined()) {
    s.time_offset = number(v, join(path, "time_offset_s"));
    range(s.time_offset, -1e7, 1e7, join(path, "time_offset_s"), v, "s");
  }
  auto vec_in = [&](const YAML::Node& v, const std::string& p, double lim) {
    const Vec3 x = vec3(v, p);
    for (std::size_t i = 0; i < 3; ++i)
      range(x[static_cast<int>(i)], -lim, lim, index_path(p, i), v, "m");
    return x;
  };
  if (auto v = get(n, "position_v_m"); v.IsDefined())
    s.p_inV = vec_in(v, join(path, "position_v_m"), ManifestLimits::kPositionM);
  if (auto v = get(n, "lever_arm_b_m"); v.IsDefined())
    s.lever_arm_inB = vec_in(v, join(path, "lever_arm_b_m"),
                             s.kind == ModuleKind::kWheel ? ManifestLimits::kWheelLeverArmM : ManifestLimits::kBodyLeverArmM);
  if (auto v = get(n, "mounting_deg"); v.IsDefined()) {
    const std::string p = join(path, "mounting_deg");
    const Vec3 deg = vec3(v, p);
    if (std::abs(deg.y()) > 90.0)
      fail(index_path(p, 1), "pitch must be within [-90, 90] deg, got " + format_double(deg.y()), &v);
    for (int i : {0, 2})
      if (std::abs(deg[i]) > 360.0)
        fail(index_path(p, static_cast<std::size_t>(i)),
             "angle must be within [-360, 360] deg, got " + format_double(deg[i]), &v);
    s.mounting_rpy = vec3(v, p, kDegU);
  }
  if (auto v = get(n, "axle_sign"); v.IsDefined()) {
    const double a = number(v, join(path, "axle_sign"));
    if (a != 1.0 && a != -1.0)
      fail(join(path, "axle_sign"),
           "must be +1 (the axle axis points to the vehicle's right) or -1 (to its left), got " + describe(v), &v);
    s.axle_sign = static_cast<int>(a);
  }
  if (auto v = get(n, "axle_axis"); v.IsDefined())
    s.axle_axis = choice<int>(v, join(path, "axle_axis"), {{"x", 0}, {"y", 1}, {"z", 2}});
  if (auto v = get(n, "wheel_radius_m"); v.IsDefined()) {
    s.wheel_radius = number(v, join(path, "wheel_radius_m"));
    if (s.kind == ModuleKind::kWheel)
      range(s.wheel_radius, 0.01, 2.0, join(path, "wheel_radius_m"), v, "m (a wheel radius)");
    else
      range(s.wheel_radius, 0.0, 2.0, join(path, "wheel_radius_m"), v, "m");
  } else if (s.kind == ModuleKind::kWheel) {
    fail(path, "missing required key 'wheel_radius_m' (every wheel module needs its wheel radius)", &n);
  }
  if (auto v = get(n, "steered"); v.IsDefined()) {
    s.steered = boolean(v, join(path, "steered"));
    if (s.steered && s.kind != ModuleKind::kWheel)
      fail(join(path, "steered"), "only a wheel module can be steered (this one is a body module)", &v);
  }
  if (auto v = get(n, "odometry_radius_m"); v.IsDefined()) {
    s.odometry_radius = number(v, join(path, "odometry_radius_m"));
    range(s.odometry_radius, 0.01, 2.0, join(path, "odometry_radius_m"), v, "m (a wheel radius)");
  }
  if (auto v = get(n, "yaw_scale_ppm"); v.IsDefined()) {
    const std::string p = join(path, "yaw_scale_ppm");
    if (s.kind != ModuleKind::kWheel)
      fail(p, "only a wheel module has a yaw scale factor here (a body module's gyro is not scaled)", &v);
    range(number(v, p), -ManifestLimits::kYawScalePpm, ManifestLimits::kYawScalePpm, p, v,
          "ppm (the wheel-plane gyro axes' scale-factor error)");
    s.yaw_scale = number(v, p) * 1e-6;
  }
  if (auto v = get(n, "gyro_range_dps"); v.IsDefined()) {
    const std::string p = join(path, "gyro_range_dps");
    range(number(v, p), ManifestLimits::kGyroRangeMinDps, ManifestLimits::kGyroRangeMaxDps, p, v,
          "deg/s (the gyro's full scale)");
    s.gyro_range = number(v, p, kDegU);
  }
  if (auto v = get(n, "accel_range_m_s2"); v.IsDefined()) {
    const std::string p = join(path, "accel_range_m_s2");
    s.accel_range = number(v, p);
    range(s.accel_range, ManifestLimits::kAccelRangeMin, ManifestLimits::kAccelRangeMax, p, v,
          "m/s^2 (the accelerometer's full scale)");
  }
  // Defaults for what the manifest does not state: ImuNoise's, and a velocity random walk
  // by kind (a rolling wheel vibrates).
  s.noise_stated = 0;
  s.noise.acc_vrw = s.kind == ModuleKind::kWheel ? kDefaultWheelVrw : kDefaultBodyVrw;
  if (auto v = get(n, "noise"); v.IsDefined()) noise(v, join(path, "noise"), s);
  if (s.steered && !(s.p_inV.x() >= 0.3))
    fail(join(path, "position_v_m"),
         "a steered wheel's x is its distance ahead of the rear axle (the v-frame origin o is the "
         "mid rear axle): at least 0.3 m, got " + format_double(s.p_inV.x()), &n);
  return s;
}

void Loader::noise(const YAML::Node& n, const std::string& path, ModuleSpec& out) const {
  require_map(n, path);
  check_keys(n, path, noise_key_names());
  std::uint16_t bit = 1;
  for (const auto& k : kNoiseKeys) {
    if (auto v = get(n, k.key); v.IsDefined()) {
      const std::string p = join(path, k.key);
      range(number(v, p), k.lo, k.hi, p, v, k.unit_name);
      out.noise.*k.member = number(v, p, k.unit);
      out.noise_stated |= bit;
    }
    bit = static_cast<std::uint16_t>(bit << 1);
  }
}

// ---------------------------------------------------------------------------- writing

// A YAML double-quoted scalar: its escapes include JSON's (\", \\, \n, \t, \r, \u00XX).
std::string yaml_string(const std::string& s) { return io_detail::json_quote(s); }

class YamlWriter {
 public:
  explicit YamlWriter(const ManifestAnnotations& notes) : notes_(notes) {}
  /// One "key: value" line at `indent` spaces; `path` selects an annotation.
  void line(int indent, const std::string& text, const std::string& path, const char* unit_note = nullptr) {
    std::string l(static_cast<std::size_t>(indent), ' ');
    l += text;
    std::string comment;
    if (auto it = notes_.comments.find(path); it != notes_.comments.end()) comment = it->second;
    if (unit_note && comment.empty()) comment = unit_note;
    if (!comment.empty()) {
      if (l.size() < 40) l.resize(40, ' ');
      else l += "  ";
      l += "# " + comment;
    }
    out_ += l + "\n";
  }
  void raw(const std::string& text) { out_ += text + "\n"; }
  std::string str() const { return out_; }

 private:
  const ManifestAnnotations& notes_;
  std::string out_;
};

std::string num(double si, Unit u = kOne) { return si_to_human(si, u); }
std::string vec(const Vec3& v, Unit u = kOne) {
  return "[" + num(v.x(), u) + ", " + num(v.y(), u) + ", " + num(v.z(), u) + "]";
}

/// A data-file path as it must be written in a manifest placed in `dir`.
fs::path rebase(const Manifest& m, const fs::path& p, const fs::path& dir) {
  if (p.is_absolute() || m.path.empty()) return p;
  const fs::path from = fs::absolute(m.path).parent_path().lexically_normal();
  const fs::path to = fs::absolute(dir).lexically_normal();
  if (from == to) return p;
  const fs::path abs = (from / p).lexically_normal();
  fs::path rel = abs.lexically_relative(to);
  return rel.empty() ? abs : rel;
}

}  // namespace

const char* to_string(ModuleKind k) { return k == ModuleKind::kWheel ? "wheel" : "body"; }
const char* to_string(SampleFormat f) { return f == SampleFormat::kRate ? "rate" : "increment"; }
const char* to_string(FileLayout l) { return l == FileLayout::kBinary ? "binary" : "text"; }

fs::path Manifest::resolve(const fs::path& p) const {
  if (p.is_absolute() || path.empty()) return p;
  return path.parent_path() / p;
}

std::vector<fs::path> Manifest::input_files() const {
  std::vector<fs::path> out;
  for (const auto& m : modules) out.push_back(resolve(m.file));
  if (truth_file) out.push_back(resolve(*truth_file));
  if (odometer_file) out.push_back(resolve(*odometer_file));
  return out;
}

const ModuleSpec* Manifest::find(const std::string& module_name) const {
  for (const auto& mod : modules)
    if (mod.name == module_name) return &mod;
  return nullptr;
}

double Manifest::gravity_or_default() const {
  return gravity ? *gravity : earth::normal_gravity(origin.lat, origin.h);
}

VehicleSetup vehicle_setup(const Manifest& m) {
  VehicleSetup s;
  s.source = m.path.string();
  s.origin = m.origin;
  s.static_start = m.static_start;
  s.static_end = m.static_end;
  s.initial_heading = m.initial_heading;
  s.heading_known = m.heading_known;
  s.gravity = m.gravity_or_default();
  for (const ModuleSpec& spec : m.modules) {
    s.modules.push_back(spec);  // the ImuModule part
    s.data_sources.push_back(m.resolve(spec.file).string());
  }
  return s;
}

Manifest::operator VehicleSetup() const { return vehicle_setup(*this); }

Manifest load_manifest(const fs::path& file) { return load_manifest(file, stderr_sink()); }

Manifest load_manifest(const fs::path& file, const WarningSink& warn) {
  return Loader(file, warn).load();
}

std::string manifest_to_yaml(const Manifest& m, const fs::path& dir, const ManifestAnnotations& notes) {
  YamlWriter w(notes);
  w.raw("# wheelins dataset manifest: human units, see docs/manifest.md");
  for (const auto& h : notes.header) w.raw(h.empty() ? "#" : "# " + h);
  w.line(0, std::string("format: ") + kFormatId, "format");
  if (!m.name.empty()) w.line(0, "name: " + yaml_string(m.name), "name");
  if (m.truth_file) w.line(0, "truth: " + yaml_string(rebase(m, *m.truth_file, dir).string()), "truth");
  if (m.truth_time_offset != 0.0)
    w.line(0, "truth_time_offset_s: " + num(m.truth_time_offset), "truth_time_offset_s",
           "added to the truth's times");
  if (m.odometer_file)
    w.line(0, "odometer: " + yaml_string(rebase(m, *m.odometer_file, dir).string()), "odometer");
  w.line(0, "static_period_s: [" + num(m.static_start) + ", " + num(m.static_end) + "]",
         "static_period_s", "initial alignment, data time [s]");
  w.line(0, "initial:", "initial", "the w-frame origin o and the vehicle heading at the start");
  w.line(2, "lat_deg: " + num(m.origin.lat, kDegU), "initial.lat_deg");
  w.line(2, "lon_deg: " + num(m.origin.lon, kDegU), "initial.lon_deg");
  w.line(2, "h_m: " + num(m.origin.h), "initial.h_m", "ellipsoidal height");
  if (m.heading_known) w.line(2, "heading_deg: " + num(m.initial_heading, kDegU), "initial.heading_deg");
  if (m.gravity) w.line(0, "gravity_m_s2: " + num(*m.gravity), "gravity_m_s2");
  w.line(0, std::string("earth_rotation: ") + (m.earth_rotation ? "true" : "false"), "earth_rotation",
         "the data contain the earth rotation rate");
  w.line(0, "vehicle:", "vehicle");
  w.line(2, "track_m: " + num(m.track_width), "vehicle.track_m", "0: unknown");
  if (m.wheelbase != 0.0) w.line(2, "wheelbase_m: " + num(m.wheelbase), "vehicle.wheelbase_m");
  if (m.antenna_inV)
    w.line(2, "antenna_v_m: " + vec(*m.antenna_inV), "vehicle.antenna_v_m",
           "the truth's antenna in the v-frame");
  w.line(0, "modules:", "modules");
  for (std::size_t i = 0; i < m.modules.size(); ++i) {
    const ModuleSpec& s = m.modules[i];
    const std::string p = YamlReader::index_path("modules", i) + ".";
    const bool wheel = s.kind == ModuleKind::kWheel;
    w.line(2, "- name: " + yaml_string(s.name), YamlReader::index_path("modules", i));
    w.line(4, std::string("kind: ") + to_string(s.kind), p + "kind");
    if (!s.group.empty()) w.line(4, "group: " + yaml_string(s.group), p + "group");
    if (!s.chip.empty()) w.line(4, "chip: " + yaml_string(s.chip), p + "chip");
    w.line(4, "file: " + yaml_string(rebase(m, s.file, dir).string()), p + "file");
    w.line(4, std::string("format: ") + to_string(s.format), p + "format",
           "rate: rad/s, m/s^2; increment: rad, m/s per sample");
    w.line(4, std::string("layout: ") + to_string(s.layout), p + "layout");
    w.line(4, "rate_hz: " + num(s.rate_hz), p + "rate_hz");
    w.line(4, "time_offset_s: " + num(s.time_offset), p + "time_offset_s", "added to the file's times");
    w.line(4, "position_v_m: " + vec(s.p_inV), p + "position_v_m",
           wheel ? "wheel centre in the v-frame" : "IMU centre in the v-frame");
    if (wheel || s.lever_arm_inB != Vec3::Zero())
      w.line(4, "lever_arm_b_m: " + vec(s.lever_arm_inB), p + "lever_arm_b_m",
             "IMU centre -> wheel centre, b-frame");
    w.line(4, "mounting_deg: " + vec(s.mounting_rpy, kDegU), p + "mounting_deg",
           wheel ? "[roll, pitch, yaw] sensor axes vs ideal wheel frame" : "[roll, pitch, yaw] C_b^v");
    if (s.axle_axis != 0)
      w.line(4, std::string("axle_axis: ") + "xyz"[s.axle_axis], p + "axle_axis",
             "the sensor axis along the axle");
    if (wheel || s.axle_sign != 1)
      w.line(4, "axle_sign: " + std::to_string(s.axle_sign), p + "axle_sign",
             "+1: the axle axis points right, -1: left");
    if (wheel || s.wheel_radius != 0.0)
      w.line(4, "wheel_radius_m: " + num(s.wheel_radius), p + "wheel_radius_m");
    if (s.steered)
      w.line(4, "steered: true", p + "steered",
             "turns with the steering; o is the mid rear axle, position x the distance ahead of it");
    if (s.odometry_radius > 0.0)
      w.line(4, "odometry_radius_m: " + num(s.odometry_radius), p + "odometry_radius_m",
             "for the raw axle rate (wheelins odometry)");
    if (s.yaw_scale != 0.0)
      w.line(4, "yaw_scale_ppm: " + num(s.yaw_scale * 1e6), p + "yaw_scale_ppm",
             "the wheel-plane gyro axes read (1 + this) x the rate (from a reference)");
    if (s.gyro_range > 0.0)
      w.line(4, "gyro_range_dps: " + num(s.gyro_range, kDegU), p + "gyro_range_dps",
             "full scale: readings at it are saturated");
    if (s.accel_range > 0.0)
      w.line(4, "accel_range_m_s2: " + num(s.accel_range), p + "accel_range_m_s2",
             "full scale: readings beyond it are faults");
    if (s.noise_stated) {
      w.line(4, "noise:", p + "noise");
      std::uint16_t bit = 1;
      for (const auto& k : kNoiseKeys) {
        if (s.noise_stated & bit)
          w.line(6, std::string(k.key) + ": " + num(s.noise.*k.member, k.unit), p + "noise." + k.key);
        bit = static_cast<std::uint16_t>(bit << 1);
      }
    }
  }
  return w.str();
}

ManifestAnnotations read_manifest_notes(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(quote(file) + ": cannot read");
  ManifestAnnotations notes;
  std::vector<std::pair<std::size_t, std::string>> stack;  // (indent, path) of the open keys
  std::map<std::string, int> items;                         // list items seen per list path
  bool body = false;
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::size_t ind = line.find_first_not_of(' ');
    if (ind == std::string::npos) continue;
    if (line[ind] == '#') {
      if (!body && ind == 0 && line.rfind("# wheelins dataset manifest", 0) != 0)
        notes.header.push_back(line.size() > 2 ? line.substr(2) : std::string());
      continue;
    }
    body = true;
    // The comment: a '#' after a blank, outside double quotes.
    std::string comment;
    bool quoted = false;
    for (std::size_t k = ind; k < line.size(); ++k) {
      if (line[k] == '"' && (k == 0 || line[k - 1] != '\\')) quoted = !quoted;
      if (!quoted && line[k] == '#' && k > 0 && line[k - 1] == ' ') {
        comment = line.substr(k + 1);
        line.resize(k);
        break;
      }
    }
    comment.erase(0, comment.find_first_not_of(' '));
    // "- key:" opens an element of the list its parent key holds; its keys sit 2 further in.
    const bool item = line.compare(ind, 2, "- ") == 0;
    const std::size_t at = item ? ind + 2 : ind;
    const std::size_t colon = line.find(':', at);
    if (colon == std::string::npos) continue;
    const std::string key = line.substr(at, colon - at);
    while (!stack.empty() && stack.back().first >= ind) stack.pop_back();
    std::string parent = stack.empty() ? "" : stack.back().second;
    if (item) {
      parent += "[" + std::to_string(items[parent]++) + "]";
      stack.emplace_back(ind, parent);
      if (key == "name" && !comment.empty()) notes.comments[parent] = comment;  // as the writer puts it
    }
    const std::string path = parent.empty() ? key : parent + "." + key;
    stack.emplace_back(at, path);
    if (!comment.empty() && !(item && key == "name")) notes.comments[path] = comment;
  }
  return notes;
}

void save_manifest(const Manifest& m, const fs::path& file) { save_manifest(m, file, {}); }

void save_manifest(const Manifest& m, const fs::path& file, const ManifestAnnotations& notes) {
  if (m.modules.empty()) throw InputError(quote(file) + ": refusing to write a manifest without modules");
  std::error_code ec;
  if (fs::is_directory(file, ec))
    throw InputError(quote(file) + ": is a directory, expected a manifest file name");
  const fs::path dir = file.has_parent_path() ? file.parent_path() : fs::path(".");
  write_file_atomic(file, manifest_to_yaml(m, dir, notes));
}

}  // namespace wheelins
