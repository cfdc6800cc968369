// Loading a run configuration (run_config.hpp) and turning it into a RunRequest.
#include "wheelins/run/run_config.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <set>

#include "wheelins/io/text_util.hpp"
#include "wheelins/io/yaml_reader.hpp"
#include "wheelins/run/presets.hpp"
#include "wheelins/run/run_options.hpp"

namespace wheelins {
namespace fs = std::filesystem;

namespace {

/// The keys each map of the file may hold ("" for the top), from the declarations' dotted keys.
struct KeyCollector {
  std::map<std::string, std::vector<std::string>> keys;

  void add(const std::string& key) {
    std::string parent;
    for (const std::string& name : dotted_key_parts(key)) {
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
  void custom(const OptionInfo& i, const char*, OptionShow, F&&) { add(i.key); }
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
  void custom(const OptionInfo& i, const char*, OptionShow, F&& read) {
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
  for (const std::string& name : dotted_key_parts(key)) {
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

constexpr const char* kSettingExample = "a key of docs/run-config.md (e.g. fusion.position_std_m=0.3)";

}  // namespace

void apply_run_settings(const std::vector<std::string>& settings, RunConfig& c) {
  if (settings.empty()) return;
  // An unknown key on the command line is a typo: an error, naming the closest known key.
  const YamlReader y(settings_document(settings, kSettingExample), "--set", warnings_are_errors(), false);
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

NamedSetting cli_setting(const NamedOption& o, const std::string& value) {
  NamedSetting s{o.option, o.key, {}, false};
  if (!o.sets.empty()) {
    s.values = {o.sets};
  } else if (o.path || value.find(',') == std::string::npos) {
    s.values = {value};
  } else {
    s.list = true;  // "a,b,,c": each item, empty ones too (the reading names them)
    std::vector<std::string_view> items;
    io_detail::split_fields(value, ',', items);
    s.values.assign(items.begin(), items.end());
  }
  return s;
}

NamedSetting cli_setting(const std::string& option, const std::string& value) {
  for (const NamedOption& n : run_named_options())
    if (("," + n.names + ",").find("," + option + ",") != std::string::npos) return cli_setting(n, value);
  throw InputError(option + ": not an option of a run setting");
}

namespace {

/// The named options read over `c`, one by one so that a message names the option.
void apply_named(const std::vector<NamedSetting>& named, RunConfig& c) {
  for (const NamedSetting& s : named) {
    YAML::Node value;
    if (s.list)
      for (const std::string& v : s.values) value.push_back(v);
    else
      value = s.values.empty() ? std::string() : s.values.front();
    YAML::Node doc(YAML::NodeType::Map);
    set_dotted_key(doc, s.key, value, s.name);
    try {
      const YamlReader y(doc, s.name, warnings_are_errors(), false);
      read_run_config(y, fs::path(), c, false);
    } catch (const InputError& e) {
      // "--configuration: configuration: ..." says the name once.
      const std::string m = e.what(), twice = s.name + ": " + s.key + ": ";
      const bool same = s.name == s.key || s.name == "--" + s.key;
      if (!same || m.rfind(twice, 0) != 0) throw;
      throw InputError(s.name + ": " + m.substr(twice.size()));
    }
  }
}

/// Which IMUs: modules name them, a configuration and chips choose them; not both ways.
void check_selection(const std::vector<NamedSetting>& named) {
  auto given = [&](const char* key) {
    return std::any_of(named.begin(), named.end(), [&](const NamedSetting& s) { return s.key == key; });
  };
  if (given("modules") && given("configuration"))
    throw InputError("modules and configuration both given: the modules name the IMUs themselves; "
                     "give one of them");
  if (given("modules") && given("chips"))
    throw InputError("modules and chips both given: chips pick the chips of a configuration; with "
                     "modules name the chips' modules (e.g. left-C2)");
}

}  // namespace

RunConfig run_config_with(const RunOverrides& o, const WarningSink& warn) {
  // The front end's own values first (in range, names known): a mistake stops the command
  // before it reads any file.
  check_selection(o.named);
  RunConfig checked;
  apply_named(o.named, checked);
  // The file and the --set settings over it, both parsed before either is read: the file's
  // unknown keys are warnings, the settings' errors (a typo on the command line).
  const YAML::Node settings = settings_document(o.settings, kSettingExample);
  std::optional<YamlReader> file;
  if (!o.config.empty()) file.emplace(o.config, warn, "run configuration");
  const YamlReader set(settings, "--set", warnings_are_errors(), false);
  RunConfig cfg;
  if (file) read_run_config(*file, o.config.parent_path(), cfg, true);
  if (!o.settings.empty()) read_run_config(set, fs::path(), cfg, false);
  apply_named(o.named, cfg);
  if (cfg.manifest.empty())
    throw InputError("no dataset: give a run configuration naming one, or a manifest (--manifest)");
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
