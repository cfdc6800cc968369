// A run fed with records pushed one at a time rather than read from the manifest's files:
// the Python Navigator, a live source. Each module's records become samples as the file
// reader makes them (io/imu_file.hpp imu_sample()) and pass the run's input checks
// (run/input_checks.hpp); the rest is the RunSession every run goes through (session.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "wheelins/io/imu_file.hpp"
#include "wheelins/run/input_checks.hpp"
#include "wheelins/run/session.hpp"

namespace wheelins {

/// A pushed record the input checks refuse before it reaches the navigation (a value not
/// finite, a time that repeats or goes back): the session is as before it, and a live source
/// may go on with the next record. Other InputErrors from push() end the run.
class RejectedSample : public InputError {
 public:
  using InputError::InputError;
};

class PushSession {
 public:
  /// The request as run_navigation() takes it, less what needs the files: the manifest is not
  /// held against its data (data_checks) and, with CalibrationMode::kEstimate, the installation
  /// is estimated from the first `calibration_warmup` seconds after the static period (the
  /// samples up to then are kept and navigated when it ends) instead of a pass over the files.
  /// `source` names the pushed samples in messages.
  PushSession(RunRequest request, double calibration_warmup, std::string source = "pushed samples");
  ~PushSession();
  PushSession(const PushSession&) = delete;
  PushSession& operator=(const PushSession&) = delete;

  /// One record of the request's module `module` (an index into its modules) as its source
  /// holds it (the manifest's format and axes; time before the module's time offset). Records
  /// must come in time order over all modules. False once the request's duration is reached
  /// (push no more). RejectedSample (an InputError) names the module, the sample and the value
  /// that is wrong.
  bool push(int module, const ImuRow& row);
  /// The end of the data (a warm-up still open ends on what it has), the reports, the files.
  RunResult finish();

  const RunRequest& request() const { return session_->request(); }
  const Navigator& navigator() const { return session_->navigator(); }
  bool finished() const { return finished_; }
  /// The calibration warm-up is still collecting samples (no navigation yet).
  bool in_warmup() const { return warmup_ && !warmup_done_; }
  /// The last time the warm-up takes [s] (only with a warm-up).
  double warmup_end() const;
  /// The warm-up's estimates are in use (CalibrationMode::kEstimate, warm-up ended).
  bool calibrated() const { return warmup_done_; }
  /// Samples were pushed that are not navigated yet: the warm-up's kept ones (and those pushed
  /// since) while they are navigated a slice per push (set_catch_up()).
  bool behind() const { return behind_; }
  /// When the warm-up ends, navigate its kept samples `per_push` at a time, with each push (a
  /// live source's latency: no single push waits for all of them), instead of all at once (0,
  /// the default). finish() navigates what is left.
  void set_catch_up(std::size_t per_push) { catch_up_per_push_ = per_push; }
  const InstallationCalibration& calibration() const { return calibration_; }

 private:
  struct Track {
    ImuReadOptions options;
    double prev_t = 0.0;
    std::uint64_t count = 0;
    InputChecks checks;
  };
  ImuSample checked_sample(int module, const ImuRow& row, bool& admitted);
  void navigate(int module, const ImuSample& s, std::uint64_t record);
  void end_warmup();
  void catch_up(std::size_t n);

  std::string source_;
  std::unique_ptr<RunSession> session_;
  std::vector<Track> tracks_;
  std::unique_ptr<CalibrationWarmup> warmup_;  ///< CalibrationMode::kEstimate
  bool warmup_done_ = false;
  // The catch-up after the warm-up: kept samples navigated so far, samples pushed meanwhile.
  std::size_t catch_up_per_push_ = 0, caught_up_ = 0;
  struct Pending {
    int module;
    ImuSample sample;
    std::uint64_t record;
  };
  std::vector<Pending> pending_;
  bool behind_ = false;
  InstallationCalibration calibration_;
  double last_t_ = -std::numeric_limits<double>::infinity();
  double process_seconds_ = 0.0;
  bool stopped_ = false, finished_ = false;
};

}  // namespace wheelins
