// Loading a study file (spec.hpp): settings by dotted key, the axes and their checks, the
// built-in experiment study, and job K resolved to its dataset and run configuration.
#include "wheelins/study/spec.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>

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

namespace {

// --- Values and settings -------------------------------------------------------

/// A value as one line of flow-style YAML.
std::string flow(const YAML::Node& v) {
  if (!v.IsDefined() || v.IsNull()) return "null";
  YAML::Emitter e;
  e.SetMapFormat(YAML::Flow);
  e.SetSeqFormat(YAML::Flow);
  e << v;
  return e.c_str();
}

/// A map key as YAML: plain when it is a simple name.
std::string yaml_key(const std::string& k) {
  const bool plain = !k.empty() &&
                     std::all_of(k.begin(), k.end(),
                                 [](unsigned char c) {
                                   return std::isalnum(c) || c == '_' || c == '-' || c == '*';
                                 }) &&
                     k[0] != '-' && k[0] != '*';
  if (plain) return k;
  YAML::Emitter e;
  e << YAML::DoubleQuoted << k;
  return e.c_str();
}

/// Settings merged by dotted path: maps merge key by key, anything else replaces. Keys are
/// kept sorted, so the text does not depend on the order the settings came in.
struct Tree {
  std::optional<std::string> leaf;  ///< flow YAML of a value that is not a map
  std::map<std::string, Tree> kids;

  void set(const YAML::Node& v) {
    if (v.IsMap()) {
      leaf.reset();
      for (const auto& kv : v) kids[kv.first.as<std::string>()].set(kv.second);
    } else {
      kids.clear();
      leaf = flow(v);
    }
  }
  void set(const std::vector<std::string>& path, std::size_t i, const YAML::Node& v) {
    if (i == path.size()) return set(v);
    leaf.reset();
    kids[path[i]].set(path, i + 1, v);
  }
  bool has(const std::vector<std::string>& path, std::size_t i = 0) const {
    if (i == path.size()) return true;
    const auto it = kids.find(path[i]);
    return it != kids.end() && it->second.has(path, i + 1);
  }
  const Tree* find(const std::string& k) const {
    const auto it = kids.find(k);
    return it == kids.end() ? nullptr : &it->second;
  }
  void emit(std::string& out, int indent) const {
    for (const auto& [k, t] : kids) {
      out.append(static_cast<std::size_t>(indent), ' ');
      out += yaml_key(k) + ":";
      if (t.leaf)
        out += " " + *t.leaf + "\n";
      else if (t.kids.empty())
        out += " {}\n";
      else {
        out += "\n";
        t.emit(out, indent + 2);
      }
    }
  }
  std::string text() const {
    std::string s;
    emit(s, 0);
    return s;
  }
};

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

std::size_t imu_count(const std::string& configuration) {
  if (configuration == "single" || configuration == "single-right") return 1;
  if (configuration == "dual-wheel" || configuration == "body-wheel") return 2;
  return 3;
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

std::string fnv_of_file(const fs::path& p, const std::string& what) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw InputError("'" + p.string() + "': " + what + " not found or unreadable");
  std::stringstream ss;
  ss << in.rdbuf();
  return hash_text(ss.str()) + " (" + std::to_string(ss.str().size()) + " bytes)";
}

std::string slug(std::string s) {
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') c = '_';
  return s;
}

/// The `wheelins simulate` option names that stand for a scenario.yaml key.
const std::map<std::string, std::string>& sim_alias() {
  static const std::map<std::string, std::string> a = {{"preset", "vehicle.preset"},
                                                       {"terrain", "terrain_slope_deg"},
                                                       {"cruise_speed", "speed_m_s"},
                                                       {"static", "static_s"},
                                                       {"radius", "vehicle.wheel_radius_m"},
                                                       {"track", "vehicle.track_m"},
                                                       {"rate", "rate_hz"},
                                                       {"duration", "duration_s"},
                                                       {"speed", "speed_file"}};
  return a;
}

/// Every scalar of `n` by its dotted key.
void flatten(const YAML::Node& n, const std::string& prefix,
             std::map<std::string, std::string>& out) {
  if (n.IsMap()) {
    for (const auto& kv : n)
      flatten(kv.second, prefix + (prefix.empty() ? "" : ".") + kv.first.as<std::string>(), out);
  } else if (n.IsScalar()) {
    out[prefix] = n.Scalar();
  }
}

/// `v` with every reference "${KEY}", "${KEY}*N" or "${KEY}/N" (a whole text value, also
/// inside lists and maps) replaced by the value `lookup` gives (times or over N).
YAML::Node substitute(
    const YAML::Node& v,
    const std::function<std::string(const std::string&, const std::string&)>& lookup,
    const std::string& where) {
  if (v.IsSequence()) {
    YAML::Node out(YAML::NodeType::Sequence);
    for (const auto& x : v) out.push_back(substitute(x, lookup, where));
    return out;
  }
  if (v.IsMap()) {
    YAML::Node out(YAML::NodeType::Map);
    for (const auto& kv : v) out[kv.first.as<std::string>()] = substitute(kv.second, lookup, where);
    return out;
  }
  if (!v.IsScalar() || v.Scalar().find("${") == std::string::npos) return YAML::Clone(v);
  // "${KEY}" [*|/ NUMBER], blanks allowed around the parts.
  const std::string text = v.Scalar();
  auto bad = [&]() {
    return InputError(where + ": '" + text +
                      "': a reference is a whole value: ${KEY}, ${KEY}*N or ${KEY}/N");
  };
  auto trim = [](std::string t) {
    while (!t.empty() && std::isspace(static_cast<unsigned char>(t.front()))) t.erase(t.begin());
    while (!t.empty() && std::isspace(static_cast<unsigned char>(t.back()))) t.pop_back();
    return t;
  };
  const std::string t = trim(text);
  const auto close = t.find('}');
  if (t.rfind("${", 0) != 0 || close == std::string::npos) throw bad();
  const std::string key = t.substr(2, close - 2);
  if (key.empty() || !std::all_of(key.begin(), key.end(), [](unsigned char c) {
        return std::isalnum(c) || c == '_' || c == '.' || c == '-';
      }))
    throw bad();
  const std::string rest = trim(t.substr(close + 1));
  const std::string value = lookup(key, where);
  if (rest.empty()) return YAML::Node(value);
  const char op = rest[0];
  const auto f = io_detail::parse_double(rest.substr(1));
  if ((op != '*' && op != '/') || !f) throw bad();
  const auto x = io_detail::parse_double(value);
  if (!x)
    throw InputError(where + ": '" + text + "': " + key + " = '" + value + "' is not a number");
  return YAML::Node(io_detail::format_double(op == '*' ? *x * *f : *x / *f));
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
  static std::atomic<unsigned> counter{0};
  // Through a file, so that the code that reads run-configuration files reads it (every
  // key it knows, now and later, works in a study; its messages name `where`).
  const fs::path tmp =
      fs::temp_directory_path() / ("wheelins-study-run-" + std::to_string(::getpid()) + "-" +
                                   std::to_string(counter++) + ".yaml");
  {
    std::ofstream out(tmp, std::ios::binary);
    out << "dataset: " << flow(YAML::Node(manifest.string())) << "\n" << run_yaml;
    if (!out) throw InputError("'" + tmp.string() + "': cannot write a temporary file");
  }
  const std::string quoted = "'" + tmp.string() + "'";
  auto rename_file = [&](std::string msg) {
    for (std::size_t p; (p = msg.find(quoted)) != std::string::npos;)
      msg.replace(p, quoted.size(), where);
    const std::string ignored = "unknown key ignored";
    if (const auto p = msg.find(ignored); p != std::string::npos)
      msg.replace(p, ignored.size(), "unknown key");
    return msg;
  };
  RunConfig cfg;
  try {
    cfg = load_run_config(tmp, [&](const std::string& m) { throw InputError(rename_file(m)); });
  } catch (const InputError& e) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw InputError(rename_file(e.what()));
  }
  std::error_code ec;
  fs::remove(tmp, ec);
  return cfg;
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

  /// A value of a setting key as given (paths are resolved later).
  Setting setting(const std::string& key, const YAML::Node& v, const std::string& where) const {
    if (!is_setting_key(key)) {
      fail(where,
           "'" + key +
               "' is not a setting: expected simulate.KEY, run.KEY, manifest.KEY, "
               "dataset, seed, configuration, chips, chip or modules" +
               closest(key, special_keys()),
           &v);
    }
    return {key, YAML::Clone(v), where};
  }

  /// A map of settings: dotted keys (or, inside `simulate:`, `run:`, `manifest:`, plain keys).
  std::vector<Setting> settings_map(const YAML::Node& m, const std::string& where,
                                    const std::string& prefix = "") const {
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
  std::vector<YAML::Node> values(const YAML::Node& v, const std::string& where) const {
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

  static std::string label_of(const YAML::Node& v) { return v.IsScalar() ? v.Scalar() : flow(v); }

  /// `key: [values]` (a list axis of one setting) or `name: {label: {settings}, ...}`.
  Axis axis(const std::string& name, const YAML::Node& v, const std::string& where,
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

  std::vector<Axis> axes(const YAML::Node& m, const std::string& where, AxisRole role) const {
    std::vector<Axis> out;
    if (!m.IsDefined() || m.IsNull()) return out;
    y.require_map(m, where);
    for (const auto& kv : m) {
      const std::string k = kv.first.as<std::string>();
      out.push_back(axis(k, kv.second, YamlReader::join(where, k), role));
    }
    return out;
  }

  Axis configurations(const YAML::Node& v) const {
    const std::string where = "configurations";
    if (!v.IsSequence() || v.size() == 0) fail(where, "expected a list of configurations", &v);
    Axis a;
    a.name = "configuration";
    a.role = AxisRole::kConfiguration;
    const auto& choices = configuration_choices();
    auto check_name = [&](const std::string& c, const std::string& w, const YAML::Node& at) {
      if (std::find(choices.begin(), choices.end(), c) == choices.end()) {
        std::string list;
        for (const auto& n : choices) list += (list.empty() ? "" : ", ") + n;
        fail(w, "unknown configuration '" + c + "' (known: " + list + ")" + closest(c, choices),
             &at);
      }
    };
    for (std::size_t i = 0; i < v.size(); ++i) {
      const YAML::Node e = v[i];
      const std::string w = YamlReader::index_path(where, i);
      AxisValue val;
      if (e.IsScalar()) {
        check_name(e.Scalar(), w, e);
        val.label = e.Scalar();
        val.settings.push_back({"configuration", YAML::Clone(e), w});
      } else if (e.IsMap()) {
        YAML::Node body = YAML::Clone(e);
        if (e["name"]) {
          val.label = y.text(e["name"], w + ".name");
          body.remove("name");
        }
        val.settings = settings_map(body, w);
        for (const auto& s : val.settings) {
          if (s.key.rfind("simulate.", 0) == 0 || s.key.rfind("manifest.", 0) == 0 ||
              s.key == "dataset" || s.key == "seed")
            fail(s.where,
                 "a configuration cannot change the data (" + s.key +
                     "): put it in `sweep` so that configurations compare on the same data",
                 &e);
          if (s.key == "configuration") check_name(label_of(s.value), s.where, e);
        }
        if (val.label.empty()) {
          for (const auto& s : val.settings)
            if (s.key == "configuration") val.label = label_of(s.value);
          if (val.label.empty()) fail(w, "a configuration needs a `name` or a `configuration`", &e);
        }
      } else {
        fail(w, "expected a configuration name or a map {name, configuration, chips, run.KEY: ...}",
             &e);
      }
      a.values.push_back(std::move(val));
    }
    std::set<std::string> labels;
    for (const auto& x : a.values)
      if (!labels.insert(x.label).second)
        fail(where, "the configuration '" + x.label + "' appears twice", &v);
    return a;
  }
};

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
      flow(YAML::Node(e.dataset.string())) + "\n";
  if (!e.only.empty()) {
    s += "  only: [";
    for (std::size_t i = 0; i < e.only.size(); ++i) s += (i ? ", " : "") + e.only[i];
    s += "]\n";
  }
  s += "  speed: " + e.speed + "\n";
  if (e.duration > 0) s += "  duration_s: " + io_detail::format_double(e.duration) + "\n";
  return s;
}

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
  auto rel = [&](const std::string& p) {
    return fs::path(p).is_absolute() ? fs::path(p) : s.dir_ / p;
  };

  s.name_ = file.stem().string();
  if (auto v = YamlReader::get(root, "name"); v.IsDefined()) s.name_ = y.text(v, "name");
  if (auto v = YamlReader::get(root, "description"); v.IsDefined())
    s.description_ = y.text(v, "description");
  s.results_ = s.dir_ / file.stem();
  if (auto v = YamlReader::get(root, "results"); v.IsDefined())
    s.results_ = rel(y.text(v, "results"));
  if (!options.results_dir.empty()) s.results_ = options.results_dir;
  s.results_ = fs::absolute(s.results_).lexically_normal();
  s.cache_ = s.results_ / "datasets";
  if (auto v = YamlReader::get(root, "cache"); v.IsDefined()) s.cache_ = rel(y.text(v, "cache"));
  if (!options.cache_dir.empty()) s.cache_ = options.cache_dir;
  s.cache_ = fs::absolute(s.cache_).lexically_normal();

  if (auto v = YamlReader::get(root, "interval"); v.IsDefined()) {
    try {
      s.interval_.method = interval_method_from_name(y.text(v, "interval"));
    } catch (const InputError& e) {
      y.fail("interval", e.what(), &v);
    }
  }
  if (auto v = YamlReader::get(root, "confidence"); v.IsDefined()) {
    s.interval_.confidence = y.number(v, "confidence");
    if (!(s.interval_.confidence > 0.5 && s.interval_.confidence < 1.0))
      y.fail("confidence", "must be in (0.5, 1), e.g. 0.95", &v);
  }
  if (auto v = YamlReader::get(root, "resamples"); v.IsDefined()) {
    const double r = y.number(v, "resamples");
    if (r != std::floor(r) || r < 100 || r > 1e7)
      y.fail("resamples", "a whole number in [100, 1e7]", &v);
    s.interval_.resamples = static_cast<int>(r);
  }

  if (auto v = YamlReader::get(root, "keep_datasets"); v.IsDefined())
    s.keep_datasets_ = y.boolean(v, "keep_datasets");

  // Fixed settings.
  if (auto v = YamlReader::get(root, "dataset"); v.IsDefined())
    s.fixed_.push_back(L.setting("dataset", v, "dataset"));
  for (const char* ns : {"simulate", "run", "manifest"})
    if (auto v = root[ns]; v.IsDefined() && !v.IsNull())
      for (auto& x : L.settings_map(v, ns, std::string(ns) + ".")) s.fixed_.push_back(std::move(x));

  if (auto e = YamlReader::get(root, "experiment"); e.IsDefined()) {
    for (const char* k : {"sweep", "seeds", "replicates", "configurations", "simulate", "dataset",
                          "manifest", "compare"})
      if (YamlReader::get(root, k).IsDefined())
        y.fail(k, "not with `experiment` (the built-in study fixes its runs)", &e);
    y.require_map(e, "experiment");
    y.check_keys(e, "experiment", {"dataset", "only", "speed", "duration_s"});
    ExperimentSpec x;
    x.dataset = rel(y.text(y.required(e, "experiment", "dataset"), "experiment.dataset"));
    if (fs::is_directory(x.dataset)) x.dataset /= "manifest.yaml";
    if (auto v = YamlReader::get(e, "only"); v.IsDefined())
      x.only = y.text_list(v, "experiment.only");
    for (const auto& o : x.only)
      if (o != "single" && o != "dual-wheel" && o != "body-wheel" && o != "triple" &&
          o != "centralized")
        y.fail("experiment.only",
               "unknown configuration '" + o +
                   "' (single, dual-wheel, body-wheel, triple, centralized)",
               &e);
    if (auto v = YamlReader::get(e, "speed"); v.IsDefined())
      x.speed = y.choice<std::string>(v, "experiment.speed", {{"mean", "mean"}, {"own", "own"}});
    if (auto v = YamlReader::get(e, "duration_s"); v.IsDefined()) {
      x.duration = y.number(v, "experiment.duration_s");
      if (x.duration < 0) y.fail("experiment.duration_s", "must be >= 0 (0: all data)", &v);
    }
    const Manifest m = load_manifest(x.dataset, {});
    eval::ExperimentOptions eo;
    eo.only = x.only;
    s.experiment_runs_ = eval::experiment_plan(m, eo);
    if (s.experiment_runs_.empty())
      throw InputError("'" + x.dataset.string() + "': no experiment run to make (no Wheel-IMU?)");
    s.experiment_ = x;
    // Axes for the labels: the configuration column and the chips as the replicate.
    Axis cfg{"configuration", AxisRole::kConfiguration, {}},
        chips{"chips", AxisRole::kReplicate, {}};
    for (const auto& r : s.experiment_runs_) {
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
    s.axes_ = {std::move(chips), std::move(cfg)};
    return s;
  }

  // Axes: conditions, replicates, configurations.
  for (auto& a : L.axes(root["sweep"], "sweep", AxisRole::kCondition))
    s.axes_.push_back(std::move(a));
  if (auto v = root["seeds"]; v.IsDefined() && !v.IsNull()) {
    Axis a = L.axis("seed", v, "seeds", AxisRole::kReplicate);
    s.axes_.push_back(std::move(a));
  }
  for (auto& a : L.axes(root["replicates"], "replicates", AxisRole::kReplicate))
    s.axes_.push_back(std::move(a));
  if (auto v = YamlReader::get(root, "configurations"); v.IsDefined())
    s.axes_.push_back(L.configurations(v));

  {
    std::set<std::string> names;
    for (const auto& a : s.axes_)
      if (!names.insert(a.name).second)
        throw InputError("'" + file.string() + "': two axes are called '" + a.name +
                         "' (name one of them: a map of named variants)");
  }
  const auto configs = s.configurations();
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
      s.compare_.emplace_back(pair[0], pair[1]);
    }
  } else if (configs.size() >= 2) {
    // Every pair (later minus earlier) for a few configurations, else each against the first.
    for (std::size_t i = 0; i < configs.size(); ++i)
      for (std::size_t j = i + 1; j < configs.size(); ++j)
        if (configs.size() <= 4 || i == 0) s.compare_.emplace_back(configs[i], configs[j]);
  }
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

Job Study::job(std::size_t k) const {
  const std::lock_guard<std::mutex> lock(*mutex_);
  if (k >= job_count())
    throw InputError("job " + std::to_string(k) + ": the study '" + file_.string() +
                     "' has jobs 0.." + std::to_string(job_count() - 1));
  std::vector<std::size_t> choice(axes_.size());
  std::vector<Setting> settings = fixed_;
  if (experiment_) {
    const eval::ExperimentRun& r = experiment_runs_[k];
    const std::string c = r.centralized ? "centralized" : r.configuration;
    const std::string l =
        r.configuration == "single" ? std::string(r.side == "left" ? "L" : "R") + r.label : r.label;
    for (std::size_t i = 0; i < axes_[0].values.size(); ++i)
      if (axes_[0].values[i].label == l) choice[0] = i;
    for (std::size_t i = 0; i < axes_[1].values.size(); ++i)
      if (axes_[1].values[i].label == c) choice[1] = i;
    const std::string w = "experiment";
    YAML::Node modules(YAML::NodeType::Sequence);
    for (const auto& m : r.modules) modules.push_back(m);
    settings.insert(settings.begin(), {"dataset", YAML::Node(experiment_->dataset.string()), w});
    settings.insert(settings.begin() + 1, {"run.fusion.speed", YAML::Node(experiment_->speed), w});
    if (experiment_->duration > 0)
      settings.insert(
          settings.begin() + 2,
          {"run.duration_s", YAML::Node(io_detail::format_double(experiment_->duration)), w});
    settings.push_back({"modules", modules, w});
    settings.push_back({"run.fusion.centralized", YAML::Node(r.centralized), w});
    Job j = resolve(k, choice, settings);
    j.keep_series = r.figure;
    j.experiment_run = r;
    j.canonical += "keep_series: " + std::string(r.figure ? "true" : "false") + "\n";
    j.key = hash_text(j.canonical);
    return j;
  }
  std::size_t rest = k;
  for (std::size_t i = axes_.size(); i-- > 0;) {
    choice[i] = rest % axes_[i].values.size();
    rest /= axes_[i].values.size();
  }
  for (std::size_t i = 0; i < axes_.size(); ++i)
    for (const auto& st : axes_[i].values[choice[i]].settings) settings.push_back(st);
  return resolve(k, choice, settings);
}

Job Study::resolve(std::size_t k, const std::vector<std::size_t>& choice,
                   const std::vector<Setting>& settings) const {
  Job j;
  j.index = k;
  j.choice = choice;
  for (std::size_t i = 0; i < axes_.size(); ++i)
    j.labels.push_back(axes_[i].values[choice[i]].label);
  const std::string who = "'" + file_.string() + "': job " + std::to_string(k);
  auto rel = [&](const std::string& p) {
    return (fs::path(p).is_absolute() ? fs::path(p) : fs::absolute(dir_ / p)).lexically_normal();
  };
  auto text_of = [&](const Setting& s) {
    if (!s.value.IsScalar() || s.value.Scalar().empty())
      throw InputError(who + ": " + s.where + ": " + s.key + ": expected a text value");
    return s.value.Scalar();
  };
  auto list_of = [&](const Setting& s) {
    std::vector<std::string> out;
    if (s.value.IsScalar()) {
      std::stringstream ss(s.value.Scalar());
      for (std::string item; std::getline(ss, item, ',');)
        if (!item.empty()) out.push_back(item);
    } else if (s.value.IsSequence()) {
      for (const auto& x : s.value) out.push_back(x.as<std::string>());
    } else {
      throw InputError(who + ": " + s.where + ": " + s.key + ": expected a list");
    }
    return out;
  };

  std::optional<fs::path> dataset;
  std::string dataset_where, sim_where;
  Tree sim_tree, run_tree;
  std::vector<std::string> sim_configs, sim_sets, faults, disable;
  std::optional<std::vector<std::string>> only;
  std::optional<std::string> wheel_noise;
  std::optional<bool> earth_rotation;
  std::string edits;
  std::optional<std::string> configuration, chip;
  std::vector<const Setting*> later;
  for (const Setting& s : settings) {
    if (s.key == "dataset") {
      dataset = rel(text_of(s));
      if (fs::is_directory(*dataset)) *dataset /= "manifest.yaml";
      dataset_where = s.where;
      continue;
    }
    if (s.key == "seed" || s.key.rfind("simulate.", 0) == 0) {
      sim_where = s.where;
      std::string key = s.key == "seed" ? "seed" : s.key.substr(9);
      const std::string first = split_dotted(key)[0];
      const auto& alias = sim_alias();
      if (key == "config")
        sim_configs.push_back(rel(text_of(s)).string());
      else if (key == "set")
        for (const auto& a : list_of(s)) sim_sets.push_back(a);
      else if (key == "only")
        only = list_of(s);
      else if (key == "disable")
        for (const auto& a : list_of(s)) disable.push_back(a);
      else if (key == "fault" || key == "faults_append")
        for (const auto& a : list_of(s)) faults.push_back(a);
      else if (key == "wheel_noise")
        wheel_noise = text_of(s);
      else if (key == "no_earth_rotation") {
        try {
          earth_rotation = !s.value.as<bool>();
        } catch (const YAML::Exception&) {
          throw InputError(who + ": " + s.where +
                           ": simulate.no_earth_rotation: expected true or false");
        }
      } else if (key == "no_ideal" || key == "out" || key == "force" || key == "quiet")
        throw InputError(who + ": " + s.where + ": simulate." + key +
                         " is an output choice of `wheelins simulate`, not a setting of the data");
      else {
        if (const auto a = alias.find(first); a != alias.end() && key == first) key = a->second;
        if (key == "scenario" || key == "speed_file") {
          const std::string p = text_of(s);
          sim_tree.set(split_dotted(key), 0,
                       YAML::Node(key == "scenario" && p == "default" ? p : rel(p).string()));
        } else {
          sim_tree.set(split_dotted(key), 0, s.value);
        }
      }
      continue;
    }
    later.push_back(&s);  // run settings and manifest edits may refer to the data's settings
  }
  // The data.
  DatasetSpec& d = j.dataset;
  const std::map<std::string, std::string>* sim_values = nullptr;  // dotted key -> value
  if (dataset && !sim_where.empty())
    throw InputError(who + ": both a dataset (" + dataset_where + ") and simulator settings (" +
                     sim_where + "): a job navigates one or the other");
  if (dataset) {
    d.manifest = *dataset;
    d.canonical = "manifest: " + dataset->string() +
                  "\nmanifest_text: " + fnv_of_file(*dataset, "manifest") + "\n";
  } else if (!sim_where.empty() || !sim_configs.empty()) {
    // The same simulator settings give the same data: resolved once per study (a sweep has
    // many jobs per dataset).
    std::string memo_key = sim_tree.text() + "\n--";
    for (const auto* list : {&sim_configs, &sim_sets, &faults, &disable}) {
      memo_key += "--\n";
      for (const auto& x : *list) memo_key += x + "\n";
    }
    memo_key += "--" + wheel_noise.value_or("-") + "\n";
    if (only)
      for (const auto& x : *only) memo_key += "only " + x + "\n";
    if (earth_rotation) memo_key += *earth_rotation ? "earth\n" : "no earth\n";
    auto& memo = *sim_memo_;
    if (const auto it = memo.find(memo_key); it != memo.end()) {
      d = it->second.data;
      sim_values = &it->second.values;
    } else {
      sim::SimConfig c;
      c.write_ideal = false;  // the cache keeps the data a filter reads, not the error-free streams
      const std::string where = who + ": simulator settings";
      for (const auto& f : sim_configs) {
        YAML::Node node;
        try {
          node = YAML::LoadFile(f);
        } catch (const YAML::Exception& e) {
          throw InputError(where + ": '" + f + "': " + e.what());
        }
        c.apply_yaml(node, where + " ('" + f + "')");
      }
      if (!sim_tree.kids.empty()) {
        YAML::Node node;
        try {
          node = YAML::Load(sim_tree.text());
        } catch (const YAML::Exception& e) {
          throw InputError(where + ": " + e.what());
        }
        c.apply_yaml(node, where);
      }
      try {
        for (const auto& a : sim_sets) c.apply_setting(a);
        if (wheel_noise) {
          c.apply_setting("errors.wheel_accel_noise_m_s_sqrt_h=" + *wheel_noise);
          c.effects.insert("wheel_noise");
        }
        for (const auto& f : faults) c.faults.push_back(sim::parse_fault_spec(f));
        if (only) c.only(*only);
        c.disable(disable);
        if (earth_rotation) c.earth_rotation = *earth_rotation;
      } catch (const InputError& e) {
        throw InputError(where + ": " + e.what());
      }
      d.canonical = "wheelins study dataset 1\n" + c.to_yaml();
      if (c.scenario != "default")
        d.canonical += "scenario_file: " + fnv_of_file(c.scenario, "scenario file") + "\n";
      if (c.speed_file)
        d.canonical += "speed_file: " + fnv_of_file(*c.speed_file, "speed file") + "\n";
      d.cache_name = slug(c.vehicle.preset + "-" + c.profile + "-seed" + std::to_string(c.seed)) +
                     "-" + hash_text(d.canonical);
      d.sim = std::move(c);
      if (memo.size() > 100000) memo.clear();
      SimMemo& m = memo[memo_key];
      m.data = d;
      flatten(YAML::Load(d.sim->to_yaml()), "", m.values);
      sim_values = &m.values;
    }
  } else {
    throw InputError(who +
                     ": no data: give `dataset: MANIFEST` or simulator settings (`simulate:`)");
  }
  // Run settings and manifest edits, with references to the data's settings resolved.
  auto lookup = [&](const std::string& ref, const std::string& where) -> std::string {
    std::string key = ref == "seed" ? "simulate.seed" : ref;
    if (key.rfind("simulate.", 0) != 0)
      throw InputError(who + ": " + where + ": ${" + ref +
                       "}: only the data's settings can be referred to (simulate.KEY or seed)");
    if (!d.sim)
      throw InputError(who + ": " + where + ": ${" + ref + "}: the job's data are not simulated");
    key = key.substr(9);
    if (const auto a = sim_alias().find(key); a != sim_alias().end()) key = a->second;
    if (key == "wheel_noise") key = "errors.wheel_accel_noise_m_s_sqrt_h";
    const auto it = sim_values->find(key);
    if (it == sim_values->end())
      throw InputError(who + ": " + where + ": ${" + ref +
                       "}: no such simulator setting (a single value)");
    return it->second;
  };
  for (const Setting* sp : later) {
    const Setting& s0 = *sp;
    const Setting s{s0.key, substitute(s0.value, lookup, s0.where), s0.where};
    if (s.key.rfind("run.", 0) == 0) {
      const std::string key = s.key.substr(4);
      if (key == "dataset")
        throw InputError(who + ": " + s.where +
                         ": run.dataset: give the data with `dataset` or `simulate`");
      run_tree.set(split_dotted(key), 0, s.value);
    } else if (s.key.rfind("manifest.", 0) == 0) {
      edits += "- " + yaml_key(s.key.substr(9)) + ": " + flow(s.value) + "\n";
    } else if (s.key == "configuration") {
      configuration = text_of(s);
    } else if (s.key == "chip") {
      chip = text_of(s);
    } else if (s.key == "chips" || s.key == "modules") {
      YAML::Node seq(YAML::NodeType::Sequence);
      for (const auto& c : list_of(s)) seq.push_back(c);
      run_tree.set({s.key}, 0, seq);
    } else {
      throw InputError(who + ": " + s.where + ": unknown setting '" + s.key + "'");
    }
  }
  if (const Tree* out = run_tree.find("output")) {
    if (out->leaf)
      throw InputError(who + ": run.output: expected a map (only output.interval_s applies)");
    for (const auto& kv : out->kids)
      if (kv.first != "interval_s")
        throw InputError(who + ": run.output." + kv.first +
                         ": a study writes no trajectories (only output.interval_s applies)");
  }

  d.manifest_edits = edits;
  // Edits of a manifest that is not ours go into the cache (the data stay where they are).
  if (d.manifest && !edits.empty())
    d.cache_name = "edited-" + slug(d.manifest->parent_path().filename().string()) + "-" +
                   hash_text(d.canonical + edits);

  // The run configuration.
  std::string cfg = configuration.value_or("");
  if (cfg.empty()) {
    if (const Tree* t = run_tree.find("configuration"); t && t->leaf)
      cfg = YAML::Load(*t->leaf).as<std::string>();
  }
  if (cfg == "centralized") {
    run_tree.set({"configuration"}, 0, YAML::Node("triple"));
    run_tree.set({"fusion", "centralized"}, 0, YAML::Node(true));
  } else if (configuration) {
    run_tree.set({"configuration"}, 0, YAML::Node(cfg));
  }
  if (chip) {
    YAML::Node seq(YAML::NodeType::Sequence);
    for (std::size_t i = 0; i < imu_count(cfg.empty() ? "single" : cfg); ++i) seq.push_back(*chip);
    run_tree.set({"chips"}, 0, seq);
  }
  if (!run_tree.has({"output", "interval_s"}))
    run_tree.set({"output", "interval_s"}, 0, YAML::Node("0.05"));
  j.run_yaml = run_tree.text();
  j.configuration = cfg.empty() ? "single" : cfg;
  for (std::size_t i = 0; i < axes_.size(); ++i)
    if (axes_[i].role == AxisRole::kConfiguration) j.configuration = j.labels[i];
  j.canonical = d.canonical + (edits.empty() ? "" : "--- manifest edits\n" + edits) + "--- run\n" +
                j.run_yaml;
  j.key = hash_text(j.canonical);
  return j;
}

std::vector<std::size_t> Study::data_siblings(std::size_t k) const {
  if (experiment_) return {k};
  auto changes_data = [](const Axis& a) {
    for (const auto& v : a.values)
      for (const auto& st : v.settings)
        if (st.key == "dataset" || st.key == "seed" || st.key.rfind("simulate.", 0) == 0)
          return true;
    return false;
  };
  std::vector<std::size_t> choice(axes_.size());
  std::size_t rest = k;
  for (std::size_t i = axes_.size(); i-- > 0;) {
    choice[i] = rest % axes_[i].values.size();
    rest /= axes_[i].values.size();
  }
  std::vector<std::size_t> free;
  for (std::size_t i = 0; i < axes_.size(); ++i)
    if (!changes_data(axes_[i])) free.push_back(i);
  std::vector<std::size_t> out;
  // Every combination of the free axes, the others as in job k.
  for (std::size_t a : free) choice[a] = 0;
  for (bool more = true; more;) {
    std::size_t index = 0;
    for (std::size_t i = 0; i < axes_.size(); ++i)
      index = index * axes_[i].values.size() + choice[i];
    out.push_back(index);
    more = false;
    for (std::size_t f = free.size(); f-- > 0;) {
      const std::size_t a = free[f];
      if (++choice[a] < axes_[a].values.size()) {
        more = true;
        break;
      }
      choice[a] = 0;
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<Job> Study::check_all() const {
  std::vector<Job> jobs;
  const std::size_t n = job_count();
  jobs.reserve(n);
  std::set<std::string> checked;
  for (std::size_t k = 0; k < n; ++k) {
    jobs.push_back(job(k));
    const Job& j = jobs.back();
    if (checked.insert(j.run_yaml).second)
      check_run_yaml(j.run_yaml, "'" + file_.string() + "': run settings of job " +
                                     std::to_string(k) + " (" + j.describe() + ")");
  }
  return jobs;
}

}  // namespace wheelins::study
