// The paper's experiment (Section VI): every configuration and chip combination
// of a dataset, evaluated against its truth, summarised as Tables 4-8.
//
// Runs: 8 single Wheel-INS (left C1-C4, right C1-C4); 16 Dual Wheel-INS (left Ci,
// right Cj); 16 Body/Wheel-INS (left Ci, body Cj); 16 Triple INS (left Ci, right Cj,
// body C(((i+j) mod 4) + 1)); and the first 8 Triple INS combinations again with the
// centralized filter (Table 7/8).
//
// The runs themselves are a built-in study (study/spec.hpp, the layer above):
// `wheelins experiment` plans them here, runs them as study jobs and writes the tables and
// plots from the jobs' results. The plan and the tables need the navigator's statistics
// (fusion) and the metrics (eval), so they sit in the top layer run; their names stay in
// namespace wheelins::eval.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "wheelins/eval/metrics.hpp"
#include "wheelins/fusion/navigator.hpp"
#include "wheelins/io/manifest.hpp"
#include "wheelins/nav/earth.hpp"

namespace wheelins::eval {

struct ExperimentOptions {
  /// Configurations to run (single, dual-wheel, body-wheel, triple, centralized); empty = all.
  std::vector<std::string> only;
};

struct ExperimentRun {
  std::string configuration;         ///< single | dual-wheel | body-wheel | triple
  bool centralized = false;
  std::vector<std::string> modules;
  std::string label;                 ///< chip digits, e.g. "14" (left C1, right C4)
  std::string side;                  ///< single: "left" | "right"
  EvalResult eval;                   ///< series (10 Hz) kept only for figure runs
  std::vector<TrajectoryRecord> track;  ///< 1 Hz vehicle solution, figure runs only
  NavigatorStats stats;
  std::size_t fault_events = 0;      ///< lines of the run's fault report (0 on clean data)
  double filter_seconds = 0.0;
  bool figure = false;  ///< a Fig. 7-9 run (paper chips or closest, see experiment_plan)
};

struct ExperimentResult {
  std::filesystem::path manifest;
  std::string dataset_name;
  std::filesystem::path truth_file;  ///< the truth the runs were evaluated against
  earth::Geodetic origin;            ///< the local frame's origin (manifest)
  double duration = 0.0;             ///< [s] of navigation per run asked for (--duration; 0: all the data)
  std::vector<ExperimentRun> runs;
  double wall_seconds = 0.0;
};

/// The run list for a manifest (needs 4 chips per module group, or fewer: combinations
/// shrink to what the manifest has).
std::vector<ExperimentRun> experiment_plan(const Manifest& m, const ExperimentOptions& o);

/// Tables 4-8 in the paper's layout (Markdown), with a header naming the dataset.
std::string experiment_markdown(const ExperimentResult& r);
/// One row per run (CSV, with a header) / everything as JSON.
std::string experiment_csv(const ExperimentResult& r);
std::string experiment_json(const ExperimentResult& r);

}  // namespace wheelins::eval
