// Loading a study file (spec.hpp): the setting keys and their checks, the axes (sweep,
// seeds, replicates, configurations), the built-in experiment study, and a run
// configuration's text read by the code that reads run-configuration files. Job K is
// resolved in resolve.cpp.
#include "wheelins/study/spec.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <set>

#include "wheelins/io/manifest.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/io/yaml_reader.hpp"
#include "wheelins/nav/types.hpp"
#include "wheelins/run/run_config.hpp"

namespace wheelins::study {
namespace fs = std::filesystem;

std::vector<std::string> split_dotted(const std::string& key) {
  std::vector<std::string> parts;
  std::size_t pos = 0;
  while (true) {
    const auto dot = key.find('.', pos);
    parts.push_back(key.substr(pos, dot == std::string::npos ? std::string::npos : dot - pos));
    if (dot == std::string::npos) break;
    pos = dot + 1;
  }
  return parts;
}

std::string hash_text(const std::string& text) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (unsigned char c : text) h = (h ^ c) * 0x100000001b3ull;
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::string flow_yaml(const YAML::Node& v) {
  if (!v.IsDefined() || v.IsNull()) return "null";
  YAML::Emitter e;
  e.SetMapFormat(YAML::Flow);
  e.SetSeqFormat(YAML::Flow);
  e << v;
  return e.c_str();
}

namespace {

// --- Setting keys ----------------------------------------------------------------------

const std::vector<std::string>& special_keys() {
  static const std::vector<std::string> k = {"dataset", "seed", "configuration",
                                             "chips",   "chip", "modules"};
  return k;
}

bool is_setting_key(const std::string& key) {
  for (const char* ns : {"simulate.", "run.", "manifest."})
    if (key.rfind(ns, 0) == 0 && key.size() > std::string(ns).size()) return true;
  return std::find(special_keys().begin(), special_keys().end(), key) != special_keys().end();
}

/// The configurations a study may name (the run configuration's names and `centralized`,
/// the Triple INS with the centralized filter).
const std::vector<std::string>& configuration_choices() {
  static const std::vector<std::string> c = {"single",     "single-right", "dual-wheel",
                                             "body-wheel", "triple",       "centralized"};
  return c;
}

std::string closest(const std::string& key, const std::vector<std::string>& known) {
  std::string best;
  std::size_t score = 4;
  for (const auto& k : known) {
    const std::size_t d = io_detail::edit_distance(key, k);
    if (d < score) score = d, best = k;
  }
  return best.empty() ? "" : "; did you mean '" + best + "'?";
}

/// "1..20" -> 1, 2, ..., 20 (whole numbers).
std::optional<std::pair<long long, long long>> parse_range(const std::string& s) {
  const auto dots = s.find("..");
  if (dots == std::string::npos) return std::nullopt;
  try {
    std::size_t used = 0;
    const long long a = std::stoll(s.substr(0, dots), &used);
    if (used != dots) return std::nullopt;
    const std::string rest = s.substr(dots + 2);
    const long long b = std::stoll(rest, &used);
    if (used != rest.size()) return std::nullopt;
    return std::make_pair(a, b);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

}  // namespace

std::string DatasetSpec::describe() const {
  if (manifest) return manifest->string();
  if (!sim) return "?";
  std::string s = sim->vehicle.preset + "/" + sim->profile + " seed " + std::to_string(sim->seed);
  if (sim->scenario != "default") s += " on " + fs::path(sim->scenario).filename().string();
  return s;
}

std::string Job::describe() const {
  std::string s;
  for (std::size_t i = 0; i < labels.size(); ++i) s += (i ? " | " : "") + labels[i];
  return s;
}

// --- Checking a run configuration -----------------------------------------------------

RunConfig load_run_yaml(const std::string& run_yaml, const fs::path& manifest,
                        const std::string& where) {
  // Read by the code that reads run-configuration files (every key it knows, now and later,
  // works in a study), its messages naming `where`; an unknown key is an error in a study.
  const std::string text = "dataset: " + flow_yaml(YAML::Node(manifest.string())) + "\n" + run_yaml;
  return load_run_config(parse_yaml(text, where, "run configuration"), manifest.parent_path(), where,
                         warnings_are_errors());
}

void check_run_yaml(const std::string& run_yaml, const std::string& where) {
  load_run_yaml(run_yaml, "/study-check/manifest.yaml", where);
}

// --- Loading --------------------------------------------------------------------------

namespace {

struct Loader {
  const YamlReader& y;
  fs::path dir;

  [[noreturn]] void fail(const std::string& path, const std::string& what,
                         const YAML::Node* at) const {
    y.fail(path, what, at);
  }

  Setting setting(const std::string& key, const YAML::Node& v, const std::string& where) const;
  std::vector<Setting> settings_map(const YAML::Node& m, const std::string& where,
                                    const std::string& prefix = "") const;
  std::vector<YAML::Node> values(const YAML::Node& v, const std::string& where) const;
  static std::string label_of(const YAML::Node& v) {
    return v.IsScalar() ? v.Scalar() : flow_yaml(v);
  }
  Axis axis(const std::string& name, const YAML::Node& v, const std::string& where,
            AxisRole role) const;
  std::vector<Axis> axes(const YAML::Node& m, const std::string& where, AxisRole role) const;
  Axis configurations(const YAML::Node& v) const;
  void check_configuration(const std::string& c, const std::string& where,
                           const YAML::Node& at) const;
  AxisValue configuration(const YAML::Node& e, const std::string& where) const;
};

/// A value of a setting key as given (paths are resolved later).
Setting Loader::setting(const std::string& key, const YAML::Node& v,
                        const std::string& where) const {
  if (!is_setting_key(key)) {
    fail(where,
         "'" + key +
             "' is not a setting: expected simulate.KEY, run.KEY, manifest.KEY, "
             "dataset, seed, configuration, chips, chip or modules" +
             closest(key, special_keys()),
         &v);
  }
  return {key, YAML::Clone(v), where,
          v.Mark().is_null() ? 0 : static_cast<std::size_t>(v.Mark().line) + 1};
}

/// A map of settings: dotted keys (or, inside `simulate:`, `run:`, `manifest:`, plain keys).
std::vector<Setting> Loader::settings_map(const YAML::Node& m, const std::string& where,
                                          const std::string& prefix) const {
  std::vector<Setting> out;
  if (!m.IsDefined() || m.IsNull()) return out;
  y.require_map(m, where);
  std::set<std::string> seen;
  for (const auto& kv : m) {
    const std::string k = kv.first.as<std::string>();
    if (!seen.insert(k).second) fail(YamlReader::join(where, k), "duplicate key", &kv.first);
    if (prefix.empty() && (k == "simulate" || k == "run" || k == "manifest") &&
        kv.second.IsMap()) {
      for (auto& s : settings_map(kv.second, YamlReader::join(where, k), k + "."))
        out.push_back(std::move(s));
      continue;
    }
    out.push_back(setting(prefix + k, kv.second, YamlReader::join(where, k)));
  }
  return out;
}

/// The values of a list axis: a sequence (whole-number ranges "a..b" expand) or a range.
std::vector<YAML::Node> Loader::values(const YAML::Node& v, const std::string& where) const {
  std::vector<YAML::Node> out;
  auto add = [&](const YAML::Node& x) {
    if (x.IsScalar())
      if (const auto r = parse_range(x.Scalar())) {
        if (r->second < r->first || r->second - r->first > 100000)
          fail(where, "range '" + x.Scalar() + "' is empty or too long", &x);
        for (long long i = r->first; i <= r->second; ++i) out.push_back(YAML::Node(i));
        return;
      }
    out.push_back(x);
  };
  if (v.IsSequence()) {
    for (const auto& x : v) add(x);
  } else if (v.IsScalar() && parse_range(v.Scalar())) {
    add(v);
  } else {
    fail(where, "expected a list of values (or a range a..b), got " + YamlReader::describe(v),
         &v);
  }
  if (out.empty()) fail(where, "an axis needs at least one value", &v);
  return out;
}

/// `key: [values]` (a list axis of one setting) or `name: {label: {settings}, ...}`.
Axis Loader::axis(const std::string& name, const YAML::Node& v, const std::string& where,
                  AxisRole role) const {
  Axis a;
  a.role = role;
  if (is_setting_key(name)) {
    const auto parts = split_dotted(name);
    a.name = parts.back();
    for (const auto& x : values(v, where))
      a.values.push_back({label_of(x), {setting(name, x, where)}});
  } else {
    a.name = name;
    if (!v.IsMap())
      fail(where,
           "'" + name +
               "' is not a setting key, so it must be a map of named variants "
               "(label: {settings}); or write the key in full, e.g. simulate." +
               name + " or run." + name,
           &v);
    for (const auto& kv : v) {
      const std::string label = kv.first.as<std::string>();
      a.values.push_back({label, settings_map(kv.second, YamlReader::join(where, label))});
    }
    if (a.values.empty()) fail(where, "an axis needs at least one value", &v);
  }
  std::set<std::string> labels;
  for (const auto& x : a.values)
    if (!labels.insert(x.label).second)
      fail(where, "the label '" + x.label + "' appears twice", &v);
  return a;
}

std::vector<Axis> Loader::axes(const YAML::Node& m, const std::string& where,
                               AxisRole role) const {
  std::vector<Axis> out;
  if (!m.IsDefined() || m.IsNull()) return out;
  y.require_map(m, where);
  for (const auto& kv : m) {
    const std::string k = kv.first.as<std::string>();
    out.push_back(axis(k, kv.second, YamlReader::join(where, k), role));
  }
  return out;
}

Axis Loader::configurations(const YAML::Node& v) const {
  const std::string where = "configurations";
  if (!v.IsSequence() || v.size() == 0) fail(where, "expected a list of configurations", &v);
  Axis a;
  a.name = "configuration";
  a.role = AxisRole::kConfiguration;
  for (std::size_t i = 0; i < v.size(); ++i)
    a.values.push_back(configuration(v[i], YamlReader::index_path(where, i)));
  std::set<std::string> labels;
  for (const auto& x : a.values)
    if (!labels.insert(x.label).second)
      fail(where, "the configuration '" + x.label + "' appears twice", &v);
  return a;
}

/// Fails unless `c` is one of configuration_choices().
void Loader::check_configuration(const std::string& c, const std::string& where,
                                 const YAML::Node& at) const {
  const auto& choices = configuration_choices();
  if (std::find(choices.begin(), choices.end(), c) == choices.end()) {
    std::string list;
    for (const auto& n : choices) list += (list.empty() ? "" : ", ") + n;
    fail(where, "unknown configuration '" + c + "' (known: " + list + ")" + closest(c, choices),
         &at);
  }
}

/// One entry `e` of `configurations`: a name, or a map {name, configuration, settings}.
AxisValue Loader::configuration(const YAML::Node& e, const std::string& where) const {
  AxisValue val;
  if (e.IsScalar()) {
    check_configuration(e.Scalar(), where, e);
    val.label = e.Scalar();
    val.settings.push_back({"configuration", YAML::Clone(e), where});
  } else if (e.IsMap()) {
    YAML::Node body = YAML::Clone(e);
    if (e["name"]) {
      val.label = y.text(e["name"], where + ".name");
      body.remove("name");
    }
    val.settings = settings_map(body, where);
    for (const auto& s : val.settings) {
      if (s.key.rfind("simulate.", 0) == 0 || s.key.rfind("manifest.", 0) == 0 ||
          s.key == "dataset" || s.key == "seed")
        fail(s.where,
             "a configuration cannot change the data (" + s.key +
                 "): put it in `sweep` so that configurations compare on the same data",
             &e);
      if (s.key == "configuration") check_configuration(label_of(s.value), s.where, e);
    }
    if (val.label.empty()) {
      for (const auto& s : val.settings)
        if (s.key == "configuration") val.label = label_of(s.value);
      if (val.label.empty()) fail(where, "a configuration needs a `name` or a `configuration`", &e);
    }
  } else {
    fail(where,
         "expected a configuration name or a map {name, configuration, chips, run.KEY: ...}", &e);
  }
  return val;
}

}  // namespace

std::string experiment_study_yaml(const ExperimentSpec& e) {
  std::string s =
      "# The paper's experiment (Section VI) as a study, written by `wheelins experiment`.\n"
      "# Shard it like any study (docs/studies.md): wheelins study run THIS_FILE --job K, then\n"
      "# wheelins study report THIS_FILE writes the experiment's tables and plots here.\n"
      "name: experiment\n"
      "results: .\n"
      "experiment:\n"
      "  dataset: " +
      flow_yaml(YAML::Node(e.dataset.string())) + "\n";
  if (!e.only.empty()) {
    s += "  only: [";
    for (std::size_t i = 0; i < e.only.size(); ++i) s += (i ? ", " : "") + e.only[i];
    s += "]\n";
  }
  s += "  speed: " + e.speed + "\n";
  if (e.duration > 0) s += "  duration_s: " + io_detail::format_double(e.duration) + "\n";
  if (e.calibration != "estimate") s += "  calibration: " + e.calibration + "\n";
  return s;
}

void check_experiment_only(const std::vector<std::string>& only, const std::string& where) {
  for (const auto& o : only)
    if (o != "single" && o != "dual-wheel" && o != "body-wheel" && o != "triple" && o != "centralized")
      throw InputError(where + ": unknown configuration '" + o +
                       "' (single, dual-wheel, body-wheel, triple, centralized)");
}

namespace {

/// A path of the study file: from the study's folder `dir` unless absolute.
fs::path from_dir(const fs::path& dir, const std::string& p) {
  return fs::path(p).is_absolute() ? fs::path(p) : dir / p;
}

/// `interval`, `confidence` and `resamples`.
IntervalOptions read_interval(const YamlReader& y, const YAML::Node& root) {
  IntervalOptions o;
  if (auto v = YamlReader::get(root, "interval"); v.IsDefined()) {
    try {
      o.method = interval_method_from_name(y.text(v, "interval"));
    } catch (const InputError& e) {
      y.fail("interval", e.what(), &v);
    }
  }
  if (auto v = YamlReader::get(root, "confidence"); v.IsDefined()) {
    o.confidence = y.number(v, "confidence");
    if (!(o.confidence > 0.5 && o.confidence < 1.0))
      y.fail("confidence", "must be in (0.5, 1), e.g. 0.95", &v);
  }
  if (auto v = YamlReader::get(root, "resamples"); v.IsDefined()) {
    const double r = y.number(v, "resamples");
    if (r != std::floor(r) || r < 100 || r > 1e7)
      y.fail("resamples", "a whole number in [100, 1e7]", &v);
    o.resamples = static_cast<int>(r);
  }
  return o;
}

/// The fixed settings: `dataset`, then `simulate`, `run` and `manifest`.
std::vector<Setting> fixed_settings(const Loader& L, const YAML::Node& root) {
  std::vector<Setting> fixed;
  if (auto v = YamlReader::get(root, "dataset"); v.IsDefined())
    fixed.push_back(L.setting("dataset", v, "dataset"));
  for (const char* ns : {"simulate", "run", "manifest"})
    if (auto v = root[ns]; v.IsDefined() && !v.IsNull())
      for (auto& x : L.settings_map(v, ns, std::string(ns) + ".")) fixed.push_back(std::move(x));
  return fixed;
}

/// `experiment` (`e`): the built-in study, which fixes its runs (no axes or data beside it).
ExperimentSpec read_experiment(const YamlReader& y, const YAML::Node& root, const YAML::Node& e,
                               const fs::path& dir) {
  for (const char* k : {"sweep", "seeds", "replicates", "configurations", "simulate", "dataset",
                        "manifest", "compare"})
    if (YamlReader::get(root, k).IsDefined())
      y.fail(k, "not with `experiment` (the built-in study fixes its runs)", &e);
  y.require_map(e, "experiment");
  y.check_keys(e, "experiment", {"dataset", "only", "speed", "duration_s", "calibration"});
  ExperimentSpec x;
  x.dataset = from_dir(dir, y.text(y.required(e, "experiment", "dataset"), "experiment.dataset"));
  if (fs::is_directory(x.dataset)) x.dataset /= "manifest.yaml";
  if (auto v = YamlReader::get(e, "only"); v.IsDefined())
    x.only = y.text_list(v, "experiment.only");
  try {
    check_experiment_only(x.only, "experiment.only");
  } catch (const InputError& err) {
    y.fail("", err.what(), &e);
  }
  if (auto v = YamlReader::get(e, "speed"); v.IsDefined())
    x.speed = y.choice<std::string>(v, "experiment.speed", {{"mean", "mean"}, {"own", "own"}});
  if (auto v = YamlReader::get(e, "calibration"); v.IsDefined())
    x.calibration = y.choice<std::string>(v, "experiment.calibration",
                                          {{"estimate", "estimate"}, {"manifest", "manifest"}});
  if (auto v = YamlReader::get(e, "duration_s"); v.IsDefined()) {
    x.duration = y.number(v, "experiment.duration_s");
    if (x.duration < 0) y.fail("experiment.duration_s", "must be >= 0 (0: all data)", &v);
  }
  return x;
}

/// Axes for the labels of the experiment's runs: the chips as the replicate and the
/// configuration column.
std::vector<Axis> experiment_axes(const std::vector<eval::ExperimentRun>& runs) {
  Axis cfg{"configuration", AxisRole::kConfiguration, {}},
      chips{"chips", AxisRole::kReplicate, {}};
  for (const auto& r : runs) {
    const std::string c = r.centralized ? "centralized" : r.configuration;
    const std::string l = r.configuration == "single"
                              ? std::string(r.side == "left" ? "L" : "R") + r.label
                              : r.label;
    auto add = [](Axis& a, const std::string& label) {
      for (const auto& v : a.values)
        if (v.label == label) return;
      a.values.push_back({label, {}});
    };
    add(chips, l);
    add(cfg, c);
  }
  return {std::move(chips), std::move(cfg)};
}

/// The axes: conditions, replicates, configurations (no two of one name).
std::vector<Axis> study_axes(const Loader& L, const YAML::Node& root, const fs::path& file) {
  std::vector<Axis> axes;
  for (auto& a : L.axes(root["sweep"], "sweep", AxisRole::kCondition))
    axes.push_back(std::move(a));
  if (auto v = root["seeds"]; v.IsDefined() && !v.IsNull()) {
    Axis a = L.axis("seed", v, "seeds", AxisRole::kReplicate);
    axes.push_back(std::move(a));
  }
  for (auto& a : L.axes(root["replicates"], "replicates", AxisRole::kReplicate))
    axes.push_back(std::move(a));
  if (auto v = YamlReader::get(root, "configurations"); v.IsDefined())
    axes.push_back(L.configurations(v));

  std::set<std::string> names;
  for (const auto& a : axes)
    if (!names.insert(a.name).second)
      throw InputError("'" + file.string() + "': two axes are called '" + a.name +
                       "' (name one of them: a map of named variants)");
  return axes;
}

/// The configuration pairs (a, b) of `compare`, or by default of `configs`.
std::vector<std::pair<std::string, std::string>> compare_pairs(
    const YamlReader& y, const YAML::Node& root, const std::vector<std::string>& configs) {
  std::vector<std::pair<std::string, std::string>> compare;
  if (auto v = YamlReader::get(root, "compare"); v.IsDefined()) {
    if (!v.IsSequence())
      y.fail("compare", "expected a list of [A, B] pairs (B - A is reported)", &v);
    for (std::size_t i = 0; i < v.size(); ++i) {
      const auto w = YamlReader::index_path("compare", i);
      const auto pair = y.text_list(v[i], w);
      if (pair.size() != 2) y.fail(w, "expected [A, B]", &v);
      for (const auto& c : pair)
        if (std::find(configs.begin(), configs.end(), c) == configs.end())
          y.fail(w, "'" + c + "' is not one of the study's configurations" + closest(c, configs),
                 &v);
      compare.emplace_back(pair[0], pair[1]);
    }
  } else if (configs.size() >= 2) {
    // Every pair (later minus earlier) for a few configurations, else each against the first.
    for (std::size_t i = 0; i < configs.size(); ++i)
      for (std::size_t j = i + 1; j < configs.size(); ++j)
        if (configs.size() <= 4 || i == 0) compare.emplace_back(configs[i], configs[j]);
  }
  return compare;
}

}  // namespace

Study Study::load(const fs::path& file, const LoadOptions& options) {
  const YamlReader y(
      file,
      [](const std::string& m) {
        std::string msg = m;
        const std::string ignored = "unknown key ignored";
        if (const auto p = msg.find(ignored); p != std::string::npos)
          msg.replace(p, ignored.size(), "unknown key");
        throw InputError(msg);
      },
      "study");
  const YAML::Node& root = y.root();
  y.check_keys(root, "",
               {"name", "description", "results", "cache", "dataset", "simulate", "run", "manifest",
                "configurations", "seeds", "replicates", "sweep", "compare", "interval",
                "confidence", "resamples", "experiment", "keep_datasets"});
  Study s;
  s.file_ = fs::absolute(file).lexically_normal();
  s.dir_ = s.file_.parent_path();
  Loader L{y, s.dir_};

  s.name_ = file.stem().string();
  if (auto v = YamlReader::get(root, "name"); v.IsDefined()) s.name_ = y.text(v, "name");
  if (auto v = YamlReader::get(root, "description"); v.IsDefined())
    s.description_ = y.text(v, "description");
  s.results_ = s.dir_ / file.stem();
  if (auto v = YamlReader::get(root, "results"); v.IsDefined())
    s.results_ = from_dir(s.dir_, y.text(v, "results"));
  if (!options.results_dir.empty()) s.results_ = options.results_dir;
  s.results_ = fs::absolute(s.results_).lexically_normal();
  s.cache_ = s.results_ / "datasets";
  if (auto v = YamlReader::get(root, "cache"); v.IsDefined())
    s.cache_ = from_dir(s.dir_, y.text(v, "cache"));
  if (!options.cache_dir.empty()) s.cache_ = options.cache_dir;
  s.cache_ = fs::absolute(s.cache_).lexically_normal();

  s.interval_ = read_interval(y, root);

  if (auto v = YamlReader::get(root, "keep_datasets"); v.IsDefined())
    s.keep_datasets_ = y.boolean(v, "keep_datasets");

  // Fixed settings.
  s.fixed_ = fixed_settings(L, root);

  if (auto e = YamlReader::get(root, "experiment"); e.IsDefined()) {
    const ExperimentSpec x = read_experiment(y, root, e, s.dir_);
    const Manifest m = load_manifest(x.dataset, {});
    eval::ExperimentOptions eo;
    eo.only = x.only;
    s.experiment_runs_ = eval::experiment_plan(m, eo);
    if (s.experiment_runs_.empty())
      throw InputError("'" + x.dataset.string() + "': no experiment run to make (no Wheel-IMU?)");
    s.experiment_ = x;
    s.axes_ = experiment_axes(s.experiment_runs_);
    return s;
  }

  // Axes: conditions, replicates, configurations.
  s.axes_ = study_axes(L, root, file);
  s.compare_ = compare_pairs(y, root, s.configurations());
  if (s.job_count() > 10000000)
    throw InputError("'" + file.string() + "': more than 10 million jobs");
  return s;
}

std::vector<std::string> Study::configurations() const {
  for (const auto& a : axes_)
    if (a.role == AxisRole::kConfiguration) {
      std::vector<std::string> v;
      for (const auto& x : a.values) v.push_back(x.label);
      return v;
    }
  return {};
}

std::size_t Study::job_count() const {
  if (experiment_) return experiment_runs_.size();
  std::size_t n = 1;
  for (const auto& a : axes_) n *= a.values.size();
  return n;
}

}  // namespace wheelins::study
