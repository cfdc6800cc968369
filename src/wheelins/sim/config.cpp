// Simulator settings (config.hpp): presets, profiles and effects, their checks, and the
// scenario.yaml form both ways.
#include "wheelins/sim/config.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <cstdio>
#include <functional>
#include <sstream>

#include "wheelins/io/manifest.hpp"
#include "wheelins/io/yaml_reader.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins::sim {
namespace {

/// A number in human units: si = x * mul / div (the same expression the defaults use).
struct HumanUnit {
  double mul = 1.0, div = 1.0;
};
constexpr HumanUnit kSi{1.0, 1.0};
constexpr HumanUnit kDegU{kDeg, 1.0};
constexpr HumanUnit kDegH{kDeg, 3600.0};
constexpr HumanUnit kArw{kDeg, 60.0};
constexpr HumanUnit kVrw{1.0, 60.0};
constexpr HumanUnit kPpm{1.0, 1e6};
constexpr HumanUnit kMgPerK{9.80665e-3, 1.0};

/// Shortest decimal text x with x * mul / div == si exactly (falls back to 17 digits).
std::string human(double si, HumanUnit u) {
  const double h = si * u.div / u.mul;
  char buf[64];
  // Enough digits for the integer part, so 120 prints as "120", not "1.2e+02".
  const int int_digits = std::abs(h) >= 1.0 && std::abs(h) < 1e17
                             ? static_cast<int>(std::floor(std::log10(std::abs(h)))) + 1
                             : 1;
  for (int p = std::max(1, int_digits); p <= 17; ++p) {
    std::snprintf(buf, sizeof buf, "%.*g", p, h);
    if (std::strtod(buf, nullptr) * u.mul / u.div == si) return buf;
  }
  double c = h;  // neighbours of the quotient
  for (int i = 0; i < 4; ++i) {
    for (double d : {std::nextafter(c, 1e300), std::nextafter(c, -1e300)}) {
      std::snprintf(buf, sizeof buf, "%.17g", d);
      if (std::strtod(buf, nullptr) * u.mul / u.div == si) return buf;
    }
    c = std::nextafter(c, 1e300);
  }
  std::snprintf(buf, sizeof buf, "%.17g", h);
  return buf;
}

std::string vec_text(const Vec3& v, HumanUnit u) {
  return "[" + human(v.x(), u) + ", " + human(v.y(), u) + ", " + human(v.z(), u) + "]";
}

double get_double(const YAML::Node& n, const std::string& where) {
  try {
    return n.as<double>();
  } catch (const YAML::Exception&) {
    throw InputError(where + ": expected a number, got " +
                     (n.IsScalar() ? "'" + n.Scalar() + "'" : n.IsDefined() && !n.IsNull() ? "a list or mapping" : "nothing"));
  }
}
/// A whole number up to `hi` (a seed, a count; its range is checked by validate()), naming
/// the key and the value otherwise.
std::uint64_t get_whole(const YAML::Node& n, const std::string& where, std::uint64_t hi) {
  if (n.IsScalar()) {
    const std::string& s = n.Scalar();
    errno = 0;
    char* end = nullptr;
    const unsigned long long x = std::strtoull(s.c_str(), &end, 10);
    if (!s.empty() && std::isdigit(static_cast<unsigned char>(s[0])) && *end == '\0' && errno == 0 && x <= hi)
      return x;
  }
  throw InputError(where + ": expected a whole number (0 to " + std::to_string(hi) + "), got " +
                   (n.IsScalar() ? "'" + n.Scalar() + "'" : std::string("a list or mapping")));
}
bool get_bool(const YAML::Node& n, const std::string& where) {
  if (n.IsScalar()) {
    std::string s = n.Scalar();
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (s == "true" || s == "yes" || s == "on") return true;
    if (s == "false" || s == "no" || s == "off") return false;
  }
  throw InputError(where + ": expected true or false, got " +
                   (n.IsScalar() ? "'" + n.Scalar() + "'" : std::string("a list or mapping")));
}
std::string get_text(const YAML::Node& n, const std::string& where) {
  if (!n.IsScalar() || n.Scalar().empty())
    throw InputError(where + ": expected a name, got " +
                     (n.IsScalar() ? std::string("nothing") : std::string("a list or mapping")));
  return n.Scalar();
}
Vec3 get_vec(const YAML::Node& n, const std::string& where, HumanUnit u) {
  if (!n.IsSequence() || n.size() != 3) throw InputError(where + ": expected [x, y, z]");
  Vec3 v;
  for (int i = 0; i < 3; ++i) v[i] = get_double(n[i], where) * u.mul / u.div;
  return v;
}

struct ErrorKey {
  const char* key;
  double ErrorParams::*member;
  HumanUnit unit;
  /// false: written to scenario.yaml only when not 0, so that the files of the datasets made
  /// before the key existed stay the same.
  bool always_written = true;
};
const ErrorKey kErrorKeys[] = {
    {"gyro_bias_deg_h", &ErrorParams::gyro_bias, kDegH},
    {"gyro_gm_sigma_deg_h", &ErrorParams::gyro_gm_sigma, kDegH},
    {"gyro_gm_tau_s", &ErrorParams::gyro_gm_tau, kSi},
    {"gyro_arw_deg_sqrt_h", &ErrorParams::gyro_arw, kArw},
    {"gyro_sf_ppm", &ErrorParams::gyro_sf, kPpm},
    {"gyro_misalignment_deg", &ErrorParams::gyro_misalign, kDegU},
    {"gyro_lsb_deg_s", &ErrorParams::gyro_lsb, kDegU},
    {"gyro_range_deg_s", &ErrorParams::gyro_range, kDegU},
    {"gyro_tempco_deg_h_per_K", &ErrorParams::gyro_tempco, kDegH},
    {"accel_bias_m_s2", &ErrorParams::accel_bias, kSi},
    {"accel_gm_sigma_m_s2", &ErrorParams::accel_gm_sigma, kSi},
    {"accel_gm_tau_s", &ErrorParams::accel_gm_tau, kSi},
    {"accel_vrw_m_s_sqrt_h", &ErrorParams::accel_vrw, kVrw},
    {"accel_sf_ppm", &ErrorParams::accel_sf, kPpm},
    {"accel_misalignment_deg", &ErrorParams::accel_misalign, kDegU},
    {"accel_lsb_m_s2", &ErrorParams::accel_lsb, kSi},
    {"accel_range_m_s2", &ErrorParams::accel_range, kSi},
    {"accel_tempco_mg_per_K", &ErrorParams::accel_tempco, kMgPerK},
    {"temperature_rise_K", &ErrorParams::temp_rise, kSi},
    {"temperature_tau_s", &ErrorParams::temp_tau, kSi},
    {"radius_rel", &ErrorParams::radius_rel, kSi},
    {"slip_per_m_s2", &ErrorParams::slip_coeff, kSi},
    {"skid_s", &ErrorParams::skid_coeff, kSi},
    {"skid_deg_per_m_s2", &ErrorParams::skid_angle, kDegU, false},
    {"time_offset_s", &ErrorParams::time_offset, kSi},
    {"wheel_accel_noise_m_s_sqrt_h", &ErrorParams::wheel_accel_noise, kVrw},
    {"wheel_accel_noise_rest", &ErrorParams::wheel_accel_noise_rest, kSi},
    {"calibration_lever_arm_m", &ErrorParams::cal_lever_arm, kSi},
    {"calibration_mounting_deg", &ErrorParams::cal_mounting, kDegU},
    {"calibration_position_m", &ErrorParams::cal_position, kSi},
    {"calibration_radius_rel", &ErrorParams::cal_radius_rel, kSi},
};
struct ErrorVecKey {
  const char* key;
  Vec3 ErrorParams::*member;
  HumanUnit unit;
};
const ErrorVecKey kErrorVecKeys[] = {
    {"vibration_body_accel_rms_m_s2", &ErrorParams::vib_body_accel, kSi},
    {"vibration_body_rate_rms_deg_s", &ErrorParams::vib_body_rate, kDegU},
    {"vibration_wheel_accel_rms_m_s2", &ErrorParams::vib_wheel_accel, kSi},
    {"vibration_wheel_rate_rms_deg_s", &ErrorParams::vib_wheel_rate, kDegU},
};

void check_effect(const std::string& name) {
  for (const auto& e : all_effects())
    if (e == name) return;
  std::string list;
  for (const auto& e : all_effects()) list += (list.empty() ? "" : ", ") + e;
  throw InputError("unknown effect '" + name + "' (known: " + list + ")");
}

}  // namespace

std::set<std::string> profile_effects(const std::string& profile) {
  const auto& all = all_effects();
  if (profile == "ideal") return {};
  if (profile == "datasheet") return {all.begin(), all.begin() + 11};
  if (profile == "field") return {all.begin(), all.begin() + kFieldEffects};
  throw InputError("unknown profile '" + profile + "' (expected ideal, datasheet or field)");
}

VehicleConfig VehicleConfig::preset_named(const std::string& name) {
  VehicleConfig v;
  v.preset = name;
  v.left.group = "left-wheel";
  v.right.group = "right-wheel";
  v.body.group = "body";
  v.body.wheel = false;
  const bool steered = name == "car-steered";
  if (name == "robot") {
    // Pioneer 3DX-like: the Wheel-INS dataset's radius, lever arm and rate.
    v.wheel_radius = 0.097;
    v.track = 0.33;
    v.left.lever_arm_inB = Vec3(0.015, -0.004, 0.006);
    v.right.lever_arm_inB = Vec3(-0.015, 0.005, 0.005);
    v.left.mounting_rpy = Vec3(0.0, 0.6, -0.8) * kDeg;
    v.right.mounting_rpy = Vec3(0.0, -0.5, 0.4) * kDeg;
    v.body.p_inV = Vec3(0.12, 0.03, -0.22);
    v.body.mounting_rpy = Vec3(0.4, -0.6, 1.2) * kDeg;
  } else if (name == "car" || steered) {
    v.wheel_radius = 0.35;
    v.track = 1.6;
    v.left.lever_arm_inB = Vec3(0.02, 0.004, -0.003);
    v.right.lever_arm_inB = Vec3(-0.02, -0.003, 0.004);
    v.left.mounting_rpy = Vec3(0.0, 0.5, -0.7) * kDeg;
    v.right.mounting_rpy = Vec3(0.0, -0.6, 0.3) * kDeg;
    v.body.p_inV = Vec3(1.3, 0.1, -0.5);
    v.body.mounting_rpy = Vec3(0.5, -0.3, 0.8) * kDeg;
  } else {
    throw InputError("unknown vehicle preset '" + name + "' (expected robot, car or car-steered)");
  }
  v.left.p_inV = Vec3(0.0, -0.5 * v.track, 0.0);
  v.right.p_inV = Vec3(0.0, 0.5 * v.track, 0.0);
  if (steered) {
    // The car with two Wheel-IMUs on its steered front wheels, the same chips as the rear ones.
    v.wheelbase = 2.6;
    ModuleGeometry fl, fr;
    fl.group = "front-left-wheel";
    fr.group = "front-right-wheel";
    fl.steered = fr.steered = true;
    fl.lever_arm_inB = Vec3(0.02, -0.003, 0.004);
    fr.lever_arm_inB = Vec3(-0.02, 0.004, -0.003);
    fl.mounting_rpy = Vec3(0.0, 0.4, -0.6) * kDeg;
    fr.mounting_rpy = Vec3(0.0, -0.5, 0.5) * kDeg;
    fl.p_inV = Vec3(v.wheelbase, -0.5 * v.track, 0.0);
    fr.p_inV = Vec3(v.wheelbase, 0.5 * v.track, 0.0);
    v.front = {fl, fr};
  }
  return v;
}

std::vector<const ModuleGeometry*> VehicleConfig::modules() const {
  std::vector<const ModuleGeometry*> r = {&left, &right, &body};
  for (const ModuleGeometry& f : front) r.push_back(&f);
  return r;
}

std::vector<ModuleGeometry*> VehicleConfig::mutable_modules() {
  std::vector<ModuleGeometry*> r = {&left, &right, &body};
  for (ModuleGeometry& f : front) r.push_back(&f);
  return r;
}

ErrorParams profile_errors(const std::string& profile) {
  profile_effects(profile);  // the name checked
  ErrorParams e;
  if (profile == "field") e.gyro_sf = 3000e-6;
  return e;
}

void SimConfig::set_profile(const std::string& name) {
  effects = profile_effects(name);
  profile = name;
  errors = profile_errors(name);
}

void SimConfig::disable(const std::vector<std::string>& names) {
  for (const auto& n : names) {
    check_effect(n);
    effects.erase(n);
  }
}

void SimConfig::only(const std::vector<std::string>& names) {
  effects.clear();
  for (const auto& n : names) {
    check_effect(n);
    effects.insert(n);
  }
}

void SimConfig::apply_yaml(const YAML::Node& node, const std::string& where, const KeyOrigin& key_origin) {
  if (!node.IsMap()) throw InputError(where + ": expected a map of settings");
  static const std::set<std::string> known = {
      "seed", "profile", "effects", "scenario", "speed_file", "duration_s", "rate_hz", "chips",
      "gps_week", "earth_rotation", "start_time_s", "origin", "static_s", "laps", "speed_m_s",
      "stops", "stop_s", "loop_scale", "path_sigma_m", "speed_sigma_s", "terrain_slope_deg", "start_steering_deg",
      "vehicle", "errors", "faults", "draws_from"};
  auto key = [&](const std::string& k) { return where + ": " + k + (key_origin ? key_origin(k) : std::string()); };
  for (const auto& kv : node) {
    const auto k = get_text(kv.first, where + ": a key");
    if (!known.count(k)) throw InputError(key(k) + ": unknown key '" + k + "'");
  }
  try {
    // Profile and preset first: they reset what they own.
    if (node["profile"]) set_profile(get_text(node["profile"], key("profile")));
    if (node["vehicle"] && node["vehicle"]["preset"])
      vehicle = VehicleConfig::preset_named(get_text(node["vehicle"]["preset"], key("vehicle.preset")));
    if (node["effects"]) {
      std::vector<std::string> list;
      for (const auto& e : node["effects"]) list.push_back(get_text(e, key("effects")));
      only(list);
    }
    if (node["seed"]) seed = get_whole(node["seed"], key("seed"), std::numeric_limits<std::uint64_t>::max());
    if (node["scenario"]) scenario = get_text(node["scenario"], key("scenario"));
    if (node["speed_file"]) {
      if (node["speed_file"].IsNull()) speed_file.reset();
      else speed_file = get_text(node["speed_file"], key("speed_file"));
    }
    if (node["duration_s"]) {
      if (node["duration_s"].IsNull()) duration.reset();
      else duration = get_double(node["duration_s"], key("duration_s"));
    }
    if (node["rate_hz"]) rate_hz = get_double(node["rate_hz"], key("rate_hz"));
    if (node["chips"]) chips = static_cast<int>(get_whole(node["chips"], key("chips"), 1000000));
    if (node["gps_week"]) gps_week = get_double(node["gps_week"], key("gps_week"));
    if (node["earth_rotation"]) earth_rotation = get_bool(node["earth_rotation"], key("earth_rotation"));
    if (node["start_time_s"]) {
      if (node["start_time_s"].IsNull()) start_time.reset();
      else start_time = get_double(node["start_time_s"], key("start_time_s"));
    }
    if (node["origin"]) {
      const auto& o = node["origin"];
      if (o.IsNull()) {
        origin.reset();
      } else {
        earth::Geodetic g;
        g.lat = get_double(o["lat_deg"], key("origin.lat_deg")) * kDeg;
        g.lon = get_double(o["lon_deg"], key("origin.lon_deg")) * kDeg;
        g.h = o["h_m"] ? get_double(o["h_m"], key("origin.h_m")) : 0.0;
        origin = g;
      }
    }
    if (node["static_s"]) static_duration = get_double(node["static_s"], key("static_s"));
    if (node["laps"]) laps = static_cast<int>(get_whole(node["laps"], key("laps"), 1000000));
    if (node["stops"]) stops = get_bool(node["stops"], key("stops"));
    if (node["stop_s"]) stop_s = get_double(node["stop_s"], key("stop_s"));
    auto opt_double = [&](const char* k, std::optional<double>& dst) {
      if (!node[k]) return;
      if (node[k].IsNull()) dst.reset();
      else dst = get_double(node[k], key(k));
    };
    opt_double("speed_m_s", speed);
    opt_double("loop_scale", loop_scale);
    opt_double("path_sigma_m", path_sigma);
    opt_double("speed_sigma_s", speed_sigma);
    if (node["terrain_slope_deg"])
      terrain_slope_deg = get_double(node["terrain_slope_deg"], key("terrain_slope_deg"));
    if (node["start_steering_deg"])
      start_steering_deg = get_double(node["start_steering_deg"], key("start_steering_deg"));
    if (const auto& v = node["vehicle"]) {
      static const std::set<std::string> vk = {"preset", "wheel_radius_m", "track_m", "wheelbase_m",
                                               "left-wheel", "right-wheel", "body", "front-left-wheel",
                                               "front-right-wheel"};
      for (const auto& kv : v)
        if (!vk.count(get_text(kv.first, key("vehicle"))))
          throw InputError(key("vehicle") + ": unknown key '" + kv.first.Scalar() + "'");
      for (const char* f : {"front-left-wheel", "front-right-wheel"})
        if (v[f] && vehicle.front.empty())
          throw InputError(key(std::string("vehicle.") + f) + ": the vehicle preset '" + vehicle.preset +
                           "' has no such module (preset car-steered has)");
      if (v["wheel_radius_m"]) vehicle.wheel_radius = get_double(v["wheel_radius_m"], key("vehicle.wheel_radius_m"));
      if (v["track_m"]) {
        vehicle.track = get_double(v["track_m"], key("vehicle.track_m"));
        vehicle.left.p_inV.y() = -0.5 * vehicle.track;
        vehicle.right.p_inV.y() = 0.5 * vehicle.track;
        for (ModuleGeometry& f : vehicle.front) f.p_inV.y() = (f.p_inV.y() < 0.0 ? -0.5 : 0.5) * vehicle.track;
      }
      if (v["wheelbase_m"]) {
        vehicle.wheelbase = get_double(v["wheelbase_m"], key("vehicle.wheelbase_m"));
        for (ModuleGeometry& f : vehicle.front) f.p_inV.x() = vehicle.wheelbase;
      }
      for (ModuleGeometry* m : vehicle.mutable_modules()) {
        const auto& mn = v[m->group];
        if (!mn) continue;
        const std::string w = key("vehicle." + m->group);
        for (const auto& kv : mn) {
          const auto k = get_text(kv.first, w);
          if (k != "position_m" && k != "mounting_deg" && !(m->wheel && k == "lever_arm_m"))
            throw InputError(w + ": unknown key '" + k + "'");
        }
        if (mn["position_m"]) m->p_inV = get_vec(mn["position_m"], w + ".position_m", kSi);
        if (mn["lever_arm_m"]) m->lever_arm_inB = get_vec(mn["lever_arm_m"], w + ".lever_arm_m", kSi);
        if (mn["mounting_deg"]) m->mounting_rpy = get_vec(mn["mounting_deg"], w + ".mounting_deg", kDegU);
      }
    }
    if (const auto& e = node["errors"]) {
      for (const auto& kv : e) {
        const auto k = get_text(kv.first, key("errors"));
        bool found = false;
        for (const auto& ek : kErrorKeys)
          if (k == ek.key) {
            errors.*ek.member = get_double(kv.second, key("errors." + k)) * ek.unit.mul / ek.unit.div;
            found = true;
          }
        for (const auto& ek : kErrorVecKeys)
          if (k == ek.key) {
            errors.*ek.member = get_vec(kv.second, key("errors." + k), ek.unit);
            found = true;
          }
        if (k == "vibration_body_band_hz" || k == "vibration_wheel_band_hz") {
          double* band = k == "vibration_body_band_hz" ? errors.vib_body_band : errors.vib_wheel_band;
          if (!kv.second.IsSequence() || kv.second.size() != 2)
            throw InputError(key("errors." + k) + ": expected [low, high]");
          band[0] = get_double(kv.second[0], key("errors." + k));
          band[1] = get_double(kv.second[1], key("errors." + k));
          found = true;
        }
        if (!found) throw InputError(key("errors") + ": unknown key '" + k + "'");
      }
    }
    if (const auto& f = node["faults"]) {
      // The list replaces the current one (null or [] clears it); entries are maps or
      // `--fault` spec strings.
      if (!f.IsNull() && !f.IsSequence())
        throw InputError(key("faults") + ": expected a list of fault events");
      std::vector<FaultEvent> list;
      for (std::size_t i = 0; i < f.size(); ++i)
        list.push_back(fault_from_yaml(f[i], key("faults[" + std::to_string(i) + "]")));
      faults = std::move(list);
    }
    if (const auto& c = node["draws_from"]) {
      // Entries are set one by one (null removes one, a null map clears them all), so that
      // --set draws_from.GROUP=OTHER adds to a file's map.
      if (c.IsNull()) draws_from.clear();
      else if (!c.IsMap()) throw InputError(key("draws_from") + ": expected a map {module: module}");
      for (const auto& kv : c) {
        const std::string g = get_text(kv.first, key("draws_from"));
        if (kv.second.IsNull()) draws_from.erase(g);
        else draws_from[g] = get_text(kv.second, key("draws_from." + g));
      }
    }
  } catch (const YAML::Exception& ex) {
    throw InputError(where + ": " + ex.what());
  }
  // The ranges are checked once every setting is in (validate()): a check here would judge
  // the settings given so far and blame this YAML (or --set) for another option's value.
}

void SimConfig::validate() const {
  auto check = [](double x, double lo, double hi, const char* key, const char* option,
                  const char* unit, bool lo_open = false) {
    if (std::isfinite(x) && x <= hi && (lo_open ? x > lo : x >= lo)) return;
    char range[160];
    std::snprintf(range, sizeof range, ": must be in %s%g, %g]%s%s, got %g", lo_open ? "(" : "[", lo, hi,
                  *unit ? " " : "", unit, x);
    throw InputError(std::string("simulator setting ") + key +
                     (*option ? std::string(" (") + option + ")" : std::string()) + range);
  };
  check(rate_hz, 20.0, 10000.0, "rate_hz", "--rate", "Hz");
  check(chips, 1, 16, "chips", "--chips", "chips per module");
  check(laps, 1, 1000, "laps", "--laps", "");
  if (duration) check(*duration, 0.0, 86400.0, "duration_s", "--duration", "s", true);
  if (speed) check(*speed, 0.05, 60.0, "speed_m_s", "--cruise-speed", "m/s");
  check(static_duration, 0.0, 3600.0, "static_s", "--static", "s");
  check(stop_s, 1.0, 86400.0, "stop_s", "", "s");
  check(terrain_slope_deg, 0.0, 30.0, "terrain_slope_deg", "--terrain", "deg");
  check(vehicle.wheel_radius, 0.01, 2.0, "vehicle.wheel_radius_m", "--radius", "m");
  check(vehicle.track, 0.05, 10.0, "vehicle.track_m", "--track", "m");
  // A steered wheel is ahead of the rear axle: the vehicle needs a wheelbase (0: none stated).
  if (!vehicle.front.empty() || vehicle.wheelbase != 0.0)
    check(vehicle.wheelbase, 0.5, 20.0, "vehicle.wheelbase_m", "", "m");
  for (const ModuleGeometry& f : vehicle.front)
    if (!(f.p_inV.x() >= 0.5))
      throw InputError("simulator setting vehicle." + f.group +
                       ".position_m: a steered wheel's x is its distance ahead of the rear axle (o): "
                       "at least 0.5 m, got " + human(f.p_inV.x(), kSi));
  check(start_steering_deg, -40.0, 40.0, "start_steering_deg", "--start-steering-deg", "deg");
  if (start_steering_deg != 0.0 && !(vehicle.wheelbase > 0.0))
    throw InputError("simulator setting start_steering_deg (--start-steering-deg): the arc's curvature is "
                     "tan(angle) / wheelbase: needs vehicle.wheelbase_m (preset car-steered, or --set "
                     "vehicle.wheelbase_m=M)");
  if (start_steering_deg != 0.0 && scenario != "default")
    throw InputError("simulator setting start_steering_deg (--start-steering-deg): only with the default "
                     "scenario, not '" + scenario + "'");
  if (loop_scale) check(*loop_scale, 0.01, 100.0, "loop_scale", "", "");
  if (path_sigma) check(*path_sigma, 0.0, 100.0, "path_sigma_m", "", "m");
  if (speed_sigma) check(*speed_sigma, 0.0, 100.0, "speed_sigma_s", "", "s");
  if (start_time) check(*start_time, 0.0, 1e9, "start_time_s", "", "s");
  check(gps_week, 0.0, 1e5, "gps_week", "", "");
  for (const auto& k : kErrorKeys) {
    const double x = errors.*k.member * k.unit.div / k.unit.mul;  // in the key's unit, as given
    const std::string name = std::string("errors.") + k.key;
    // Full scales, time constants and the wheel's rolling noise factor need a positive value.
    const bool positive = name.find("range") != std::string::npos || name.find("tau") != std::string::npos;
    check(x, 0.0, 1e9, name.c_str(), "", "", positive);
  }
  for (const auto& k : kErrorVecKeys)
    for (int i = 0; i < 3; ++i)
      check((errors.*k.member)[i] * k.unit.div / k.unit.mul, 0.0, 1e9, (std::string("errors.") + k.key).c_str(), "",
            "");
  for (const double* band : {errors.vib_body_band, errors.vib_wheel_band})
    if (!(band[0] > 0.0 && band[1] > band[0] && band[1] <= 1e5))
      throw InputError("simulator setting errors.vibration_*_band_hz: expected 0 < low < high, got [" +
                       std::to_string(band[0]) + ", " + std::to_string(band[1]) + "]");
  check(errors.wheel_accel_noise_rest, 0.0, 1.0, "errors.wheel_accel_noise_rest", "", "");
  // What the dataset's manifest will say must be what `run` accepts (ManifestLimits): the
  // full scales when they are simulated, and the geometry with room for the installation
  // calibration error drawn on it (5 sigma).
  if (on("saturation")) {
    check(errors.gyro_range / kDeg, ManifestLimits::kGyroRangeMinDps, ManifestLimits::kGyroRangeMaxDps,
          "errors.gyro_range_deg_s", "", "deg/s (a manifest's gyro_range_dps)");
  }
  const int rate_samples = static_cast<int>(std::floor(static_duration * rate_hz + 1e-9));
  if (rate_samples < kMinStaticSamples)
    throw InputError("simulator setting static_s (--static): " + human(static_duration, kSi) +
                     " s at " + human(rate_hz, kSi) + " Hz gives " + std::to_string(rate_samples) +
                     " samples at rest; the initial alignment of `wheelins run` needs at least " +
                     std::to_string(kMinStaticSamples) + " (at least " +
                     human(kMinStaticSamples / rate_hz, kSi) + " s)");
  check_draws_from();
  for (const ModuleGeometry* g : vehicle.modules()) {
    const double pos_room = ManifestLimits::kPositionM - 5.0 * errors.cal_position;
    const double arm_room = ManifestLimits::kWheelLeverArmM - 5.0 * errors.cal_lever_arm;
    for (int i = 0; i < 3; ++i) {
      if (!(std::abs(g->p_inV[i]) <= pos_room))
        throw InputError("simulator setting vehicle." + g->group + ".position_m: " + human(g->p_inV[i], kSi) +
                         " m on axis " + std::to_string(i) + "; a manifest's position_v_m is at most " +
                         human(ManifestLimits::kPositionM, kSi) + " m per axis (" + human(pos_room, kSi) +
                         " m leaves room for errors.calibration_position_m)");
      if (g->wheel && !(std::abs(g->lever_arm_inB[i]) <= arm_room))
        throw InputError("simulator setting vehicle." + g->group + ".lever_arm_m: " +
                         human(g->lever_arm_inB[i], kSi) + " m on axis " + std::to_string(i) +
                         "; a wheel's lever_arm_b_m in a manifest is at most " +
                         human(ManifestLimits::kWheelLeverArmM, kSi) + " m per axis (" + human(arm_room, kSi) +
                         " m leaves room for errors.calibration_lever_arm_m)");
    }
  }
}

void SimConfig::check_draws_from() const {
  std::string groups;
  for (const ModuleGeometry* g : vehicle.modules()) groups += (groups.empty() ? "" : ", ") + g->group;
  auto find = [&](const std::string& n) -> const ModuleGeometry* {
    for (const ModuleGeometry* g : vehicle.modules())
      if (g->group == n) return g;
    return nullptr;
  };
  for (const auto& [to, from] : draws_from) {
    const std::string k = "simulator setting draws_from." + to + ": ";
    if (!find(to))
      throw InputError(k + "'" + to + "' is not a module of the vehicle preset '" + vehicle.preset + "' (" +
                       groups + ")");
    if (!find(from))
      throw InputError(k + "'" + from + "' is not a module of the vehicle preset '" + vehicle.preset + "' (" +
                       groups + ")");
    if (from == to) throw InputError(k + "a module's draws are its own already");
    if (find(from)->wheel != find(to)->wheel)
      throw InputError(k + "'" + from + "' is " + (find(from)->wheel ? "a wheel" : "not a wheel") + ", '" + to +
                       "' is " + (find(to)->wheel ? "one" : "not"));
  }
  for (const auto& [to, from] : draws_from) {
    const std::string k = "simulator setting draws_from." + to + ": ";
    if (draws_from.count(from))
      throw InputError(k + "'" + from + "' takes another module's draws itself (" +
                       draws_from.at(from) + "'s): name that module");
  }
}

void SimConfig::apply_setting(const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("--set '" + assignment + "': expected key.path=value");
  const std::string path = assignment.substr(0, eq);
  const YAML::Node value = parse_yaml(assignment.substr(eq + 1), "--set '" + assignment + "'", "setting");
  // Build {a: {b: {c: value}}}.
  const std::vector<std::string> parts = dotted_key_parts(path);
  YAML::Node node = value;
  for (auto it = parts.rbegin(); it != parts.rend(); ++it) {
    YAML::Node m(YAML::NodeType::Map);
    m[*it] = node;
    node = m;
  }
  apply_yaml(node, "--set " + path);
}

std::string SimConfig::to_yaml() const {
  std::ostringstream o;
  o << "# wheelins simulate: every setting of this dataset. Reproduce it with\n"
       "#   wheelins simulate --config scenario.yaml --out DIR\n"
       "# (relative paths are as given on the command line). Units in the key names.\n";
  o << "seed: " << seed << "\n";
  o << "profile: " << profile << "\n";
  o << "effects: [";
  bool first = true;
  for (const auto& e : all_effects())
    if (effects.count(e)) {
      o << (first ? "" : ", ") << e;
      first = false;
    }
  o << "]\n";
  o << "scenario: \"" << scenario << "\"\n";
  o << "speed_file: " << (speed_file ? "\"" + speed_file->string() + "\"" : std::string("null")) << "\n";
  o << "duration_s: " << (duration ? human(*duration, kSi) : std::string("null")) << "\n";
  o << "rate_hz: " << human(rate_hz, kSi) << "\n";
  o << "chips: " << chips << "\n";
  o << "gps_week: " << human(gps_week, kSi) << "\n";
  o << "earth_rotation: " << (earth_rotation ? "true" : "false") << "\n";
  o << "start_time_s: " << (start_time ? human(*start_time, kSi) : std::string("null")) << "\n";
  if (origin)
    o << "origin: {lat_deg: " << human(origin->lat, kDegU) << ", lon_deg: " << human(origin->lon, kDegU)
      << ", h_m: " << human(origin->h, kSi) << "}\n";
  else
    o << "origin: null\n";
  o << "static_s: " << human(static_duration, kSi) << "\n";
  o << "laps: " << laps << "\n";
  auto opt_text = [](const std::optional<double>& v) { return v ? human(*v, kSi) : std::string("null"); };
  o << "speed_m_s: " << opt_text(speed) << "\n";
  o << "loop_scale: " << opt_text(loop_scale) << "\n";
  o << "stops: " << (stops ? "true" : "false") << "\n";
  if (stop_s != 15.0) o << "stop_s: " << human(stop_s, kSi) << "\n";
  o << "path_sigma_m: " << (path_sigma ? human(*path_sigma, kSi) : std::string("null")) << "\n";
  o << "speed_sigma_s: " << (speed_sigma ? human(*speed_sigma, kSi) : std::string("null")) << "\n";
  o << "terrain_slope_deg: " << human(terrain_slope_deg, kSi) << "\n";
  if (start_steering_deg != 0.0) o << "start_steering_deg: " << human(start_steering_deg, kSi) << "\n";
  o << "vehicle:\n";
  o << "  preset: " << vehicle.preset << "\n";
  o << "  wheel_radius_m: " << human(vehicle.wheel_radius, kSi) << "\n";
  o << "  track_m: " << human(vehicle.track, kSi) << "\n";
  if (vehicle.wheelbase != 0.0) o << "  wheelbase_m: " << human(vehicle.wheelbase, kSi) << "\n";
  for (const ModuleGeometry* m : vehicle.modules()) {
    o << "  " << m->group << ":\n";
    o << "    position_m: " << vec_text(m->p_inV, kSi) << "\n";
    if (m->wheel) o << "    lever_arm_m: " << vec_text(m->lever_arm_inB, kSi) << "\n";
    o << "    mounting_deg: " << vec_text(m->mounting_rpy, kDegU) << "\n";
  }
  o << "errors:\n";
  for (const auto& ek : kErrorKeys) {
    if (!ek.always_written && errors.*ek.member == 0.0) continue;
    o << "  " << ek.key << ": " << human(errors.*ek.member, ek.unit) << "\n";
  }
  for (const auto& ek : kErrorVecKeys) o << "  " << ek.key << ": " << vec_text(errors.*ek.member, ek.unit) << "\n";
  o << "  vibration_body_band_hz: [" << human(errors.vib_body_band[0], kSi) << ", "
    << human(errors.vib_body_band[1], kSi) << "]\n";
  o << "  vibration_wheel_band_hz: [" << human(errors.vib_wheel_band[0], kSi) << ", "
    << human(errors.vib_wheel_band[1], kSi) << "]\n";
  if (!draws_from.empty()) {
    o << "draws_from:  # module: the module whose draws (its own and its chips' errors) it takes\n";
    for (const auto& [to, from] : draws_from) o << "  " << to << ": " << from << "\n";
  }
  // Times in seconds since the start of the data; the bias step in deg/s (gyro) or m/s^2.
  if (faults.empty()) {
    o << "faults: []\n";
  } else {
    o << "faults:  # times in seconds since the start of the data (end_s: end = to the end)\n";
    for (const auto& f : faults) o << "  - " << f.yaml() << "\n";
  }
  return o.str();
}

}  // namespace wheelins::sim
