// Loading a run configuration (run_config.hpp) and turning it into a RunRequest.
#include "wheelins/run/run_config.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <set>
#include <tuple>

#include "wheelins/io/yaml_reader.hpp"
#include "wheelins/run/presets.hpp"
#include "wheelins/run/run_options.hpp"

namespace wheelins {
namespace fs = std::filesystem;

namespace {

/// "filter.initial_std.heading_deg" -> {filter, initial_std, heading_deg} (empty parts kept).
std::vector<std::string> key_parts(const std::string& key) {
  std::vector<std::string> parts;
  for (std::size_t from = 0;;) {
    const std::size_t dot = key.find('.', from);
    parts.push_back(key.substr(from, dot == std::string::npos ? std::string::npos : dot - from));
    if (dot == std::string::npos) return parts;
    from = dot + 1;
  }
}

/// The keys each map of the file may hold ("" for the top), from the declarations' dotted keys.
struct KeyCollector {
  std::map<std::string, std::vector<std::string>> keys;

  void add(const std::string& key) {
    std::string parent;
    for (const std::string& name : key_parts(key)) {
      auto& list = keys[parent];
      if (std::find(list.begin(), list.end(), name) == list.end()) list.push_back(name);
      parent += (parent.empty() ? "" : ".") + name;
    }
  }
  void number(const OptionInfo& i, double&, const OptionRange&, OptionScale = {}, double* = nullptr) {
    add(i.key);
  }
  void rate(const OptionInfo& i, double&, const OptionRange&) { add(i.key); }
  void whole(const OptionInfo& i, int&, int, int) { add(i.key); }
  void vec3(const OptionInfo& i, Vec3&, const OptionRange&) { add(i.key); }
  void flag(const OptionInfo& i, bool&) { add(i.key); }
  void path(const OptionInfo& i, fs::path&, bool, const char*) { add(i.key); }
  template <class E>
  void choice(const OptionInfo& i, E&, const OptionChoices<E>&) { add(i.key); }
  template <class F>
  void custom(const OptionInfo& i, const char*, const char*, F&&) { add(i.key); }
  template <class F>
  void section_check(const char*, F&&) {}
};

/// Reads each declared setting from the file: the maps on its way checked once (a map, its keys
/// known), the value checked against its type and range, converted and stored.
class YamlOptionReader {
 public:
  /// `whole`: a whole configuration (its required keys must be there), else settings over one.
  YamlOptionReader(const YamlReader& y, fs::path base, std::map<std::string, std::vector<std::string>> keys,
                   bool whole)
      : y_(y), base_(std::move(base)), keys_(std::move(keys)), whole_(whole) {}

  void number(const OptionInfo& i, double& x, const OptionRange& r, OptionScale s = {}, double* also = nullptr) {
    if (const YAML::Node v = node(i.key); v.IsDefined()) {
      x = y_.number_in(v, i.key, r.lo, r.hi, r.unit) * s.mul / s.div;
      if (also) *also = x;
    }
  }
  void rate(const OptionInfo& i, double& interval, const OptionRange& r) {
    if (const YAML::Node v = node(i.key); v.IsDefined()) interval = 1.0 / y_.number_in(v, i.key, r.lo, r.hi, r.unit);
  }
  void whole(const OptionInfo& i, int& n, int lo, int hi) {
    if (const YAML::Node v = node(i.key); v.IsDefined()) {
      const double x = y_.number(v, i.key);
      if (x != std::floor(x) || x < lo || x > hi) y_.fail(i.key, "must be a whole number >= " + std::to_string(lo), &v);
      n = static_cast<int>(x);
    }
  }
  void vec3(const OptionInfo& i, Vec3& x, const OptionRange& r) {
    if (const YAML::Node v = node(i.key); v.IsDefined()) {
      x = y_.vec3(v, i.key);
      for (int k = 0; k < 3; ++k) y_.range(x[k], r.lo, r.hi, YamlReader::index_path(i.key, static_cast<std::size_t>(k)), v, r.unit);
    }
  }
  void flag(const OptionInfo& i, bool& b) {
    if (const YAML::Node v = node(i.key); v.IsDefined()) b = y_.boolean(v, i.key);
  }
  void path(const OptionInfo& i, fs::path& p, bool required, const char*) {
    const YAML::Node v = node(i.key);
    if (!v.IsDefined()) {
      if (required && whole_) (void)y_.required(y_.root(), "", i.key);  // the error naming the missing key
      return;
    }
    const std::string text = y_.text(v, i.key);
    p = fs::path(text).is_absolute() ? fs::path(text) : base_ / text;
  }
  template <class E>
  void choice(const OptionInfo& i, E& e, const OptionChoices<E>& names) {
    if (const YAML::Node v = node(i.key); v.IsDefined()) e = y_.choice<E>(v, i.key, names);
  }
  template <class F>
  void custom(const OptionInfo& i, const char*, const char*, F&& read) {
    if (const YAML::Node v = node(i.key); v.IsDefined()) read(y_, v, *config_, base_);
  }
  template <class F>
  void section_check(const char* section, F&& check) {
    const YAML::Node s = YamlReader::get(y_.root(), section);
    if (!s.IsDefined()) return;
    try {
      check(*config_);
    } catch (const InputError& e) {
      y_.fail(section, e.what(), &s);
    }
  }

  void read_into(RunConfig& c) {
    config_ = &c;
    declare_run_options(*this, c);
  }

 private:
  /// The node of a dotted key (undefined when it or a map on its way is not there); each map
  /// on the way is checked when first met.
  YAML::Node node(const std::string& key);

  const YamlReader& y_;
  fs::path base_;
  std::map<std::string, std::vector<std::string>> keys_;
  std::set<std::string> entered_;
  bool whole_;
  RunConfig* config_ = nullptr;
};

YAML::Node YamlOptionReader::node(const std::string& key) {
  std::vector<YAML::Node> way{y_.root()};
  std::string path;
  for (const std::string& name : key_parts(key)) {
    if (!way.back().IsDefined()) break;
    if (entered_.insert(path).second) {
      if (!path.empty()) y_.require_map(way.back(), path);
      y_.check_keys(way.back(), path, keys_[path]);
    }
    way.push_back(YamlReader::get(way.back(), name));
    path += (path.empty() ? "" : ".") + name;
  }
  return way.back();
}

}  // namespace

const OptionChoices<SpeedSharing>& speed_sharing_choices() {
  static const OptionChoices<SpeedSharing> c = {{"mean", SpeedSharing::kMean}, {"own", SpeedSharing::kOwn}};
  return c;
}

const OptionChoices<YawScaleFactorChoice>& yaw_scale_factor_choices() {
  static const OptionChoices<YawScaleFactorChoice> c = {{"auto", YawScaleFactorChoice::kAuto},
                                                        {"held", YawScaleFactorChoice::kHeld},
                                                        {"constraint", YawScaleFactorChoice::kFromConstraint},
                                                        {"estimated", YawScaleFactorChoice::kEstimated}};
  return c;
}

const OptionChoices<CalibrationMode>& calibration_mode_choices() {
  static const OptionChoices<CalibrationMode> c = {{"estimate", CalibrationMode::kEstimate},
                                                   {"manifest", CalibrationMode::kManifest}};
  return c;
}

namespace {
/// A choice named on the command line: InputError "<what> 'x': expected a, b or c" otherwise.
template <class E>
E choice_from_name(const char* what, const std::string& name, const OptionChoices<E>& choices) {
  std::string list;
  for (std::size_t k = 0; k < choices.size(); ++k) {
    if (name == choices[k].first) return choices[k].second;
    list += (k == 0 ? "" : k + 1 == choices.size() ? " or " : ", ") + choices[k].first;
  }
  throw InputError(std::string(what) + " '" + name + "': expected " + list);
}
}  // namespace

SpeedSharing speed_sharing_from_name(const std::string& name) {
  return choice_from_name("wheel speed sharing", name, speed_sharing_choices());
}

YawScaleFactorChoice yaw_scale_factors_from_name(const std::string& name) {
  return choice_from_name("yaw scale factors", name, yaw_scale_factor_choices());
}

CalibrationMode calibration_mode_from_name(const std::string& name) {
  return choice_from_name("calibration", name, calibration_mode_choices());
}

ReferenceWeighting weighting_from_name(const std::string& name) {
  if (name == "equal") return ReferenceWeighting::kFixed;
  if (name == "covariance") return ReferenceWeighting::kCovariance;
  if (name == "standalone") return ReferenceWeighting::kStandalone;
  throw InputError("reference weights '" + name + "': expected equal, covariance or standalone");
}

namespace {
/// The settings of `y` read over `c` (`whole`: a whole configuration file).
void read_run_config(const YamlReader& y, const fs::path& base, RunConfig& c, bool whole) {
  KeyCollector keys;
  RunConfig defaults;
  declare_run_options(keys, defaults);
  YamlOptionReader(y, base, std::move(keys.keys), whole).read_into(c);
}

RunConfig read_run_config(const YamlReader& y, const fs::path& base) {
  RunConfig c;
  read_run_config(y, base, c, true);
  return c;
}

/// `--set KEY=VALUE` settings as one YAML document: {filter: {speed_window_s: 0.1}, ...}.
YAML::Node settings_document(const std::vector<std::string>& settings) {
  YAML::Node root(YAML::NodeType::Map);
  for (const std::string& s : settings) {
    const std::string where = "--set '" + s + "'";
    const std::size_t eq = s.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError(where + ": expected KEY=VALUE, a key of docs/run-config.md (e.g. fusion.position_std_m=0.3)");
    const YAML::Node value = parse_yaml(s.substr(eq + 1), where, "value");
    if (!value.IsDefined() || value.IsNull()) throw InputError(where + ": no value after '='");
    const std::string key = s.substr(0, eq);
    const std::vector<std::string> parts = key_parts(key);
    YAML::Node map = root;
    std::string path;
    for (std::size_t k = 0; k < parts.size(); ++k) {
      const std::string& name = parts[k];
      if (name.empty()) throw InputError(where + ": an empty part in the key '" + key + "'");
      path += (path.empty() ? "" : ".") + name;
      if (k + 1 == parts.size()) {
        if (map[name].IsDefined() && !map[name].IsNull()) throw InputError(where + ": " + key + " is set twice");
        map[name] = value;
        break;
      }
      if (!map[name].IsDefined() || map[name].IsNull()) map[name] = YAML::Node(YAML::NodeType::Map);
      if (!map[name].IsMap()) throw InputError(where + ": " + path + " is set as a value and as a section");
      map.reset(map[name]);
    }
  }
  return root;
}
}  // namespace

void apply_run_settings(const std::vector<std::string>& settings, RunConfig& c) {
  if (settings.empty()) return;
  // An unknown key on the command line is a typo: an error, naming the closest known key.
  const YamlReader y(settings_document(settings), "--set", warnings_are_errors(), false);
  read_run_config(y, fs::path(), c, false);
}

WarningSink warnings_are_errors() {
  return [](std::string msg) {
    const std::string ignored = "unknown key ignored";
    if (const auto p = msg.find(ignored); p != std::string::npos) msg.replace(p, ignored.size(), "unknown key");
    throw InputError(msg);
  };
}

RunConfig load_run_config(const fs::path& file, const WarningSink& warn) {
  const YamlReader y(file, warn, "run configuration");
  return read_run_config(y, file.parent_path());
}

RunConfig load_run_config(const YAML::Node& settings, const fs::path& base, const std::string& where,
                          const WarningSink& warn) {
  const YamlReader y(settings, where, warn);
  return read_run_config(y, base);
}

namespace {

/// A front end's number (its command-line option `option`) in its range [lo, hi] (NaN,
/// infinities and 1e400 fail too); `lo_open`: lo itself excluded.
void check_range(const std::optional<double>& v, const char* option, double lo, double hi, const char* unit,
                 bool lo_open = false) {
  if (!v) return;
  const double x = *v;
  if (!std::isfinite(x) || x < lo || x > hi || (lo_open && x == lo)) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "%s %g: must be in %s%g, %g] %s", option, x, lo_open ? "(" : "[", lo, hi, unit);
    throw InputError(buf);
  }
}

/// The numbers a front end gives over the file, in the ranges the file's keys have.
void check_override_numbers(const RunOverrides& o) {
  check_range(o.duration, "--duration", 0.0, 1e7, "s", true);
  for (const auto& [value, option, key] :
       {std::tuple{&o.output_interval, "--output-interval", "output.interval_s"},
        std::tuple{&o.covariance_interval, "--covariance-interval", "filter.covariance_interval_s"}}) {
    const OptionRange r = run_option_range(key);
    check_range(*value, option, r.lo, r.hi, r.unit);
  }
}

}  // namespace

RunConfig run_config_with(const RunOverrides& o, const WarningSink& warn) {
  check_override_numbers(o);
  RunConfig cfg = o.config.empty() ? RunConfig{} : load_run_config(o.config, warn);
  apply_run_settings(o.settings, cfg);
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
