// `wheelins run`: navigate one configuration of a dataset and write its trajectory.
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "cli.hpp"
#include "run_report.hpp"
#include "wheelins/eval/run_evaluation.hpp"
#include "wheelins/fusion/aids/position_constraint/reference_weights.hpp"
#include "wheelins/run/presets.hpp"
#include "wheelins/run/run.hpp"
#include "wheelins/run/run_config.hpp"
#include "wheelins/run/run_options.hpp"
#include "wheelins/io/truth.hpp"

namespace {
using namespace wheelins;


struct RunArgs {
  std::string config_file;
  std::string manifest;
  std::string configuration;
  std::string chips;
  std::string modules;
  std::string out;
  std::string formats, tum_frame;
  std::string speed;
  std::string weights;
  std::string yaw;
  std::string calibration;
  bool centralized = false;
  bool no_constraint = false;
  bool no_faults = false;
  bool no_standstill = false;
  bool fixed_noise = false;
  bool no_evaluate = false;
  bool no_data_checks = false;
  bool force = false;
  bool quiet = false;
  bool verbose = false;
  bool full_rate = false;
  bool subsystems = false;
  std::optional<double> duration, output_interval, covariance_interval, align_start;
  std::string antenna;
  std::vector<std::string> settings;  ///< --set KEY=VALUE, any key of docs/run-config.md
};

/// The statistics of the run every summary starts with: time, updates, covariance checks.
void print_run_statistics(const RunResult& res) {
  const NavigatorStats& st = res.stats;
  const double nav_s = st.t_end - st.t_start;
  const double epochs = std::max<double>(1.0, static_cast<double>(st.epochs));
  std::printf("\nnavigated %.1f s (%llu epochs) in %.2f s wall: %.0fx real time, %.2f us per epoch "
              "(the navigator %.2f us)\n",
              nav_s, static_cast<unsigned long long>(st.epochs), res.wall_seconds,
              nav_s / std::max(1e-9, res.wall_seconds), 1e6 * res.wall_seconds / epochs,
              1e6 * res.filter_seconds / epochs);
  std::printf("velocity updates: %llu (%llu rejected, max test ratio %.2f)",
              static_cast<unsigned long long>(st.velocity_updates),
              static_cast<unsigned long long>(st.velocity_rejected), st.max_velocity_test_ratio);
  if (st.position_updates)
    std::printf("; position constraint: %llu (%llu rejected, max %.2f)",
                static_cast<unsigned long long>(st.position_updates),
                static_cast<unsigned long long>(st.position_rejected), st.max_position_test_ratio);
  std::printf("\ncovariance checks: %llu, not positive definite: %llu, max asymmetry %.1e\n",
              static_cast<unsigned long long>(st.covariance_checks),
              static_cast<unsigned long long>(st.covariance_not_pd), st.max_covariance_asymmetry);
}

/// `run -v`: everything, as listed tables (the calibration, the noise model, the weights)
/// and every file written.
void print_run_details(const RunRequest& req, const RunResult& res) {
  print_run_statistics(res);
  if (req.nav.faults.enabled) std::cout << res.fault_report;
  std::cout << res.calibration_report << res.noise_report << res.weights_report;
  for (const auto& f : res.files) std::cout << "wrote " << f.string() << "\n";
}

/// The short summary (the default): a line each for the calibration, the noise model and the
/// weights, their warnings on stderr, and where the files went.
void print_run_summary(const RunRequest& req, const RunResult& res) {
  print_run_statistics(res);
  if (req.nav.faults.enabled) std::cout << res.fault_report;
  if (!res.calibration_report.empty())
    std::cout << "installation calibration: estimated from the data (calibration.yaml; -v lists it)\n";
  std::cout << "noise model: " << (req.nav.noise.enabled ? "identified from the data" : "fixed")
            << " (noise.yaml; -v lists it)\n";
  const WarningSink warn = req.warn ? req.warn : stderr_sink();
  for (const auto& n : res.noise)
    for (const auto& w : n.warnings) warn(w);  // each names its module
  if (!res.weights.empty()) {
    const std::vector<WeightSummary>& s = res.weight_summary;
    std::cout << "reference weights k_i (eq. 8), mean:";
    for (std::size_t i = 0; i < s.size(); ++i)
      std::printf("%s %s %.3f", i ? "," : "", req.modules[i].c_str(), s[i].mean);
    std::cout << " (weights.csv)\n";
  }
  if (res.files.empty()) return;
  std::cout << "wrote " << res.files.size() << " files to "
            << res.files.front().parent_path().string() << " (";
  for (std::size_t i = 0; i < res.files.size(); ++i)
    std::cout << (i ? ", " : "") << res.files[i].filename().string();
  // What more the flags would write: every record (when records are passed over), and each
  // IMU's own trajectory.
  const char* sep = "; ";
  if (req.file_interval > req.nav.output_interval) {
    std::printf("%sthe trajectory every %g s: --full-rate for every record", sep, req.file_interval);
    sep = ", ";
  }
  if (req.modules.size() > 1 && !req.write_subsystems) std::cout << sep << "--subsystems for each IMU's";
  std::cout << ")\n";
}

/// The command line's settings over the run configuration (run/run_config.hpp: RunOverrides,
/// applied as Python's run() applies its keywords).
RunOverrides overrides_of(const RunArgs& a) {
  RunOverrides o;
  o.config = a.config_file;
  o.manifest = a.manifest;
  o.configuration = a.configuration;
  if (!a.chips.empty()) o.chips = cli::split_list(a.chips);
  if (!a.modules.empty()) {
    o.modules = cli::split_list(a.modules);
    if (o.modules.empty()) throw InputError("--modules '" + a.modules + "': no module named");
  }
  o.output_dir = a.out;
  if (!a.formats.empty()) o.formats = cli::split_list(a.formats);
  o.tum_frame = a.tum_frame;
  o.speed = a.speed;
  o.weights = a.weights;
  o.yaw_scale_factors = a.yaw;
  o.calibration = a.calibration;
  auto flag = [](bool set, bool value) { return set ? std::optional<bool>(value) : std::nullopt; };
  o.centralized = flag(a.centralized, true);
  o.position_constraint = flag(a.no_constraint, false);
  o.fault_handling = flag(a.no_faults, false);
  o.standstill = flag(a.no_standstill, false);
  o.fixed_noise = flag(a.fixed_noise, true);
  o.data_checks = flag(a.no_data_checks, false);
  o.duration = a.duration;
  o.output_interval = a.output_interval;
  o.covariance_interval = a.covariance_interval;
  o.overwrite = a.force;
  o.full_rate = a.full_rate;
  o.subsystems = a.subsystems;
  o.settings = a.settings;
  return o;
}

int run(const RunArgs& a) {
  const RunOverrides overrides = overrides_of(a);
  const WarningSink warn = stderr_sink();  // one sink: each warning once
  const RunConfig cfg = run_config_with(overrides, warn);
  RunRequest req = make_run_request(cfg, warn);
  req.progress = !a.quiet;

  // Evaluation against the truth as the run goes (run/evaluation.hpp): a truth file that
  // cannot be opened stops the command before the run; a bad record met later is reported
  // after the trajectory is written.
  if (!a.no_evaluate) req.evaluation = RunEvaluationRequest{a.align_start, a.antenna, false, ""};

  std::cout << "wheelins run: " << cfg.configuration << " [";
  for (std::size_t i = 0; i < req.modules.size(); ++i) std::cout << (i ? ", " : "") << req.modules[i];
  std::cout << "] on '" << req.manifest.path.string() << "'\n";
  if (a.verbose) std::cout << req.nav.describe();
  if (!req.manifest.heading_known)
    std::cout << "initial heading:            not in the manifest: a local frame (odometry frame, as ROS's odom) "
                 "with the vehicle's heading 0 at the start\n";

  const RunResult res = run_navigation(req);
  if (a.verbose)
    print_run_details(req, res);
  else
    print_run_summary(req, res);
  if (res.evaluation)
    print_evaluation(*res.evaluation, res.truth_file.string(), res.stats.t_start, res.stats.t_end,
                     req.modules.size() > 1 && !req.nav.fusion.centralized);
  if (!res.evaluation_error.empty()) throw InputError(res.evaluation_error);
  return 0;
}

const bool registered = cli::register_command(
    20, "run", "Navigate a dataset with one IMU configuration and write the trajectory",
    [](CLI::App& sub) {
      auto a = std::make_shared<RunArgs>();
      sub.add_option("config", a->config_file, "Run configuration (YAML; see docs/run-config.md)");
      sub.add_option("--manifest,-m", a->manifest, "Dataset manifest (overrides the config's)");
      std::string configurations;  // from the presets, so the help cannot fall behind them
      for (const auto& n : configuration_names())
        configurations += (configurations.empty() ? "" : " | ") + n + (n == "single" ? " | single-right" : "");
      sub.add_option("--configuration,-c", a->configuration, configurations + " (default: single)");
      sub.add_option("--chips", a->chips, "Chip per IMU, e.g. C1,C4 (default: the first of each)");
      sub.add_option("--modules", a->modules, "Explicit module names (instead of a configuration)");
      sub.add_option("--out,-o", a->out, "Output directory");
      sub.add_option("--formats", a->formats, "Trajectory formats: csv,tum,kml (default: all)");
      sub.add_option("--tum-frame", a->tum_frame,
                     "trajectory.tum's frame: ned (x north, y east, z down; the default) or enu (x east, "
                     "y north, z up; body x forward, y left, z up: ROS, evo)");
      sub.add_option("--speed", a->speed, "Wheel speed sharing: own (default) | mean (paper)");
      sub.add_option("--yaw-scale-factors", a->yaw,
                     "Yaw-rate scale factors: auto (default: from the position constraint with a "
                     "Body-IMU, else held) | held | constraint | estimated");
      sub.add_option("--weights", a->weights,
                     "Reference weights k_i of eq. (8): equal (paper) | covariance (each "
                     "subsystem's own uncertainty) | standalone (each subsystem's drift without the "
                     "constraint; weights.csv)");
      sub.add_option("--calibration", a->calibration,
                     "installation geometry: estimate (default: from the data, "
                     "calibration.yaml) | manifest (as given)");
      sub.add_flag("--centralized", a->centralized, "One joint covariance over all IMUs");
      sub.add_flag("--no-position-constraint", a->no_constraint, "Disable the multi-IMU constraint");
      sub.add_flag("--no-evaluate", a->no_evaluate,
                   "Do not evaluate against the manifest's truth (the evaluation streams the truth "
                   "file alongside the run)");
      sub.add_flag("--no-data-checks", a->no_data_checks,
                   "Run the manifest as it is, without holding it against its data first (the axle "
                   "axis and sign, clock offsets, kinds, sides, a body's mounting)");
      sub.add_flag("--fixed-noise", a->fixed_noise,
                   "Hold the manifest's noise figures (or the defaults) fixed instead of identifying "
                   "them from the data (docs/filter.md section 13)");
      sub.add_flag("--no-fault-handling", a->no_faults,
                   "Use every sample and module as it comes (no outage, saturation, slip or "
                   "fault isolation)");
      sub.add_flag("--no-standstill", a->no_standstill,
                   "No zero-velocity detection: a standing vehicle gets the wheel-speed updates of a "
                   "moving one (docs/faults.md, \"Standing still\")");
      sub.add_option("--duration", a->duration, "Stop after this many seconds of navigation");
      sub.add_option("--antenna", a->antenna,
                     "Evaluation: the truth's antenna X,Y,Z in the vehicle frame [m] (default: the manifest's "
                     "vehicle.antenna_v_m)");
      sub.add_option("--align-start", a->align_start,
                     "Evaluation: align the trajectory's first METRES of travel onto the truth's (default: 100 "
                     "when the manifest has no initial heading, else 0 = off)");
      sub.add_option("--output-interval", a->output_interval, "Output interval [s]; 0 = every epoch");
      sub.add_option("--covariance-interval", a->covariance_interval,
                     "Covariance time update every this many seconds (F integrated in between); "
                     "0 = every IMU epoch; at most 0.5 s");
      cli::add_settings_option(sub, a->settings);
      sub.add_flag("--force,-f", a->force, "Overwrite existing results");
      sub.add_flag("--quiet,-q", a->quiet, "No progress line");
      sub.add_flag("--verbose,-v", a->verbose,
                   "Also the option listing, the calibration, noise and weight tables, and every file written");
      sub.add_flag("--full-rate", a->full_rate,
                   "Write the trajectory at every record (default: every 0.1 s, output.file_interval_s)");
      sub.add_flag("--subsystems", a->subsystems,
                   "Also write each IMU's own trajectory, <module>.csv (multi-IMU runs)");
      return [a]() { return run(*a); };
    });
}  // namespace
