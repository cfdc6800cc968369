// One run's pipeline between its input and its results, whatever feeds it: the request's
// checks and staged outputs at the start, then sample after sample (the navigator, the
// non-finite guard, the consumer, the thinned files on the writer thread), then the reports
// and every file at once. run_navigation() feeds it from the manifest's files; a caller
// with samples of its own (a live source, Python) pushes them as they come.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "wheelins/fusion/navigator.hpp"
#include "wheelins/io/output_dir.hpp"
#include "wheelins/io/record_pipe.hpp"
#include "wheelins/run/run.hpp"

namespace wheelins {

/// Which records of one stream go to its files (RunRequest::file_interval): the first at or
/// after each step of the interval from the first record, and the last one (held back until
/// the end). No allocation: one record is held.
class FileThinning {
 public:
  explicit FileThinning(double interval) : interval_(interval) {}
  /// True: write `rec` now; false: it is passed over (and held, in case it is the last).
  bool keep(const TrajectoryRecord& rec);
  /// The stream's last record if it was passed over.
  const std::optional<TrajectoryRecord>& held() const { return held_; }

 private:
  double interval_;
  double next_ = 0.0;
  bool started_ = false;
  std::optional<TrajectoryRecord> held_;
};

/// What the feeder knows of a module's input when the run ends: the samples its input checks
/// left out (beyond the sensor's range or not finite) and where they came from.
struct SessionInput {
  std::uint64_t dropped = 0;
  std::string source;  ///< the file the module's samples came from, or what else fed them
};

class RunSession {
 public:
  /// Everything before the first sample: the request validated, the output directory
  /// checked, locked and staged (so a refusal costs nothing), the manifest held against the
  /// data (RunRequest::data_checks), the installation calibration (CalibrationMode::kEstimate:
  /// `calibration` if given, e.g. from a warm-up on the samples, else a first pass over the
  /// Wheel-IMUs' files), the writers and the navigator on the calibrated manifest.
  explicit RunSession(RunRequest request, const InstallationCalibration* calibration = nullptr);
  ~RunSession();
  RunSession(const RunSession&) = delete;
  RunSession& operator=(const RunSession&) = delete;

  /// One sample of the request's module `module` (an index into its modules), after its
  /// input checks; `record` is its 0-based index in its source, named by an error. False once
  /// the request's max_duration is reached (this sample was navigated; push no more).
  bool push(int module, const ImuSample& sample, std::uint64_t record);
  /// Throws InputError naming the module, the cause and the time if the solution is no longer
  /// finite (a record that is not finite is never passed on). Called after a block of samples.
  void check_finite(double t_now) const;
  /// The end: every record written, the reports, every file at once. `process_seconds` is the
  /// feeder's time inside push() (RunResult::filter_seconds, less the consumer's share);
  /// `inputs` follow the request's modules.
  RunResult finish(double process_seconds, const std::vector<SessionInput>& inputs);

  /// The installation calibration to navigate with, in place of the one the session started
  /// with (a warm-up's estimates): the navigator is built again. Only before the first push().
  void use_calibration(const InstallationCalibration& calibration);

  const RunRequest& request() const { return req_; }
  const Navigator& navigator() const { return *nav_; }

 private:
  void stage_outputs();
  void open_writers();
  void make_navigator();
  void on_record(int stream, const TrajectoryRecord& rec);
  void write_reports(const std::string& input_csv, const std::vector<ModuleNoiseReport>& noise);
  void require_navigating(const std::vector<SessionInput>& inputs) const;
  void finish_evaluation(RunResult& result);

  std::chrono::steady_clock::time_point wall0_;
  RunRequest req_;
  std::vector<std::filesystem::path> outputs_;
  std::unique_ptr<OutputDir> out_dir_;
  InstallationCalibration calibration_;
  Manifest manifest_;  ///< the request's, calibrated
  std::vector<std::unique_ptr<TrajectoryWriter>> vehicle_, subsystems_;
  std::unique_ptr<RecordPipe> pipe_;
  std::vector<FileThinning> thinning_;
  double sink_seconds_ = 0.0;
  bool started_ = false;
  int bad_stream_ = -1;
  double bad_t_ = 0.0;
  std::unique_ptr<Navigator> nav_;
  std::unique_ptr<eval::RunEvaluation> evaluation_;  ///< RunRequest::evaluation
};

}  // namespace wheelins
