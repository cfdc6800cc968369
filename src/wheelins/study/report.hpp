// The report of a study: whatever jobs are done, merged (docs/studies.md, "Report").
//
// Per condition (row) and configuration (column): mean, standard deviation and a confidence
// interval of the mean of every metric over the replicates; paired differences between
// configurations on the same replicates with their intervals; plots of the drift rate and
// the heading RMSE by condition (gnuplot, like the experiment's). Files in the results
// directory, rewritten on every report: report.md, summary.csv, differences.csv, jobs.csv,
// report.json, timing.csv, plots/. Every file but timing.csv depends only on the results,
// so the same results give the same bytes however and wherever the jobs ran. A job not done
// (missing, failed, stale, unreadable) is listed in report.md and jobs.csv, never skipped
// silently.
//
// A built-in experiment study (`experiment:`) reports as `wheelins experiment` does:
// experiment.md (Tables 4-8), runs.csv, experiment.json and the Fig. 7-10 plots.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "wheelins/io/diagnostics.hpp"
#include "wheelins/run/plots.hpp"
#include "wheelins/study/job.hpp"
#include "wheelins/study/spec.hpp"

namespace wheelins::study {

struct ReportOptions {
  bool plots = true;
  eval::PlotOptions plot;
  WarningSink warn;
  /// Experiment studies: refuse to replace existing output files unless true.
  bool overwrite = true;
};

struct JobEntry {
  Job job;
  JobStatus status;
  std::optional<JobRecord> record;  ///< when done
};

struct Report {
  std::vector<JobEntry> jobs;
  std::size_t done = 0;
  std::string markdown;                      ///< report.md (experiment.md for experiments)
  std::vector<std::filesystem::path> files;  ///< written
  /// The jobs not in the report, one line each ("job 7 (robot | 3 | triple): failed: ...").
  std::vector<std::string> not_done;
  double job_seconds = 0.0;   ///< the done jobs' time, summed
  double span_seconds = 0.0;  ///< first start to last finish
};

/// Reads every job's state and result (in plan order).
std::vector<JobEntry> collect_jobs(const Study& study, bool with_series = false);

/// Writes the report into the study's results directory.
Report write_report(const Study& study, const ReportOptions& options = {});

/// The files an experiment study's report writes (to refuse early).
std::vector<std::filesystem::path> experiment_report_targets(const Study& study, bool plots);

}  // namespace wheelins::study
