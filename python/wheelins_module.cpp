// The Python module's native part, wheelins._core (pybind11): the simulator, a run
// (the same request `wheelins run` makes, evaluated the same way), the evaluation of a
// trajectory (`wheelins evaluate`), and a navigator fed sample by sample through the
// code path of a run (io/imu_file.hpp imu_sample(), fusion/navigator.hpp). InputError
// becomes wheelins.InputError (a ValueError) with the CLI's message. The Python layer
// on top is python/wheelins/__init__.py.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <cmath>
#include <limits>
#include <optional>
#include <thread>

#include "wheelins/eval/metrics.hpp"
#include "wheelins/eval/run_evaluation.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/io/truth.hpp"
#include "wheelins/run/calibration.hpp"
#include "wheelins/run/input_checks.hpp"
#include "wheelins/run/presets.hpp"
#include "wheelins/run/push_session.hpp"
#include "wheelins/run/run.hpp"
#include "wheelins/run/run_config.hpp"
#include "wheelins/run/run_options.hpp"
#include "wheelins/run/noise_report.hpp"
#include "wheelins/sim/simulator.hpp"
#include "wheelins/util/interrupt.hpp"

namespace py = pybind11;
using namespace wheelins;

namespace {

/// The records as a (n, columns) array in the trajectory CSV's units and header order.
py::array_t<double> table(const std::vector<TrajectoryRecord>& recs) {
  const std::size_t nc = trajectory_csv_header().size();
  py::array_t<double> a({recs.size(), nc});
  double* p = a.mutable_data();
  for (const auto& r : recs) {
    trajectory_csv_values(r, p);
    p += nc;
  }
  return a;
}

py::dict stats_dict(const NavigatorStats& s) {
  py::dict d;
  d["samples"] = s.samples;
  d["epochs"] = s.epochs;
  d["velocity_updates"] = s.velocity_updates;
  d["velocity_rejected"] = s.velocity_rejected;
  d["position_updates"] = s.position_updates;
  d["position_rejected"] = s.position_rejected;
  d["records"] = s.records;
  d["t_start"] = s.t_start;
  d["t_end"] = s.t_end;
  d["max_velocity_test_ratio"] = s.max_velocity_test_ratio;
  d["max_position_test_ratio"] = s.max_position_test_ratio;
  d["covariance_checks"] = s.covariance_checks;
  d["covariance_not_pd"] = s.covariance_not_pd;
  d["max_covariance_asymmetry"] = s.max_covariance_asymmetry;
  return d;
}

/// A YAML document (the reports wheelins writes) as Python objects: maps as dicts, lists
/// as lists, plain scalars as bool, int or float where they read as one, else str.
py::object from_yaml(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Map: {
      py::dict d;
      for (const auto& kv : n) d[py::str(kv.first.as<std::string>())] = from_yaml(kv.second);
      return d;
    }
    case YAML::NodeType::Sequence: {
      py::list l;
      for (const auto& x : n) l.append(from_yaml(x));
      return l;
    }
    case YAML::NodeType::Scalar: {
      const std::string v = n.Scalar();
      if (n.Tag() == "!") return py::str(v);  // quoted
      if (v == "true" || v == "false") return py::bool_(v == "true");
      if (v == "null" || v == "~") return py::none();
      char* end = nullptr;
      const long long i = std::strtoll(v.c_str(), &end, 10);
      if (!v.empty() && *end == '\0') return py::int_(i);
      const double x = std::strtod(v.c_str(), &end);
      if (!v.empty() && *end == '\0') return py::float_(x);
      return py::str(v);
    }
    default:
      return py::none();
  }
}
py::object yaml_dict(const std::string& text) { return from_yaml(YAML::Load(text)); }

/// The fault report as a dict: "events" (t_s, module, detected, action per detection, as
/// faults.csv) and "modules" (each module's counts, as faults.csv's per-module lines).
py::dict faults_dict(const std::vector<FaultEvent>& events, const std::vector<std::string>& names,
                     const std::vector<ModuleFaultStats>& stats) {
  py::list ev;
  for (const FaultEvent& e : events) {
    py::dict d;
    d["t_s"] = e.t;
    d["module"] = e.module;
    d["detected"] = e.what;
    d["action"] = e.action;
    ev.append(d);
  }
  py::dict mods;
  for (std::size_t i = 0; i < stats.size() && i < names.size(); ++i) {
    // faults.csv's per-module columns, in its order.
    static const std::pair<const char*, std::uint64_t ModuleFaultStats::*> counts[] = {
        {"gaps", &ModuleFaultStats::gaps},
        {"saturated_samples", &ModuleFaultStats::saturated_samples},
        {"speed_rejected", &ModuleFaultStats::speed_rejected},
        {"velocity_tests", &ModuleFaultStats::velocity_tests},
        {"velocity_failed", &ModuleFaultStats::velocity_failed},
        {"velocity_rejected", &ModuleFaultStats::velocity_rejected},
        {"isolations", &ModuleFaultStats::isolations},
        {"restarts", &ModuleFaultStats::restarts}};
    py::dict d;
    for (const auto& [key, member] : counts) d[key] = stats[i].*member;
    d["seconds_unused"] = stats[i].seconds_unused;
    mods[py::str(names[i])] = d;
  }
  py::dict out;
  out["events"] = ev;
  out["modules"] = mods;
  return out;
}

/// The command line's words in a message, as a Python caller spells them: the options without
/// a value as their keywords (--force as force=True, --no-data-checks as data_checks=False).
std::string python_message(std::string m) {
  std::vector<std::pair<std::string, std::string>> words = {
      {"use --force to", "use force=True to"}, {"--set '", "setting '"}, {"--set ", "setting "}};
  for (const NamedOption& o : run_named_options())
    if (!o.sets.empty()) words.emplace_back(o.option, o.keyword + (o.keyword_value(true) == o.sets ? "=True" : "=False"));
  for (const auto& [cli, py] : words)
    for (std::size_t at = m.find(cli); at != std::string::npos; at = m.find(cli, at + py.size()))
      m.replace(at, cli.size(), py);
  return m;
}

/// `f()` on a worker thread while this one, holding the GIL every 10 ms, looks for signals:
/// Ctrl-C raises the library's interrupt flag (the run stops at its next block and removes
/// its unfinished output: nothing is left half-written) and KeyboardInterrupt is raised.
template <class F>
auto interruptible(F&& f) -> decltype(f()) {
  clear_interrupt();
  std::optional<decltype(f())> result;
  std::exception_ptr error;
  std::atomic<bool> done{false};
  bool interrupted = false;
  std::thread worker([&] {
    try {
      result.emplace(f());
    } catch (...) {
      error = std::current_exception();
    }
    done = true;
  });
  while (!done) {
    {
      py::gil_scoped_release free;
      for (int k = 0; k < 10 && !done; ++k) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    if (!interrupted && PyErr_CheckSignals() != 0) {
      interrupted = true;
      request_interrupt();
    }
  }
  worker.join();
  clear_interrupt();
  if (interrupted) throw py::error_already_set();  // the KeyboardInterrupt (or the handler's error)
  if (error) std::rethrow_exception(error);
  return std::move(*result);
}

std::optional<std::string> text(const py::object& o) {
  if (o.is_none()) return std::nullopt;
  return py::str(py::module_::import("os").attr("fspath")(o)).cast<std::string>();
}

/// A keyword's value as an option's text: True/False as YAML's, numbers exactly, paths.
std::string keyword_text(const std::string& keyword, const py::handle& v) {
  if (py::isinstance<py::bool_>(v)) return v.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::int_>(v)) return py::str(v).cast<std::string>();
  if (py::isinstance<py::float_>(v)) return py::repr(py::float_(py::reinterpret_borrow<py::object>(v))).cast<std::string>();
  if (py::isinstance<py::str>(v) || py::hasattr(v, "__fspath__")) return *text(py::reinterpret_borrow<py::object>(v));
  if (py::hasattr(v, "__index__")) return py::str(py::int_(py::reinterpret_borrow<py::object>(v))).cast<std::string>();
  if (py::hasattr(v, "__float__"))  // numpy's numbers
    return py::repr(py::float_(py::reinterpret_borrow<py::object>(v))).cast<std::string>();
  throw InputError(keyword + ": expected a number, a text, True or False, got " + py::repr(v).cast<std::string>());
}

/// run()'s and Navigator()'s keywords as `wheelins run`'s options (their names from the run
/// settings' declarations, run/run_options.hpp: run_named_options); None: not given.
std::vector<NamedSetting> keyword_settings(const py::dict& keywords) {
  std::vector<NamedSetting> out;
  for (const auto& [k, v] : keywords) {
    const std::string keyword = py::str(k).cast<std::string>();
    const NamedOption* o = find_named_option(keyword);
    if (!o || o->keyword != keyword) throw py::type_error("unexpected keyword argument '" + keyword + "'");
    if (v.is_none()) continue;
    NamedSetting s{keyword, o->key, {}, false};
    if (!o->sets.empty()) {
      if (!py::isinstance<py::bool_>(v))
        throw InputError(keyword + ": expected True or False, got " + py::repr(v).cast<std::string>());
      const std::optional<std::string> value = o->keyword_value(v.cast<bool>());
      if (!value) continue;
      s.values = {*value};
    } else if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
      s.list = true;
      for (const py::handle item : v) s.values.push_back(keyword_text(keyword, item));
    } else {
      s.values = {keyword_text(keyword, v)};
    }
    out.push_back(std::move(s));
  }
  return out;
}

/// The keywords run() and Navigator() take for the run settings, each with its setting's key.
std::vector<std::pair<std::string, std::string>> run_keywords() {
  std::vector<std::pair<std::string, std::string>> out;
  for (const NamedOption& o : run_named_options()) out.emplace_back(o.keyword, o.key);
  return out;
}

// ----------------------------------------------------------------------------- run

struct RunOutput {
  std::vector<std::string> modules;
  std::vector<TrajectoryRecord> records;
  std::optional<std::string> metrics_json;
  NavigatorStats stats;
  std::string fault_report, noise_report, weights_report, calibration_report;
  std::string noise_yaml, calibration_yaml;  ///< noise.yaml and calibration.yaml's text (empty: not estimated)
  std::vector<FaultEvent> fault_events;
  std::vector<ModuleFaultStats> fault_stats;
  std::vector<WeightRecord> weights;  ///< the reference weights of eq. (8) over time
  std::vector<std::string> files;
  std::string manifest;
  std::vector<double> origin_deg;  ///< the manifest's origin: lat [deg], lon [deg], h [m]
  double wall_seconds = 0.0;
};

RunOutput run(const py::object& config, const py::object& out, bool evaluate, bool progress, const py::dict& keywords,
              const std::vector<std::string>& settings) {
  const RunOverrides s{text(config).value_or(""), keyword_settings(keywords), settings};
  const WarningSink warn = stderr_sink();
  const std::optional<std::string> out_dir = text(out);
  RunRequest req = make_run_request(run_config_with(s, warn), warn);
  req.output_dir = out_dir ? std::filesystem::path(*out_dir) : std::filesystem::path();  // none: nothing written
  req.progress = progress;
  RunOutput o;
  o.modules = req.modules;
  o.manifest = req.manifest.path.string();
  o.origin_deg = {req.manifest.origin.lat / kDeg, req.manifest.origin.lon / kDeg, req.manifest.origin.h};
  // The evaluation `wheelins run` makes, with the same settings (run/evaluation.hpp).
  if (evaluate) req.evaluation = RunEvaluationRequest{};
  req.on_record = [&](const TrajectoryRecord& r) { o.records.push_back(r); };
  const RunResult res = interruptible([&] { return run_navigation(req); });
  if (!res.evaluation_error.empty()) throw InputError(res.evaluation_error);
  if (res.evaluation) o.metrics_json = eval::to_json(*res.evaluation);
  o.stats = res.stats;
  o.fault_report = res.fault_report;
  o.noise_report = res.noise_report;
  o.calibration_report = res.calibration_report;
  o.noise_yaml = noise_report_yaml(res.noise, req.manifest, req.nav.noise.enabled);
  if (!res.calibration_report.empty()) o.calibration_yaml = calibration_yaml(res.calibration, req.manifest);
  o.fault_events = res.fault_events;
  o.fault_stats = res.fault_stats;
  o.weights_report = res.weights_report;
  o.weights = res.weights;
  for (const auto& f : res.files) o.files.push_back(f.string());
  o.wall_seconds = res.wall_seconds;
  return o;
}

// ------------------------------------------------------------------------ evaluate

/// The metrics as `wheelins evaluate --json` writes them and, with `series`, the per-epoch
/// errors as `wheelins evaluate --series` writes them (columns t_s, distance_m, err_n_m,
/// err_e_m, err_d_m, err_h_m, heading_err_deg, sigma_h_m, nees_h).
py::tuple evaluate(const py::object& truth_file, const py::object& trajectory, const std::string& format,
                   const std::string& truth_layout, double segment, double max_gap, bool align,
                   std::optional<std::vector<double>> origin, bool series) {
  const TruthData truth = read_truth(*text(truth_file), truth_layout_from_name(truth_layout));
  TrajectoryData traj;
  if (py::isinstance<RunOutput>(trajectory)) {
    const RunOutput& r = trajectory.cast<const RunOutput&>();
    traj.file = "the run's vehicle solution";
    traj.format = TrajectoryFormat::kCsv;
    traj.has_lla = traj.has_ned = traj.has_velocity = traj.has_roll_pitch = traj.has_heading = traj.has_pos_std = true;
    traj.records = r.records;
  } else {
    const TrajectoryFormat f = trajectory_format_from_name(format);
    if (f == TrajectoryFormat::kKml)
      throw InputError("format kml: KML is written for viewing only and cannot be evaluated");
    traj = read_trajectory(*text(trajectory), f);
  }
  if (traj.records.empty()) throw InputError("'" + traj.file.string() + "': no trajectory records");
  earth::Geodetic o = truth.records.front().lla;
  if (origin) {
    if (origin->size() != 3 || !(std::abs((*origin)[0]) <= 90.0) || !(std::abs((*origin)[1]) <= 180.0))
      throw InputError("origin: expected [lat_deg, lon_deg, h_m] within range");
    o = {(*origin)[0] * kDeg, (*origin)[1] * kDeg, (*origin)[2]};
  }
  eval::EvalOptions opt;
  opt.segment_length = segment;
  opt.max_gap = max_gap;
  opt.align_origin = align;
  const eval::EvalResult res = eval::evaluate(truth, traj, earth::LocalFrame(o), opt);
  if (!series) return py::make_tuple(eval::to_json(res), py::none());
  py::array_t<double> a({res.series.size(), std::size_t(9)});
  for (std::size_t k = 0; k < res.series.size(); ++k) {
    const eval::EpochError& e = res.series[k];
    const double v[9] = {e.t, e.distance, e.err_ned.x(), e.err_ned.y(), e.err_ned.z(), e.err_h,
                         e.heading_err / kDeg, e.sigma_h, e.nees_h};
    for (int c = 0; c < 9; ++c) a.mutable_at(k, c) = v[c];
  }
  return py::make_tuple(eval::to_json(res), a);
}

/// A truth file in the local frame about `origin` (default: its first record): columns
/// t_s, north_m, east_m, down_m, lat_deg, lon_deg, h_m, vn_m_s, ve_m_s, vd_m_s, roll_deg,
/// pitch_deg, heading_deg.
py::array_t<double> read_truth_table(const py::object& file, std::optional<std::vector<double>> origin) {
  const TruthData truth = read_truth(*text(file));
  earth::Geodetic o = truth.records.front().lla;
  if (origin) {
    if (origin->size() != 3) throw InputError("origin: expected [lat_deg, lon_deg, h_m]");
    o = {(*origin)[0] * kDeg, (*origin)[1] * kDeg, (*origin)[2]};
  }
  const earth::LocalFrame frame(o);
  py::array_t<double> a({truth.records.size(), std::size_t(13)});
  for (std::size_t k = 0; k < truth.records.size(); ++k) {
    const TruthRecord& r = truth.records[k];
    const Vec3 p = frame.ned_from_geodetic(r.lla);
    const double v[13] = {r.t, p.x(), p.y(), p.z(), r.lla.lat / kDeg, r.lla.lon / kDeg, r.lla.h, r.v_ned.x(),
                          r.v_ned.y(), r.v_ned.z(), r.rpy.x() / kDeg, r.rpy.y() / kDeg, r.rpy.z() / kDeg};
    for (int c = 0; c < 13; ++c) a.mutable_at(k, c) = v[c];
  }
  return a;
}

// ----------------------------------------------------------------------- simulate

py::dict simulate(const py::object& out, const std::vector<std::string>& settings, bool force, bool progress,
                  bool write_ideal) {
  sim::SimConfig cfg;
  for (const auto& s : settings) cfg.apply_setting(s);
  if (!write_ideal) cfg.write_ideal = false;
  const std::string dir = *text(out);
  const sim::Simulation simulation(cfg);
  const sim::DatasetSummary sum = interruptible([&] { return simulation.write(dir, force, progress); });
  py::dict d;
  d["manifest"] = (std::filesystem::path(dir) / "manifest.yaml").string();
  d["scenario"] = sum.scenario;
  d["duration_s"] = sum.duration;
  d["distance_m"] = sum.distance;
  d["imu_rows"] = sum.imu_rows;
  d["files"] = sum.files;
  d["bytes"] = sum.bytes;
  d["seconds"] = sum.seconds;
  return d;
}

// ---------------------------------------------------------------------- navigator

/// A run fed sample by sample (run/push_session.hpp): the request `wheelins run` makes,
/// without files, the pushed records made into samples as the file reader makes them and
/// passed through the run's input checks, then the RunSession every run goes through.
class StreamNavigator {
 public:
  StreamNavigator(const py::object& config, const py::dict& keywords, double calibration_warmup,
                  const std::vector<std::string>& settings);

  int index_of(const py::object& module) const;

  /// One record of module `module` as its file holds it; false once the duration is reached.
  bool push(const py::object& module, double t, const std::array<double, 3>& gyro, const std::array<double, 3>& accel) {
    ImuRow row;
    row.t = t;
    row.gyro = Vec3(gyro[0], gyro[1], gyro[2]);
    row.accel = Vec3(accel[0], accel[1], accel[2]);
    return run_->push(index_of(module), row);
  }

  void finish() {
    if (!run_->finished()) run_->finish();
  }

  py::object state() const;
  py::array_t<double> covariance(const py::object& module) const;

  const std::vector<std::string>& modules() const { return run_->request().modules; }
  bool navigating() const { return nav().navigating(); }
  py::array_t<double> records() const { return table(records_); }
  std::size_t record_count() const { return records_.size(); }
  py::dict stats() const { return stats_dict(nav().stats()); }
  std::string fault_report() const { return fault_report_text(nav().faults()); }
  py::dict faults() const {
    std::vector<ModuleFaultStats> st;
    for (int i = 0; i < nav().faults().size(); ++i) st.push_back(nav().faults().stats(i));
    return faults_dict(nav().faults().events(), modules(), st);
  }
  /// The noise model now, as noise.yaml's text.
  std::string noise_yaml() const {
    std::vector<ModuleNoiseReport> n;
    for (int i = 0; i < nav().subsystem_count(); ++i) n.push_back(nav().noise_report(i));
    return noise_report_yaml(n, run_->request().manifest, run_->request().nav.noise.enabled);
  }
  /// The warm-up's estimates (calibration.yaml's text; None with the manifest's geometry or
  /// during the warm-up).
  py::object calibration() const {
    if (!run_->calibrated()) return py::none();
    return py::str(calibration_yaml(run_->calibration(), run_->request().manifest));
  }
  py::object calibration_report() const {
    if (!run_->calibrated()) return py::none();
    return py::str(wheelins::calibration_report(run_->calibration()));
  }

 private:
  const Navigator& nav() const { return run_->navigator(); }
  std::vector<TrajectoryRecord> records_;  // before run_: its consumer writes here
  std::unique_ptr<PushSession> run_;
};

StreamNavigator::StreamNavigator(const py::object& config, const py::dict& keywords, double calibration_warmup,
                                 const std::vector<std::string>& settings) {
  // It sees each sample once. "manifest" (the default): the manifest's geometry as it is
  // (a calibrated manifest comes from `wheelins calibrate`). "estimate": the installation
  // geometry estimated from the first `calibration_warmup` seconds after the static period,
  // whose samples are kept and navigated when it ends (docs/python.md).
  py::dict named;
  named["calibration"] = "manifest";
  for (const auto& [k, v] : keywords)
    if (!v.is_none()) named[k] = v;
  const RunOverrides s{text(config).value_or(""), keyword_settings(named), settings};
  const WarningSink warn = stderr_sink();
  RunRequest req = make_run_request(run_config_with(s, warn), warn);
  req.output_dir.clear();
  req.on_record = [this](const TrajectoryRecord& r) { records_.push_back(r); };
  run_ = std::make_unique<PushSession>(std::move(req), calibration_warmup);
}

int StreamNavigator::index_of(const py::object& module) const {
  const std::vector<std::string>& names = run_->request().modules;
  if (py::isinstance<py::int_>(module)) {
    const int i = module.cast<int>();
    if (i < 0 || i >= static_cast<int>(names.size()))
      throw InputError("module index " + std::to_string(i) + " out of range (0.." +
                       std::to_string(names.size() - 1) + ")");
    return i;
  }
  const std::string name = module.cast<std::string>();
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  std::string list;
  for (const auto& m : names) list += (list.empty() ? "" : ", ") + m;
  throw InputError("module '" + name + "' is not navigated (modules: " + list + ")");
}

py::object StreamNavigator::state() const {
  if (!navigating()) return py::none();
  const TrajectoryRecord r = nav().vehicle_record();
  const auto names = trajectory_csv_header();
  std::vector<double> v(names.size());
  trajectory_csv_values(r, v.data());
  py::dict d;
  for (std::size_t k = 0; k < names.size(); ++k) d[py::str(names[k])] = v[k];
  return d;
}

py::array_t<double> StreamNavigator::covariance(const py::object& module) const {
  const int i = index_of(module);
  if (run_->in_warmup()) throw InputError("no covariance during the calibration warm-up (it ends at t = " +
                                          io_detail::format_double(run_->warmup_end()) + " s)");
  if (!nav().navigating()) throw InputError("no covariance before navigation starts (the static period)");
  if (run_->request().nav.fusion.centralized)
    throw InputError("the centralized filter keeps one joint covariance; its per-module blocks are not "
                     "exposed (the state's *_std_* entries are the vehicle's sigmas)");
  const Mat21& P = nav().subsystem(i).ekf().covariance();
  py::array_t<double> a({21, 21});
  for (int r = 0; r < 21; ++r)
    for (int c = 0; c < 21; ++c) a.mutable_at(r, c) = P(r, c);
  return a;
}

// ------------------------------------------------------------------------ bindings

/// InputError as wheelins.InputError (a ValueError), its message in Python's words.
void bind_errors(py::module_& m) {
  static py::exception<InputError> input_error(m, "InputError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      input_error(python_message(e.what()).c_str());
    } catch (const Interrupted& e) {
      PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
    }
  });
}

void bind_formats(py::module_& m) {
  m.def("yaml_dict", &yaml_dict, py::arg("text"), "A YAML report's text as dicts and lists");
  m.def("csv_columns", &trajectory_csv_header, "The trajectory CSV's column names, in order");
}

void bind_run_output(py::module_& m) {
  py::class_<RunOutput>(m, "RunOutput")
      .def_readonly("modules", &RunOutput::modules)
      .def_readonly("metrics_json", &RunOutput::metrics_json)
      .def_readonly("fault_report", &RunOutput::fault_report)
      .def_readonly("noise_report", &RunOutput::noise_report)
      .def_readonly("calibration_report", &RunOutput::calibration_report)
      .def_readonly("noise_yaml", &RunOutput::noise_yaml)
      .def_readonly("calibration_yaml", &RunOutput::calibration_yaml)
      .def_property_readonly("faults", [](const RunOutput& r) { return faults_dict(r.fault_events, r.modules, r.fault_stats); })
      .def_readonly("weights_report", &RunOutput::weights_report)
      .def_property_readonly("weights_table",
                             [](const RunOutput& r) {
                               // rows: t, then one weight per module (weights.csv's columns)
                               const std::size_t n = r.modules.size();
                               py::array_t<double> a({r.weights.size(), n + 1});
                               auto v = a.mutable_unchecked<2>();
                               for (std::size_t i = 0; i < r.weights.size(); ++i) {
                                 v(i, 0) = r.weights[i].t;
                                 for (std::size_t j = 0; j < n; ++j) v(i, j + 1) = r.weights[i].k[j];
                               }
                               return a;
                             })
      .def_readonly("files", &RunOutput::files)
      .def_readonly("manifest", &RunOutput::manifest)
      .def_readonly("origin_deg", &RunOutput::origin_deg)
      .def_readonly("wall_seconds", &RunOutput::wall_seconds)
      .def_property_readonly("stats", [](const RunOutput& r) { return stats_dict(r.stats); })
      .def_property_readonly("table", [](const RunOutput& r) { return table(r.records); });
}

/// run, evaluate, read_truth and simulate (after RunOutput, which run() returns).
void bind_functions(py::module_& m) {
  m.def("run", &run, py::kw_only(), py::arg("config") = py::none(), py::arg("out") = py::none(),
        py::arg("evaluate") = true, py::arg("progress") = false, py::arg("keywords") = py::dict(),
        py::arg("settings") = std::vector<std::string>{});
  m.def("run_keywords", &run_keywords,
        "The run settings' keywords of run() and Navigator(), each with its setting's key (docs/run-config.md)");
  m.def("evaluate", &evaluate, py::arg("truth"), py::arg("trajectory"), py::kw_only(), py::arg("format") = "auto",
        py::arg("truth_layout") = "auto", py::arg("segment") = 100.0, py::arg("max_gap") = 5.0, py::arg("align") = false,
        py::arg("origin") = py::none(), py::arg("series") = false);
  m.def("read_truth", &read_truth_table, py::arg("truth"), py::arg("origin") = py::none());
  m.def("simulate", &simulate, py::arg("out"), py::arg("settings"), py::arg("force") = false, py::arg("progress") = false,
        py::arg("write_ideal") = true);
}

void bind_navigator(py::module_& m) {
  py::class_<StreamNavigator>(m, "Navigator")
      .def(py::init<const py::object&, const py::dict&, double, const std::vector<std::string>&>(), py::kw_only(),
           py::arg("config") = py::none(), py::arg("keywords") = py::dict(), py::arg("calibration_warmup") = 120.0,
           py::arg("settings") = std::vector<std::string>{})
      .def("push", &StreamNavigator::push, py::arg("module"), py::arg("t"), py::arg("gyro"), py::arg("accel"))
      .def("finish", &StreamNavigator::finish)
      .def("covariance", &StreamNavigator::covariance, py::arg("module") = 0)
      .def_property_readonly("state", &StreamNavigator::state)
      .def_property_readonly("modules", &StreamNavigator::modules)
      .def_property_readonly("navigating", &StreamNavigator::navigating)
      .def_property_readonly("table", &StreamNavigator::records)
      .def_property_readonly("record_count", &StreamNavigator::record_count)
      .def_property_readonly("stats", &StreamNavigator::stats)
      .def_property_readonly("fault_report", &StreamNavigator::fault_report)
      .def_property_readonly("faults", &StreamNavigator::faults)
      .def_property_readonly("noise_yaml", &StreamNavigator::noise_yaml)
      .def_property_readonly("calibration", &StreamNavigator::calibration)
      .def_property_readonly("calibration_report", &StreamNavigator::calibration_report);
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "wheelins native core (use the wheelins package)";
  bind_errors(m);
  bind_formats(m);
  bind_run_output(m);
  bind_functions(m);
  bind_navigator(m);
}
