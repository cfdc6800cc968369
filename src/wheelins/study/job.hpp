// Running a study's jobs and reading their results back.
//
// Job K writes RESULTS/jobs/K.json (write_file_atomic: complete or absent) with the
// evaluation of `wheelins evaluate --json`, the run's counters, the labels, the settings
// (canonical text and key) and the timing; a failed job writes K.failed.json with its error
// instead. An experiment figure run also writes K.series.csv and K.track.csv first.
// A K.json of other settings (the study file changed) is moved to jobs/stale/ before K runs.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "wheelins/eval/metrics.hpp"
#include "wheelins/fusion/navigator.hpp"
#include "wheelins/io/diagnostics.hpp"
#include "wheelins/study/files.hpp"
#include "wheelins/study/spec.hpp"

namespace wheelins::study {

/// Where each part of a job's time went [s] (wall clock). The overhead of a job is
/// everything but `navigate`.
struct JobTiming {
  double dataset = 0.0;    ///< finding (or generating) the dataset
  double setup = 0.0;      ///< run configuration, manifest, truth reader
  double navigate = 0.0;   ///< run_navigation with the streaming evaluation
  double finish = 0.0;     ///< the evaluation's end and the result's text
  double write = 0.0;      ///< writing the files (not in the job's own file: measured after)
  double filter = 0.0;     ///< RunResult::filter_seconds
  bool generated = false;  ///< the dataset was simulated by this job
  double started = 0.0, finished = 0.0;  ///< Unix time [s]
  std::string host;
};

struct JobOutcome {
  bool ok = false;
  std::string error;    ///< when !ok
  std::string summary;  ///< one line: the headline metrics
  JobTiming timing;
};

struct JobOptions {
  bool progress = false;    ///< the run's own progress line (one job on a terminal)
  WarningSink warn;         ///< warnings of the run (also kept in the result)
  ChunkWriter write_chunk;  ///< tests: replaces writing the result's bytes
};

/// Runs one job and writes its result (or its failure). Never throws for a failure of the
/// job itself (returned, and written as K.failed.json); throws Interrupted (nothing written)
/// on an interrupt, and an error if not even the failure can be written.
JobOutcome run_job(const Study& study, const Job& job, const JobOptions& options = {});

/// With `keep_datasets: false`: deletes job j's simulated dataset if every job on it is done
/// (run_job calls it after a success). Returns whether it deleted it.
bool delete_dataset_when_done(const Study& study, const Job& job);

enum class JobState { kMissing, kDone, kFailed, kStale, kUnreadable };
const char* job_state_name(JobState s);

struct JobStatus {
  JobState state = JobState::kMissing;
  std::string detail;  ///< the error of a failed job, what is wrong with an unreadable file
};
/// The state of job `job` from its files (reads only the start of K.json).
JobStatus job_status(const Study& study, const Job& job);

struct RunOptions {
  int workers = 1;              ///< jobs at once (threads)
  bool rerun = false;           ///< run jobs that are done too
  bool progress = false;        ///< a progress line on a terminal (stderr)
  std::ostream* log = nullptr;  ///< a line per finished job
  JobOptions job;
};

struct RunSummary {
  std::size_t requested = 0, already_done = 0, done = 0, failed = 0;
  std::vector<std::pair<std::size_t, std::string>> failures;  ///< job, error
  double seconds = 0.0;
};

/// Runs the jobs `indices` (all of the study when empty) that are not done, on
/// `workers` threads. The run settings of those jobs are checked first (InputError before
/// anything runs). Interrupted (util/interrupt.hpp: Ctrl-C, a kill), the running jobs stop
/// and write nothing, the finished ones are kept, and Interrupted is thrown; run again, it
/// does the rest.
RunSummary run_jobs(const Study& study, const std::vector<std::size_t>& indices,
                    const RunOptions& options);

/// The format of a result file K.json, and the text every complete one ends with: a result
/// without it (cut short) is not done.
inline constexpr const char* kJobResultFormat = "wheelins-study-job-1";
inline constexpr const char* kJobResultTail = "\"status\": \"done\"\n}\n";

/// A finished job as read back from K.json.
struct JobRecord {
  std::size_t index = 0;
  std::string key, canonical, configuration;
  std::vector<std::string> labels, modules, warnings;
  eval::EvalResult eval;  ///< without the per-epoch series
  NavigatorStats stats;   ///< counters (the step timings too)
  std::size_t fault_events = 0;
  JobTiming timing;
  /// Experiment figure runs: the 10 Hz error series and 1 Hz track (from the side files).
  std::vector<eval::EpochError> series;
  std::vector<TrajectoryRecord> track;
};

/// Reads a result file; nullopt and `error` when it is not a complete result.
std::optional<JobRecord> read_job_record(const std::filesystem::path& file, std::string& error,
                                         bool with_series = false);

/// Parses a job list "3", "0-9", "1,4,7-9" (inclusive ranges) for a study of `count` jobs.
std::vector<std::size_t> parse_job_list(const std::string& text, std::size_t count);

}  // namespace wheelins::study
