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
  std::vector<NamedSetting> named;    ///< the run settings' options (run/run_options.hpp), as given
  std::vector<std::string> settings;  ///< --set KEY=VALUE, any key of docs/run-config.md
  bool no_evaluate = false;
  bool quiet = false;
  bool verbose = false;
  std::optional<double> align_start;
  std::string antenna;
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
      if (s[i].follows && s[i].counted == 0.0) std::printf("%s %s follows (steered)", i ? "," : "", req.modules[i].c_str());
      else std::printf("%s %s %.3f", i ? "," : "", req.modules[i].c_str(), s[i].mean);
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

int run(const RunArgs& a) {
  const WarningSink warn = stderr_sink();  // one sink: each warning once
  const RunConfig cfg = run_config_with(RunOverrides{a.config_file, a.named, a.settings}, warn);
  RunRequest req = make_run_request(cfg, warn);
  req.progress = !a.quiet;

  // Evaluation against the truth as the run goes (run/evaluation.hpp): a truth file that
  // cannot be opened stops the command before the run; a bad record met later is reported
  // after the trajectory is written.
  if (!a.no_evaluate) req.evaluation = RunEvaluationRequest{a.align_start, a.antenna, false, ""};

  std::cout << "wheelins run: " << cfg.configuration << " [";
  for (std::size_t i = 0; i < req.modules.size(); ++i) std::cout << (i ? ", " : "") << req.modules[i];
  std::cout << "] on '" << req.manifest.path.string() << "'\n";
  if (a.verbose) std::cout << run_options_listing(cfg);
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
      cli::add_run_setting_options(sub, a->named);  // --manifest, --configuration, ... (docs/run-config.md)
      sub.add_flag("--no-evaluate", a->no_evaluate,
                   "Do not evaluate against the manifest's truth (the evaluation streams the truth "
                   "file alongside the run)");
      sub.add_option("--antenna", a->antenna,
                     "Evaluation: the truth's antenna X,Y,Z in the vehicle frame [m] (default: the manifest's "
                     "vehicle.antenna_v_m)");
      sub.add_option("--align-start", a->align_start,
                     "Evaluation: align the trajectory's first METRES of travel onto the truth's (default: 100 "
                     "when the manifest has no initial heading, else 0 = off)");
      cli::add_settings_option(sub, a->settings);
      sub.add_flag("--quiet,-q", a->quiet, "No progress line");
      sub.add_flag("--verbose,-v", a->verbose,
                   "Also the option listing, the calibration, noise and weight tables, and every file written");
      return [a]() { return run(*a); };
    });
}  // namespace
