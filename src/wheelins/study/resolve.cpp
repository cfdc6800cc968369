// Job K of a study resolved (spec.hpp): its settings merged by dotted key, the data (a
// manifest, or simulator settings, resolved once per study), references to the data's
// settings, the manifest edits and the run configuration; the jobs on the same data, and
// every job checked.
#include "wheelins/study/spec.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>

#include "wheelins/io/text_util.hpp"
#include "wheelins/io/yaml_reader.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins::study {
namespace fs = std::filesystem;

namespace {

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
      leaf = flow_yaml(v);
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

std::size_t imu_count(const std::string& configuration) {
  if (configuration == "single" || configuration == "single-right") return 1;
  if (configuration == "dual-wheel" || configuration == "body-wheel") return 2;
  return 3;
}

std::string fnv_of_file(const fs::path& p, const std::string& what) {
  io_detail::check_input_file(p, "a " + what);  // a regular file: /dev/zero or a FIFO never ends
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

/// Where a job's messages and relative paths start: "'FILE': job K" and the study's folder.
struct JobContext {
  std::string who;
  fs::path dir;

  fs::path rel(const std::string& p) const {
    return (fs::path(p).is_absolute() ? fs::path(p) : fs::absolute(dir / p)).lexically_normal();
  }
  std::string text_of(const Setting& s) const {
    if (!s.value.IsScalar() || s.value.Scalar().empty())
      throw InputError(who + ": " + s.origin() + ": " + s.key + ": expected a text value");
    return s.value.Scalar();
  }
  std::vector<std::string> list_of(const Setting& s) const {
    std::vector<std::string> out;
    if (s.value.IsScalar()) {
      std::stringstream ss(s.value.Scalar());
      for (std::string item; std::getline(ss, item, ',');)
        if (!item.empty()) out.push_back(item);
    } else if (s.value.IsSequence()) {
      for (const auto& x : s.value) out.push_back(x.as<std::string>());
    } else {
      throw InputError(who + ": " + s.origin() + ": " + s.key + ": expected a list");
    }
    return out;
  }
};

/// The settings of a job's data: a manifest, or simulator settings.
struct DataSettings {
  std::optional<fs::path> dataset;
  std::string dataset_where, sim_where;
  Tree sim_tree;
  std::vector<std::string> sim_configs, sim_sets, faults, disable;
  std::map<std::string, std::string> sim_origin;  // dotted simulator key -> where it was set
  std::optional<std::vector<std::string>> only;
  std::optional<std::string> wheel_noise;
  std::optional<bool> earth_rotation;

  void add_simulate(const Setting& s, const JobContext& cx);
  std::string memo_key() const;
};

/// A `seed` or `simulate.KEY` setting.
void DataSettings::add_simulate(const Setting& s, const JobContext& cx) {
  sim_where = s.origin();
  std::string key = s.key == "seed" ? "seed" : s.key.substr(9);
  const std::string first = split_dotted(key)[0];
  const auto& alias = sim_alias();
  if (key == "config")
    sim_configs.push_back(cx.rel(cx.text_of(s)).string());
  else if (key == "set")
    for (const auto& a : cx.list_of(s)) sim_sets.push_back(a);
  else if (key == "only")
    only = cx.list_of(s);
  else if (key == "disable")
    for (const auto& a : cx.list_of(s)) disable.push_back(a);
  else if (key == "fault" || key == "faults_append")
    for (const auto& a : cx.list_of(s)) faults.push_back(a);
  else if (key == "wheel_noise")
    wheel_noise = cx.text_of(s);
  else if (key == "no_earth_rotation") {
    try {
      earth_rotation = !s.value.as<bool>();
    } catch (const YAML::Exception&) {
      throw InputError(cx.who + ": " + s.origin() +
                       ": simulate.no_earth_rotation: expected true or false");
    }
  } else if (key == "no_ideal" || key == "out" || key == "force" || key == "quiet")
    throw InputError(cx.who + ": " + s.origin() + ": simulate." + key +
                     " is an output choice of `wheelins simulate`, not a setting of the data");
  else {
    if (const auto a = alias.find(first); a != alias.end() && key == first) key = a->second;
    sim_origin[key] = s.origin();
    if (key == "scenario" || key == "speed_file") {
      const std::string p = cx.text_of(s);
      sim_tree.set(split_dotted(key), 0,
                   YAML::Node(key == "scenario" && p == "default" ? p : cx.rel(p).string()));
    } else {
      sim_tree.set(split_dotted(key), 0, s.value);
    }
  }
}

/// The simulator settings as text: equal text, the same data.
std::string DataSettings::memo_key() const {
  std::string key = sim_tree.text() + "\n--";
  for (const auto* list : {&sim_configs, &sim_sets, &faults, &disable}) {
    key += "--\n";
    for (const auto& x : *list) key += x + "\n";
  }
  key += "--" + wheel_noise.value_or("-") + "\n";
  if (only)
    for (const auto& x : *only) key += "only " + x + "\n";
  if (earth_rotation) key += *earth_rotation ? "earth\n" : "no earth\n";
  return key;
}

/// The settings of the data; the others (run settings and manifest edits) go to `later`, in
/// order.
DataSettings read_data_settings(const std::vector<Setting>& settings, const JobContext& cx,
                                std::vector<const Setting*>& later) {
  DataSettings data;
  for (const Setting& s : settings) {
    if (s.key == "dataset") {
      data.dataset = cx.rel(cx.text_of(s));
      if (fs::is_directory(*data.dataset)) *data.dataset /= "manifest.yaml";
      data.dataset_where = s.origin();
      continue;
    }
    if (s.key == "seed" || s.key.rfind("simulate.", 0) == 0) {
      data.add_simulate(s, cx);
      continue;
    }
    later.push_back(&s);  // run settings and manifest edits may refer to the data's settings
  }
  return data;
}

/// The simulator configuration of `data`; messages name `where`.
sim::SimConfig sim_config(const DataSettings& data, const std::string& where) {
  sim::SimConfig c;
  c.write_ideal = false;  // the cache keeps the data a filter reads, not the error-free streams
  for (const auto& f : data.sim_configs) {
    YAML::Node node;
    try {
      node = load_yaml_file(f, "simulator settings");
    } catch (const InputError& e) {
      throw InputError(where + ": " + e.what());
    }
    c.apply_yaml(node, where + " ('" + f + "')");
  }
  if (!data.sim_tree.kids.empty()) {
    // A message about a key names the study's setting that gave it (its key and line).
    const auto origin = [&](const std::string& k) {
      for (std::string p = k;; p = p.substr(0, p.rfind('.'))) {
        if (const auto it = data.sim_origin.find(p); it != data.sim_origin.end())
          return " (set by " + it->second + ")";
        if (p.find('.') == std::string::npos) return std::string();
      }
    };
    c.apply_yaml(parse_yaml(data.sim_tree.text(), where, "simulator settings"), where, origin);
  }
  try {
    for (const auto& a : data.sim_sets) c.apply_setting(a);
    if (data.wheel_noise) {
      c.apply_setting("errors.wheel_accel_noise_m_s_sqrt_h=" + *data.wheel_noise);
      c.effects.insert("wheel_noise");
    }
    for (const auto& f : data.faults) c.faults.push_back(sim::parse_fault_spec(f));
    if (data.only) c.only(*data.only);
    c.disable(data.disable);
    if (data.earth_rotation) c.earth_rotation = *data.earth_rotation;
  } catch (const InputError& e) {
    throw InputError(where + ": " + e.what());
  }
  return c;
}

/// The data simulated by `c`: their canonical text and cache directory.
DatasetSpec simulated_data(sim::SimConfig c) {
  DatasetSpec d;
  d.canonical = "wheelins study dataset 1\n" + c.to_yaml();
  if (c.scenario != "default")
    d.canonical += "scenario_file: " + fnv_of_file(c.scenario, "scenario file") + "\n";
  if (c.speed_file)
    d.canonical += "speed_file: " + fnv_of_file(*c.speed_file, "speed file") + "\n";
  d.cache_name = slug(c.vehicle.preset + "-" + c.profile + "-seed" + std::to_string(c.seed)) +
                 "-" + hash_text(d.canonical);
  d.sim = std::move(c);
  return d;
}

/// A reference "${KEY}" to a setting of the job's data (`values`: dotted key -> value, when
/// simulated).
struct DataRefs {
  const JobContext& cx;
  const DatasetSpec& data;
  const std::map<std::string, std::string>* values;

  std::string operator()(const std::string& ref, const std::string& where) const {
    std::string key = ref == "seed" ? "simulate.seed" : ref;
    if (key.rfind("simulate.", 0) != 0)
      throw InputError(cx.who + ": " + where + ": ${" + ref +
                       "}: only the data's settings can be referred to (simulate.KEY or seed)");
    if (!data.sim)
      throw InputError(cx.who + ": " + where + ": ${" + ref +
                       "}: the job's data are not simulated");
    key = key.substr(9);
    if (const auto a = sim_alias().find(key); a != sim_alias().end()) key = a->second;
    if (key == "wheel_noise") key = "errors.wheel_accel_noise_m_s_sqrt_h";
    const auto it = values->find(key);
    if (it == values->end())
      throw InputError(cx.who + ": " + where + ": ${" + ref +
                       "}: no such simulator setting (a single value)");
    return it->second;
  }
};

/// A job's run settings, manifest edits, `configuration` and `chip`.
struct RunSettings {
  Tree tree;
  std::string edits;
  std::optional<std::string> configuration, chip;
};

/// The run settings and manifest edits of `later`, with references to the data's settings
/// resolved by `lookup`.
RunSettings read_run_settings(
    const std::vector<const Setting*>& later,
    const std::function<std::string(const std::string&, const std::string&)>& lookup,
    const JobContext& cx) {
  RunSettings run;
  for (const Setting* sp : later) {
    const Setting& s0 = *sp;
    const Setting s{s0.key, substitute(s0.value, lookup, s0.where), s0.where, s0.line};
    if (s.key.rfind("run.", 0) == 0) {
      const std::string key = s.key.substr(4);
      if (key == "dataset")
        throw InputError(cx.who + ": " + s.origin() +
                         ": run.dataset: give the data with `dataset` or `simulate`");
      run.tree.set(split_dotted(key), 0, s.value);
    } else if (s.key.rfind("manifest.", 0) == 0) {
      run.edits += "- " + yaml_key(s.key.substr(9)) + ": " + flow_yaml(s.value) + "\n";
    } else if (s.key == "configuration") {
      run.configuration = cx.text_of(s);
    } else if (s.key == "chip") {
      run.chip = cx.text_of(s);
    } else if (s.key == "chips" || s.key == "modules") {
      YAML::Node seq(YAML::NodeType::Sequence);
      for (const auto& c : cx.list_of(s)) seq.push_back(c);
      run.tree.set({s.key}, 0, seq);
    } else {
      throw InputError(cx.who + ": " + s.origin() + ": unknown setting '" + s.key + "'");
    }
  }
  if (const Tree* out = run.tree.find("output")) {
    if (out->leaf)
      throw InputError(cx.who + ": run.output: expected a map (only output.interval_s applies)");
    for (const auto& kv : out->kids)
      if (kv.first != "interval_s")
        throw InputError(cx.who + ": run.output." + kv.first +
                         ": a study writes no trajectories (only output.interval_s applies)");
  }
  return run;
}

/// The run configuration's name (`configuration`, else run.configuration; empty: none), with
/// it and `chip` put into the run settings.
std::string apply_configuration(RunSettings& run, const JobContext& cx) {
  std::string cfg = run.configuration.value_or("");
  if (cfg.empty()) {
    if (const Tree* t = run.tree.find("configuration"); t && t->leaf)
      cfg = cx.text_of(
          {"run.configuration", parse_yaml(*t->leaf, cx.who, "setting"), "run.configuration"});
  }
  if (cfg == "centralized") {
    run.tree.set({"configuration"}, 0, YAML::Node("triple"));
    run.tree.set({"fusion", "centralized"}, 0, YAML::Node(true));
  } else if (run.configuration) {
    run.tree.set({"configuration"}, 0, YAML::Node(cfg));
  }
  if (run.chip) {
    YAML::Node seq(YAML::NodeType::Sequence);
    for (std::size_t i = 0; i < imu_count(cfg.empty() ? "single" : cfg); ++i)
      seq.push_back(*run.chip);
    run.tree.set({"chips"}, 0, seq);
  }
  return cfg;
}

}  // namespace

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
    if (experiment_->calibration != "estimate")
      settings.push_back({"run.calibration", YAML::Node(experiment_->calibration), w});
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
  JobContext cx;
  cx.who = "'" + file_.string() + "': job " + std::to_string(k);
  cx.dir = dir_;
  std::vector<const Setting*> later;
  const DataSettings data = read_data_settings(settings, cx, later);
  // The data.
  DatasetSpec& d = j.dataset;
  const std::map<std::string, std::string>* sim_values = nullptr;  // dotted key -> value
  if (data.dataset && !data.sim_where.empty())
    throw InputError(cx.who + ": both a dataset (" + data.dataset_where +
                     ") and simulator settings (" + data.sim_where +
                     "): a job navigates one or the other");
  if (data.dataset) {
    d.manifest = *data.dataset;
    d.canonical = "manifest: " + data.dataset->string() +
                  "\nmanifest_text: " + fnv_of_file(*data.dataset, "manifest") + "\n";
  } else if (!data.sim_where.empty() || !data.sim_configs.empty()) {
    // The same simulator settings give the same data: resolved once per study (a sweep has
    // many jobs per dataset).
    const std::string memo_key = data.memo_key();
    auto& memo = *sim_memo_;
    if (const auto it = memo.find(memo_key); it != memo.end()) {
      d = it->second.data;
      sim_values = &it->second.values;
    } else {
      const std::string where = cx.who + ": simulator settings";
      d = simulated_data(sim_config(data, where));
      if (memo.size() > 100000) memo.clear();
      SimMemo& m = memo[memo_key];
      m.data = d;
      flatten(parse_yaml(d.sim->to_yaml(), where, "simulator settings"), "", m.values);
      sim_values = &m.values;
    }
  } else {
    throw InputError(cx.who +
                     ": no data: give `dataset: MANIFEST` or simulator settings (`simulate:`)");
  }
  // Run settings and manifest edits, with references to the data's settings resolved.
  RunSettings run = read_run_settings(later, DataRefs{cx, d, sim_values}, cx);

  d.manifest_edits = run.edits;
  // Edits of a manifest that is not ours go into the cache (the data stay where they are).
  if (d.manifest && !run.edits.empty())
    d.cache_name = "edited-" + slug(d.manifest->parent_path().filename().string()) + "-" +
                   hash_text(d.canonical + run.edits);

  // The run configuration.
  const std::string cfg = apply_configuration(run, cx);
  if (!run.tree.has({"output", "interval_s"}))
    run.tree.set({"output", "interval_s"}, 0, YAML::Node("0.05"));
  j.run_yaml = run.tree.text();
  j.configuration = cfg.empty() ? "single" : cfg;
  for (std::size_t i = 0; i < axes_.size(); ++i)
    if (axes_[i].role == AxisRole::kConfiguration) j.configuration = j.labels[i];
  j.canonical = d.canonical + (run.edits.empty() ? "" : "--- manifest edits\n" + run.edits) +
                "--- run\n" + j.run_yaml;
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
