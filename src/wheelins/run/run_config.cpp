// Loading a run configuration (run_config.hpp) and turning it into a RunRequest.
#include "wheelins/run/run_config.hpp"

#include <cmath>

#include "wheelins/run/presets.hpp"
#include "wheelins/io/yaml_reader.hpp"

namespace wheelins {
namespace fs = std::filesystem;

namespace {
/// Ranges shared with the command line (app/cmd_run.cpp checks the same).
const std::vector<std::pair<std::string, YawScaleFactorChoice>> kYawChoices = {
    {"auto", YawScaleFactorChoice::kAuto},
    {"held", YawScaleFactorChoice::kHeld},
    {"constraint", YawScaleFactorChoice::kFromConstraint},
    {"estimated", YawScaleFactorChoice::kEstimated}};

YawScaleFactorChoice yaw_scale_factors_from(const YamlReader& y, const YAML::Node& v,
                                            const std::string& key) {
  return y.choice<YawScaleFactorChoice>(v, key, kYawChoices);
}

struct Ranges {
  double duration[2] = {0.0, 1e7};
  double output_interval[2] = {0.0, 5.0};
} const kRange;

/// A path of the configuration file: as given when absolute, else from the file's folder.
fs::path config_path(const fs::path& base, const std::string& p) {
  return fs::path(p).is_absolute() ? fs::path(p) : base / p;
}

/// The top-level keys: the data, the IMUs, how much of it and how it is checked.
void read_run_selection(const YamlReader& y, const YAML::Node& root, const fs::path& base, RunConfig& c) {
  c.manifest = config_path(base, y.text(y.required(root, "", "dataset"), "dataset"));
  if (auto v = y.get(root, "configuration"); v.IsDefined()) {
    c.configuration = y.text(v, "configuration");
    bool known = c.configuration == "single-right";
    for (const auto& n : configuration_names()) known = known || n == c.configuration;
    if (!known) y.fail("configuration", "unknown configuration '" + c.configuration + "'", &v);
  }
  if (auto v = y.get(root, "chips"); v.IsDefined()) c.chips = y.text_list(v, "chips");
  if (auto v = y.get(root, "modules"); v.IsDefined()) c.modules = y.text_list(v, "modules");
  if (auto v = y.get(root, "duration_s"); v.IsDefined()) {
    c.max_duration = y.number_in(v, "duration_s", kRange.duration[0], kRange.duration[1], "s");
    if (c.max_duration <= 0) y.fail("duration_s", "must be > 0 s (leave it out for all the data)", &v);
  }

  if (auto v = y.get(root, "data_checks"); v.IsDefined()) c.data_checks = y.boolean(v, "data_checks");
  if (auto v = y.get(root, "calibration"); v.IsDefined())
    c.calibration = y.choice<CalibrationMode>(
        v, "calibration", {{"estimate", CalibrationMode::kEstimate}, {"manifest", CalibrationMode::kManifest}});
}

void read_output(const YamlReader& y, const YAML::Node& out, const fs::path& base, RunConfig& c) {
  y.require_map(out, "output");
  y.check_keys(out, "output",
               {"dir", "file_interval_s", "formats", "interval_s", "overwrite", "subsystems", "tum_frame"});
  if (auto v = y.get(out, "dir"); v.IsDefined()) c.output_dir = config_path(base, y.text(v, "output.dir"));
  if (auto v = y.get(out, "formats"); v.IsDefined()) {
    c.formats.clear();
    for (const auto& f : y.text_list(v, "output.formats")) {
      if (f != "csv" && f != "tum" && f != "kml")
        y.fail("output.formats", "unknown format '" + f + "' (csv, tum or kml)", &v);
      c.formats.push_back(trajectory_format_from_name(f));
    }
  }
  if (auto v = y.get(out, "tum_frame"); v.IsDefined()) {
    const std::string f = y.text(v, "output.tum_frame");
    if (f != "ned" && f != "enu") y.fail("output.tum_frame", "'" + f + "': expected ned or enu", &v);
    c.tum_frame = tum_frame_from_name(f);
  }
  if (auto v = y.get(out, "interval_s"); v.IsDefined()) {
    c.nav.output_interval = y.number_in(v, "output.interval_s", kRange.output_interval[0],
                                        kRange.output_interval[1], "s (0 = every epoch)");
  }
  if (auto v = y.get(out, "file_interval_s"); v.IsDefined())
    c.file_interval = y.number_in(v, "output.file_interval_s", kRange.output_interval[0],
                                  kRange.output_interval[1], "s (0 = every record)");
  if (auto v = y.get(out, "overwrite"); v.IsDefined()) c.overwrite = y.boolean(v, "output.overwrite");
  if (auto v = y.get(out, "subsystems"); v.IsDefined())
    c.write_subsystems = y.boolean(v, "output.subsystems");
}

/// filter.yaw_scale_factors, or its older spelling filter.estimate_yaw_scale_factors.
void read_yaw_scale_factors(const YamlReader& y, const YAML::Node& f, NavigatorOptions& nav) {
  const YAML::Node yaw = y.get(f, "yaw_scale_factors");
  if (yaw.IsDefined())
    nav.yaw_scale_factors = yaw_scale_factors_from(y, yaw, "filter.yaw_scale_factors");
  if (auto v = y.get(f, "estimate_yaw_scale_factors"); v.IsDefined()) {
    // The older spelling: true = estimated, false = held.
    if (yaw.IsDefined())
      y.fail("filter.estimate_yaw_scale_factors",
             "conflicts with filter.yaw_scale_factors (give only the latter)", &v);
    nav.yaw_scale_factors = y.boolean(v, "filter.estimate_yaw_scale_factors")
                                ? YawScaleFactorChoice::kEstimated
                                : YawScaleFactorChoice::kHeld;
  }
}

/// A velocity sigma per axis, filter.<key>.
void read_velocity_std(const YamlReader& y, const YAML::Node& f, const char* key, Vec3& out) {
  if (auto v = y.get(f, key); v.IsDefined()) {
    const std::string path = std::string("filter.") + key;
    out = y.vec3(v, path);
    for (int i = 0; i < 3; ++i)
      y.range(out[i], 1e-4, 10.0, YamlReader::index_path(path, static_cast<std::size_t>(i)), v, "m/s");
  }
}

void read_initial_std(const YamlReader& y, const YAML::Node& s, NavigatorOptions& nav) {
  y.require_map(s, "filter.initial_std");
  y.check_keys(s, "filter.initial_std",
               {"position_m", "velocity_m_s", "roll_pitch_deg", "heading_deg"});
  InitialUncertainty& u = nav.wheel.init;
  auto one = [&](const char* key, double& out, double factor, double lo, double hi,
                 const char* unit) {
    if (auto v = y.get(s, key); v.IsDefined()) {
      const std::string path = std::string("filter.initial_std.") + key;
      out = y.number_in(v, path, lo, hi, unit) * factor;
    }
  };
  one("position_m", u.position, 1.0, 1e-4, 1000.0, "m");
  one("velocity_m_s", u.velocity, 1.0, 1e-4, 100.0, "m/s");
  one("roll_pitch_deg", u.roll_pitch, kDeg, 1e-3, 90.0, "deg");
  one("heading_deg", u.heading, kDeg, 1e-3, 180.0, "deg");
  nav.body.init = u;
}

void read_filter(const YamlReader& y, const YAML::Node& f, RunConfig& c) {
  y.require_map(f, "filter");
  y.check_keys(f, "filter",
               {"mechanization", "earth_rotation", "velocity_update_hz", "velocity_average", "speed_window_s",
                "wheel_velocity_std_m_s", "body_velocity_std_m_s", "velocity_gate",
                "initial_std", "covariance_interval_s", "yaw_scale_factors",
                "estimate_yaw_scale_factors", "estimate_axle_accel_scale_factors"});
  if (auto v = y.get(f, "estimate_axle_accel_scale_factors"); v.IsDefined())
    c.nav.wheel.estimate_axle_accel_scale_factor =
        y.boolean(v, "filter.estimate_axle_accel_scale_factors");
  read_yaw_scale_factors(y, f, c.nav);
  if (auto v = y.get(f, "mechanization"); v.IsDefined())
    c.nav.mechanization = y.choice<MechanizationOptions::Method>(
        v, "filter.mechanization",
        {{"rotation-exact", MechanizationOptions::Method::kRotationExact},
         {"classic", MechanizationOptions::Method::kClassicTwoSample}});
  if (auto v = y.get(f, "earth_rotation"); v.IsDefined())
    c.earth_rotation = y.choice<std::string>(v, "filter.earth_rotation",
                                             {{"auto", "auto"}, {"true", "true"}, {"false", "false"}});
  if (auto v = y.get(f, "covariance_interval_s"); v.IsDefined()) {
    // NavigatorOptions' range, checked here to name the key and its line.
    c.nav.covariance_interval =
        y.number_in(v, "filter.covariance_interval_s", 0.0,
                    NavigatorOptions::kMaxCovarianceInterval, "s (0 = every epoch)");
  }
  if (auto v = y.get(f, "velocity_update_hz"); v.IsDefined()) {
    const double hz = y.number_in(v, "filter.velocity_update_hz", 0.05, 100.0, "Hz");
    c.nav.wheel.velocity_update_interval = 1.0 / hz;
  }
  if (auto v = y.get(f, "velocity_average"); v.IsDefined())
    c.nav.wheel.turn_average = y.choice<bool>(v, "filter.velocity_average",
                                              {{"whole-turns", true}, {"none", false}});
  if (auto v = y.get(f, "speed_window_s"); v.IsDefined()) {
    c.nav.wheel.speed_window = y.number_in(v, "filter.speed_window_s", 0.001, 2.0, "s");
  }
  read_velocity_std(y, f, "wheel_velocity_std_m_s", c.nav.wheel.velocity_std);
  read_velocity_std(y, f, "body_velocity_std_m_s", c.nav.body.velocity_std);
  if (auto v = y.get(f, "velocity_gate"); v.IsDefined()) {
    c.nav.wheel.gate = c.nav.body.gate =
        y.number_in(v, "filter.velocity_gate", 0.0, 1e4, "(test ratio; 0 = off)");
  }
  if (auto s = y.get(f, "initial_std"); s.IsDefined()) read_initial_std(y, s, c.nav);
}

/// fusion.weights: a name, or a list of one positive weight per module.
void read_fusion_weights(const YamlReader& y, const YAML::Node& v, FusionOptions& o) {
  if (v.IsScalar()) {
    // equal (the paper) | covariance (from each subsystem's uncertainty) | a list.
    if (v.Scalar() != "equal" && v.Scalar() != "covariance" && v.Scalar() != "standalone")
      y.fail("fusion.weights",
             "expected equal, covariance or standalone (or a list of one positive weight per "
             "module), got " +
                 YamlReader::describe(v),
             &v);
    o.weighting = weighting_from_name(v.Scalar());
  } else {
    o.weights = y.number_list(v, "fusion.weights");
    if (o.weights.empty()) y.fail("fusion.weights", "an empty list (leave it out for equal weights)", &v);
    for (std::size_t i = 0; i < o.weights.size(); ++i)
      if (!(o.weights[i] > 0.0) || o.weights[i] > 1e6)
        y.fail(YamlReader::index_path("fusion.weights", i),
               "must be in (0, 1e6], got " + std::to_string(o.weights[i]) +
                   " (every module of the run needs a positive weight; leave a module out of "
                   "the configuration instead of giving it weight 0)",
               &v);
  }
}

void read_fusion(const YamlReader& y, const YAML::Node& f, FusionOptions& o) {
  y.require_map(f, "fusion");
  y.check_keys(f, "fusion", {"speed", "share_level", "position_constraint", "position_update_hz",
                             "position_std_m", "position_gate", "weights", "weight_window_epochs",
                             "centralized"});
  if (auto v = y.get(f, "speed"); v.IsDefined())
    o.speed = y.choice<SpeedSharing>(v, "fusion.speed",
                                     {{"mean", SpeedSharing::kMean}, {"own", SpeedSharing::kOwn}});
  if (auto v = y.get(f, "share_level"); v.IsDefined()) o.share_level = y.boolean(v, "fusion.share_level");
  if (auto v = y.get(f, "position_constraint"); v.IsDefined())
    o.position_constraint = y.boolean(v, "fusion.position_constraint");
  if (auto v = y.get(f, "position_update_hz"); v.IsDefined()) {
    const double hz = y.number_in(v, "fusion.position_update_hz", 0.01, 100.0, "Hz");
    o.position_update_interval = 1.0 / hz;
  }
  if (auto v = y.get(f, "position_std_m"); v.IsDefined()) {
    o.position_std = y.number_in(v, "fusion.position_std_m", 1e-3, 100.0, "m");
  }
  if (auto v = y.get(f, "position_gate"); v.IsDefined()) {
    o.position_gate = y.number_in(v, "fusion.position_gate", 0.0, 1e4, "(test ratio; 0 = off)");
  }
  if (auto v = y.get(f, "weights"); v.IsDefined()) read_fusion_weights(y, v, o);
  if (auto v = y.get(f, "weight_window_epochs"); v.IsDefined())
    o.weight_window = y.number_in(v, "fusion.weight_window_epochs", 1.0, 1e6, "constraint epochs");
  if (auto v = y.get(f, "centralized"); v.IsDefined()) o.centralized = y.boolean(v, "fusion.centralized");
}

/// The noise identification (docs/filter.md section 13, docs/run-config.md).
void read_noise(const YamlReader& y, const YAML::Node& f, NoiseAdaptationOptions& o) {
  y.require_map(f, "noise");
  y.check_keys(f, "noise", {"adapt", "window_updates", "min_velocity_std_fraction", "max_vrw_m_s_sqrt_h",
                            "min_speed_m_s", "settle_s", "min_gyro_bias_deg_h"});
  if (auto v = y.get(f, "adapt"); v.IsDefined()) o.enabled = y.boolean(v, "noise.adapt");
  if (auto v = y.get(f, "window_updates"); v.IsDefined())
    o.window = y.number_in(v, "noise.window_updates", 5.0, 1e5, "velocity updates");
  if (auto v = y.get(f, "min_velocity_std_fraction"); v.IsDefined())
    o.r_floor_fraction = y.number_in(v, "noise.min_velocity_std_fraction", 0.01, 1.0, "(of the given sigma)");
  if (auto v = y.get(f, "max_vrw_m_s_sqrt_h"); v.IsDefined())
    o.vrw_max = y.number_in(v, "noise.max_vrw_m_s_sqrt_h", 0.01, 1000.0, "m/s/sqrt(h)") / 60.0;
  if (auto v = y.get(f, "min_speed_m_s"); v.IsDefined())
    o.min_speed = y.number_in(v, "noise.min_speed_m_s", 0.0, 100.0, "m/s");
  if (auto v = y.get(f, "settle_s"); v.IsDefined())
    o.settle = y.number_in(v, "noise.settle_s", 0.0, 3600.0, "s");
  if (auto v = y.get(f, "min_gyro_bias_deg_h"); v.IsDefined())
    o.bias_floor = y.number_in(v, "noise.min_gyro_bias_deg_h", 0.0, 1e4, "deg/h") * kDeg / 3600.0;
}

/// Zero-velocity detection while standing (docs/faults.md, "Standing still").
void read_standstill(const YamlReader& y, const YAML::Node& f, StandstillOptions& o) {
  y.require_map(f, "standstill");
  y.check_keys(f, "standstill", {"enabled", "max_rate_deg_s", "max_force_spread_m_s2", "block_s", "min_time_s",
                                 "velocity_std_m_s", "rate_std_deg_s"});
  if (auto v = y.get(f, "enabled"); v.IsDefined()) o.enabled = y.boolean(v, "standstill.enabled");
  if (auto v = y.get(f, "max_rate_deg_s"); v.IsDefined())
    o.max_rate = y.number_in(v, "standstill.max_rate_deg_s", 0.001, 100.0, "deg/s") * kDeg;
  if (auto v = y.get(f, "max_force_spread_m_s2"); v.IsDefined())
    o.max_force_spread = y.number_in(v, "standstill.max_force_spread_m_s2", 0.001, 100.0, "m/s^2");
  if (auto v = y.get(f, "block_s"); v.IsDefined()) o.block = y.number_in(v, "standstill.block_s", 0.001, 10.0, "s");
  if (auto v = y.get(f, "min_time_s"); v.IsDefined())
    o.min_time = y.number_in(v, "standstill.min_time_s", 0.01, 3600.0, "s");
  if (auto v = y.get(f, "velocity_std_m_s"); v.IsDefined())
    o.velocity_std = y.number_in(v, "standstill.velocity_std_m_s", 1e-6, 10.0, "m/s");
  if (auto v = y.get(f, "rate_std_deg_s"); v.IsDefined())
    o.rate_std = y.number_in(v, "standstill.rate_std_deg_s", 1e-6, 100.0, "deg/s") * kDeg;
  try {
    o.validate();
  } catch (const InputError& e) {
    y.fail("standstill", e.what(), &f);
  }
}

void read_faults(const YamlReader& y, const YAML::Node& f, FaultOptions& o) {
  y.require_map(f, "faults");
  struct Key {
    const char* name;
    double FaultOptions::*member;
    double unit;
    double lo, hi;
    const char* unit_name;
  };
  static const Key kKeys[] = {
      {"stale_after_s", &FaultOptions::stale_after, 1.0, 0.001, 60.0, "s"},
      {"max_gap_s", &FaultOptions::max_gap, 1.0, 0.001, 60.0, "s"},
      {"realign_s", &FaultOptions::realign_time, 1.0, 0.01, 60.0, "s"},
      {"probation_s", &FaultOptions::probation, 1.0, 0.01, 3600.0, "s"},
      {"retry_after_s", &FaultOptions::retry_after, 1.0, 0.01, 3600.0, "s"},
      {"speed_gate_sigma", &FaultOptions::speed_gate, 1.0, 0.1, 1e4, "sigma"},
      {"wheel_mismatch_m_s", &FaultOptions::wheel_mismatch, 1.0, 1e-3, 100.0, "m/s"},
      {"test_ratio", &FaultOptions::test_ratio, 1.0, 0.1, 1e6, ""},
      {"heading_gate_deg", &FaultOptions::heading_gate, kDeg, 0.01, 180.0, "deg"},
      {"saturation_margin", &FaultOptions::saturation_margin, 1.0, 0.5, 1.0, "(of the full scale)"},
      {"saturation_hold_s", &FaultOptions::saturation_hold, 1.0, 0.001, 60.0, "s"},
      {"max_outage_s", &FaultOptions::max_outage, 1.0, 0.01, 1e6, "s"},
      {"reverse_speed_m_s", &FaultOptions::reverse_speed, 1.0, 0.01, 100.0, "m/s"},
      {"reverse_time_s", &FaultOptions::reverse_time, 1.0, 0.1, 3600.0, "s"}};
  std::vector<std::string> names{"enabled", "window", "max_failed", "heading_epochs"};
  for (const auto& k : kKeys) names.push_back(k.name);
  y.check_keys(f, "faults", names);
  if (auto v = y.get(f, "enabled"); v.IsDefined()) o.enabled = y.boolean(v, "faults.enabled");
  for (const auto& k : kKeys)
    if (auto v = y.get(f, k.name); v.IsDefined()) {
      const std::string path = std::string("faults.") + k.name;
      const double x = y.number_in(v, path, k.lo, k.hi, k.unit_name);
      o.*k.member = x * k.unit;
    }
  auto integer = [&](const char* name, int& out) {
    if (auto v = y.get(f, name); v.IsDefined()) {
      const std::string path = std::string("faults.") + name;
      const double x = y.number(v, path);
      if (x != std::floor(x) || x < 1 || x > 1000) y.fail(path, "must be a whole number >= 1", &v);
      out = static_cast<int>(x);
    }
  };
  integer("window", o.window);
  integer("max_failed", o.max_failed);
  integer("heading_epochs", o.heading_epochs);
  try {
    o.validate();
  } catch (const InputError& e) {
    y.fail("faults", e.what(), &f);
  }
}

}  // namespace

SpeedSharing speed_sharing_from_name(const std::string& name) {
  if (name == "mean") return SpeedSharing::kMean;
  if (name == "own") return SpeedSharing::kOwn;
  throw InputError("wheel speed sharing '" + name + "': expected mean or own");
}

YawScaleFactorChoice yaw_scale_factors_from_name(const std::string& name) {
  for (const auto& [n, c] : kYawChoices)
    if (name == n) return c;
  throw InputError("yaw scale factors '" + name + "': expected auto, held, constraint or estimated");
}

CalibrationMode calibration_mode_from_name(const std::string& name) {
  if (name == "estimate") return CalibrationMode::kEstimate;
  if (name == "manifest") return CalibrationMode::kManifest;
  throw InputError("calibration '" + name + "': expected estimate or manifest");
}

ReferenceWeighting weighting_from_name(const std::string& name) {
  if (name == "equal") return ReferenceWeighting::kFixed;
  if (name == "covariance") return ReferenceWeighting::kCovariance;
  if (name == "standalone") return ReferenceWeighting::kStandalone;
  throw InputError("reference weights '" + name + "': expected equal, covariance or standalone");
}

RunConfig load_run_config(const fs::path& file, const WarningSink& warn) {
  const YamlReader y(file, warn, "run configuration");
  const YAML::Node& root = y.root();
  y.check_keys(root, "", {"dataset", "configuration", "chips", "modules", "output", "duration_s",
                          "calibration", "data_checks", "filter", "fusion", "faults", "noise", "standstill"});
  RunConfig c;
  const fs::path base = file.parent_path();
  read_run_selection(y, root, base, c);
  if (auto out = y.get(root, "output"); out.IsDefined()) read_output(y, out, base, c);
  if (auto f = y.get(root, "filter"); f.IsDefined()) read_filter(y, f, c);
  if (auto f = y.get(root, "fusion"); f.IsDefined()) read_fusion(y, f, c.nav.fusion);
  if (auto f = y.get(root, "noise"); f.IsDefined()) read_noise(y, f, c.nav.noise);
  if (auto f = y.get(root, "standstill"); f.IsDefined()) read_standstill(y, f, c.nav.standstill);
  if (auto f = y.get(root, "faults"); f.IsDefined()) read_faults(y, f, c.nav.faults);
  return c;
}

RunConfig run_config_with(const RunOverrides& o, const WarningSink& warn) {
  RunConfig cfg = o.config.empty() ? RunConfig{} : load_run_config(o.config, warn);
  if (!o.manifest.empty()) cfg.manifest = o.manifest;
  if (cfg.manifest.empty())
    throw InputError("no dataset: give a run configuration naming one, or a manifest (--manifest)");
  if (!o.modules.empty() && !o.configuration.empty())
    throw InputError("modules and configuration both given: the modules name the IMUs themselves; "
                     "give one of them");
  if (!o.modules.empty() && !o.chips.empty())
    throw InputError("modules and chips both given: chips pick the chips of a configuration; with "
                     "modules name the chips' modules (e.g. left-C2)");
  if (!o.configuration.empty()) {
    cfg.configuration = o.configuration;
    cfg.modules.clear();  // the front end's choice over the configuration file's modules
  }
  if (!o.chips.empty()) cfg.chips = o.chips;
  if (!o.modules.empty()) cfg.modules = o.modules;
  if (!o.output_dir.empty()) cfg.output_dir = o.output_dir;
  if (!o.formats.empty()) {
    cfg.formats.clear();
    for (const auto& f : o.formats) cfg.formats.push_back(trajectory_format_from_name(f));
  }
  if (!o.tum_frame.empty()) cfg.tum_frame = tum_frame_from_name(o.tum_frame);
  if (!o.speed.empty()) cfg.nav.fusion.speed = speed_sharing_from_name(o.speed);
  if (!o.yaw_scale_factors.empty()) cfg.nav.yaw_scale_factors = yaw_scale_factors_from_name(o.yaw_scale_factors);
  if (!o.weights.empty()) {
    cfg.nav.fusion.weighting = weighting_from_name(o.weights);
    cfg.nav.fusion.weights.clear();  // over the configuration's list of fixed weights
  }
  if (!o.calibration.empty()) cfg.calibration = calibration_mode_from_name(o.calibration);
  if (o.centralized) cfg.nav.fusion.centralized = *o.centralized;
  if (o.position_constraint) cfg.nav.fusion.position_constraint = *o.position_constraint;
  if (o.fault_handling) cfg.nav.faults.enabled = *o.fault_handling;
  if (o.standstill) cfg.nav.standstill.enabled = *o.standstill;
  if (o.fixed_noise) cfg.nav.noise.enabled = !*o.fixed_noise;
  if (o.data_checks) cfg.data_checks = *o.data_checks;
  if (o.duration) cfg.max_duration = *o.duration;
  if (o.output_interval) cfg.nav.output_interval = *o.output_interval;
  if (o.covariance_interval) cfg.nav.covariance_interval = *o.covariance_interval;
  if (o.overwrite) cfg.overwrite = true;
  if (o.full_rate) cfg.file_interval = 0.0;
  if (o.subsystems) cfg.write_subsystems = true;
  return cfg;
}

RunRequest make_run_request(const RunConfig& cfg, const WarningSink& warn) {
  RunRequest r;
  r.manifest = load_manifest(cfg.manifest, warn);
  r.modules = cfg.modules.empty() ? configuration_modules(r.manifest, cfg.configuration, cfg.chips)
                                  : cfg.modules;
  r.nav = cfg.nav;
  r.nav.earth_rotation =
      cfg.earth_rotation == "auto" ? r.manifest.earth_rotation : cfg.earth_rotation == "true";
  r.output_dir = cfg.output_dir;
  if (r.output_dir.empty()) {
    std::string name = cfg.modules.empty() ? cfg.configuration : std::string("modules");
    for (const auto& m : r.modules) name += "-" + m;
    r.output_dir = fs::path("results") / name;
  }
  r.formats = cfg.formats;
  r.tum_frame = cfg.tum_frame;
  r.overwrite = cfg.overwrite;
  r.write_subsystems = cfg.write_subsystems;
  r.file_interval = cfg.file_interval;
  r.max_duration = cfg.max_duration;
  r.calibration = cfg.calibration;
  r.data_checks = cfg.data_checks;
  r.warn = warn;
  return r;
}

}  // namespace wheelins
