// One navigation run end to end: the selected modules' files are streamed and
// merged by time, the navigator runs, and the trajectories are written (each file
// appears complete or not at all; existing results are kept unless overwrite).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "wheelins/fusion/navigator.hpp"
#include "wheelins/io/diagnostics.hpp"
#include "wheelins/io/manifest.hpp"
#include "wheelins/io/trajectory.hpp"
#include "wheelins/run/calibration.hpp"
#include "wheelins/run/evaluation.hpp"

namespace wheelins {

struct RunRequest {
  Manifest manifest;
  std::vector<std::string> modules;  ///< the first drives the output epochs
  NavigatorOptions nav;
  std::filesystem::path output_dir;  ///< empty: nothing is written (the sink still runs)
  std::vector<TrajectoryFormat> formats{TrajectoryFormat::kCsv, TrajectoryFormat::kTum,
                                        TrajectoryFormat::kKml};
  /// trajectory.tum's convention (its header names it and the manifest's origin).
  TumFrame tum_frame = TumFrame::kNed;
  bool overwrite = false;
  bool write_subsystems = true;      ///< also <module>.csv per subsystem (multi-IMU runs)
  /// [s] between the records written to the trajectory files: the first record at or after
  /// each step from the first, and always the last; 0: every record. on_record (the
  /// evaluation) sees every record either way. The run configuration's default is 0.1 s.
  double file_interval = 0.0;
  bool progress = true;              ///< a progress line on a terminal
  double max_duration = 0.0;         ///< stop after this much navigation [s]; 0 = all data
  /// The Wheel-IMUs' mounting and lever arm: estimated from the data in a first pass over
  /// their files (calibration.yaml beside the trajectory), or the manifest's.
  CalibrationMode calibration = CalibrationMode::kEstimate;
  InstallationCalibrationOptions calibration_options;
  /// What the data can check of the manifest is checked before the run (survey/checks.hpp):
  /// a disagreement is an InputError naming the module and the setting; false runs the
  /// manifest as it is.
  bool data_checks = true;
  WarningSink warn;
  /// The vehicle solution evaluated against the manifest's truth as the run goes (when the
  /// manifest has one): a truth file that cannot be read stops the run before any work; a
  /// bad record met later is RunResult::evaluation_error, the trajectory written.
  std::optional<RunEvaluationRequest> evaluation;
  /// Called for every vehicle record (e.g. to keep them in memory); may be empty.
  std::function<void(const TrajectoryRecord&)> on_record;
};

struct RunResult {
  NavigatorStats stats;
  double wall_seconds = 0.0;
  double filter_seconds = 0.0;  ///< time inside the navigator incl. making the records (no input reading, no on_record, no hand-over to the writer thread)
  std::vector<std::filesystem::path> files;  ///< what was written
  std::string fault_report;                  ///< readable summary of the fault handling
  std::vector<FaultEvent> fault_events;      ///< every detection and what was done
  std::vector<ModuleFaultStats> fault_stats; ///< per module, in the order of the request's modules (faults.csv)
  std::vector<ModuleNoiseReport> noise;      ///< the noise model per module (noise.yaml)
  std::string noise_report;                  ///< readable summary of it, with the warnings
  std::vector<WeightRecord> weights;         ///< the reference weights of eq. (8) over time (weights.csv)
  std::string weights_report;                ///< readable summary of them (multi-IMU runs)
  std::vector<WeightSummary> weight_summary;  ///< per module: mean, least, greatest weight
  InstallationCalibration calibration;  ///< the installation estimates (calibration.yaml)
  std::string calibration_report;            ///< readable table of them (empty: not estimated)
  /// Against the truth (RunRequest::evaluation): the figures, the truth file, or why the
  /// evaluation failed after the run (the files are written either way).
  std::optional<eval::EvalResult> evaluation;
  std::filesystem::path truth_file;
  std::string evaluation_error;
};

/// Runs the request on the manifest's files (a RunSession fed by them, session.hpp). The
/// output directory is written through OutputDir: checked, locked and staged before any
/// work, its files appear together at the end (or not at all).
RunResult run_navigation(const RunRequest& request);

/// A run a calibration makes for its own use: `modules` of `m` with the manifest's
/// installation as it is (CalibrationMode::kManifest), no data checks, no progress, its
/// warnings dropped (they belong to the user's own run), the records every `output_interval`
/// seconds (0: every epoch).
RunRequest calibration_run_request(const Manifest& m, std::vector<std::string> modules, double output_interval);

/// The checks of a request before any work (InputError naming what is wrong): modules
/// known and listed once, formats listed once, the numbers in their ranges, the
/// centralized filter on several modules, every module's rate above the gap threshold.
void validate_run_request(const RunRequest& request);

/// The manifest's selected modules held against their data (survey/checks.hpp): throws
/// InputError listing every disagreement; warnings go to `warn`. Returns the survey's notes.
std::vector<std::string> check_manifest_against_data(const Manifest& manifest, const std::vector<std::string>& modules,
                                                     const WarningSink& warn);

/// A run of several modules writes <module>.csv per module (RunRequest::write_subsystems),
/// and weights.csv when it has the position constraint.
bool writes_subsystem_files(const RunRequest& request);
bool writes_weights_file(const RunRequest& request);

/// The files a run would write (to refuse early, before any work, if they exist): the
/// trajectory in each of the request's formats first, in their order.
std::vector<std::filesystem::path> run_output_files(const RunRequest& request);

}  // namespace wheelins
