// A job's result read back (job.hpp): K.json, complete or rejected, and the error series
// and track of an experiment figure run from its side files.
#include "wheelins/study/job.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <sstream>

#include "wheelins/io/yaml_reader.hpp"
#include "wheelins/nav/types.hpp"
#include "wheelins/study/files.hpp"

namespace wheelins::study {
namespace fs = std::filesystem;

namespace {

/// Rows of numbers of a side file (header skipped); empty on any problem.
std::vector<std::vector<double>> read_rows(const fs::path& file, std::size_t columns) {
  std::vector<std::vector<double>> rows;
  std::string text;
  if (!read_file(file, text)) return {};
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::vector<double> row;
    const char* p = line.c_str();
    while (*p) {
      char* end = nullptr;
      row.push_back(std::strtod(p, &end));
      if (end == p) return {};
      p = *end == ',' ? end + 1 : end;
    }
    if (row.size() != columns) return {};
    rows.push_back(std::move(row));
  }
  return rows;
}

/// A number of a result (NaN when absent or null) and a counter (0 when absent or null).
double num(const YAML::Node& v) { return v && !v.IsNull() ? v.as<double>() : std::nan(""); }
std::uint64_t count(const YAML::Node& v) { return v && !v.IsNull() ? v.as<std::uint64_t>() : 0; }

/// The `evaluation` of a result.
void read_evaluation(const YAML::Node& e, eval::EvalResult& ev) {
  ev.truth_file = e["truth_file"].as<std::string>();
  ev.traj_file = e["traj_file"].as<std::string>();
  ev.traj_format = e["traj_format"].as<std::string>();
  ev.truth_records = count(e["truth_records"]);
  ev.traj_records = count(e["traj_records"]);
  ev.epochs = count(e["epochs"]);
  ev.skipped_outside = count(e["skipped_outside"]);
  ev.skipped_gap = count(e["skipped_gap"]);
  ev.t_start = num(e["t_start_s"]);
  ev.t_end = num(e["t_end_s"]);
  ev.duration = num(e["duration_s"]);
  ev.distance = num(e["distance_m"]);
  ev.segment_length = num(e["segment_m"]);
  ev.drift_rate = num(e["drift_rate_pct"]) / 100.0;
  for (const auto& x : e["drift_curve_pct"]) ev.drift_curve.push_back(num(x) / 100.0);
  ev.heading_rmse = num(e["heading_rmse_deg"]) * kDeg;
  ev.heading_max_abs = num(e["heading_max_abs_deg"]) * kDeg;
  ev.has_heading = std::isfinite(ev.heading_rmse);
  ev.max_error = num(e["max_error_m"]);
  ev.final_error = num(e["final_error_m"]);
  ev.rms_error = num(e["rms_error_m"]);
  ev.has_sigma = e["has_sigma"].as<bool>();
  ev.sigma_epochs = count(e["sigma_epochs"]);
  ev.within_3sigma = num(e["within_3sigma_fraction"]);
  ev.mean_nees = num(e["mean_nees_h"]);
  ev.aligned = e["aligned"].as<bool>();
  ev.align_rotated = e["align_rotated"].as<bool>();
  ev.align_yaw = num(e["align_yaw_deg"]) * kDeg;
  for (int k = 0; k < 3; ++k) ev.align_offset[k] = num(e["align_offset_ned_m"][k]);
}

/// The `stats` of a result (the navigator's counters and the fault count).
void read_stats(const YAML::Node& st, JobRecord& r) {
  NavigatorStats& s = r.stats;
  s.samples = count(st["samples"]);
  s.epochs = count(st["epochs"]);
  s.records = count(st["records"]);
  s.t_start = num(st["t_start_s"]);
  s.t_end = num(st["t_end_s"]);
  s.velocity_updates = count(st["velocity_updates"]);
  s.velocity_rejected = count(st["velocity_rejected"]);
  s.max_velocity_test_ratio = num(st["max_velocity_test_ratio"]);
  s.position_updates = count(st["position_updates"]);
  s.position_rejected = count(st["position_rejected"]);
  s.max_position_test_ratio = num(st["max_position_test_ratio"]);
  s.velocity_steps = count(st["velocity_steps"]);
  s.position_steps = count(st["position_steps"]);
  s.covariance_checks = count(st["covariance_checks"]);
  s.covariance_not_pd = count(st["covariance_not_pd"]);
  s.max_covariance_asymmetry = num(st["max_covariance_asymmetry"]);
  r.fault_events = count(st["fault_events"]);
}

/// The `timing` of a result (the navigator's step timings too).
void read_timing(const YAML::Node& t, JobRecord& r) {
  r.stats.velocity_step_seconds = num(t["velocity_step_s"]);
  r.stats.position_step_seconds = num(t["position_step_s"]);
  r.timing.dataset = num(t["dataset_s"]);
  r.timing.generated = t["dataset_generated"].as<bool>();
  r.timing.setup = num(t["setup_s"]);
  r.timing.navigate = num(t["navigate_s"]);
  r.timing.finish = num(t["finish_s"]);
  r.timing.filter = num(t["filter_s"]);
  r.timing.started = num(t["started_unix"]);
  r.timing.finished = num(t["finished_unix"]);
  r.timing.host = t["host"].as<std::string>();
}

/// The error series and track of an experiment figure run, from the side files next to its
/// result `file` (none when missing or unreadable).
void read_side_files(const fs::path& file, JobRecord& r) {
  const fs::path dir = file.parent_path();
  const std::string k = std::to_string(r.index);
  for (const auto& row : read_rows(dir / (k + ".series.csv"), 9)) {
    eval::EpochError e;
    e.t = row[0];
    e.distance = row[1];
    e.err_ned = Vec3(row[2], row[3], row[4]);
    e.err_h = row[5];
    e.heading_err = row[6];
    e.sigma_h = row[7];
    e.nees_h = row[8];
    r.series.push_back(e);
  }
  for (const auto& row : read_rows(dir / (k + ".track.csv"), 4)) {
    TrajectoryRecord t;
    t.t = row[0];
    t.lla = {row[1], row[2], row[3]};
    r.track.push_back(t);
  }
}

}  // namespace

std::optional<JobRecord> read_job_record(const fs::path& file, std::string& error,
                                         bool with_series) {
  std::string text;
  if (!read_file(file, text)) {
    error = "cannot read '" + file.string() + "'";
    return std::nullopt;
  }
  const std::string tail = kJobResultTail;
  if (text.size() < tail.size() ||
      text.compare(text.size() - tail.size(), tail.size(), tail) != 0) {
    error = "'" + file.string() + "' is not a complete result";
    return std::nullopt;
  }
  JobRecord r;
  try {
    const YAML::Node n = parse_yaml(text, "'" + file.string() + "'", "study result");
    if (n["format"].as<std::string>() != kJobResultFormat) {
      error = "'" + file.string() + "': not a study result (format " +
              n["format"].as<std::string>() + ")";
      return std::nullopt;
    }
    r.index = n["job"].as<std::size_t>();
    r.key = n["key"].as<std::string>();
    r.canonical = n["canonical"].as<std::string>();
    r.configuration = n["configuration"].as<std::string>();
    for (const auto& kv : n["labels"]) r.labels.push_back(kv.second.as<std::string>());
    for (const auto& m : n["modules"]) r.modules.push_back(m.as<std::string>());
    for (const auto& m : n["warnings"]) r.warnings.push_back(m.as<std::string>());
    read_evaluation(n["evaluation"], r.eval);
    read_stats(n["stats"], r);
    read_timing(n["timing"], r);
  } catch (const YAML::Exception& ex) {
    error = "'" + file.string() + "': cannot be read as a study result: " + ex.what();
    return std::nullopt;
  } catch (const InputError& ex) {
    error = std::string(ex.what()) + " (cannot be read as a study result)";
    return std::nullopt;
  }
  if (with_series) read_side_files(file, r);
  return r;
}

}  // namespace wheelins::study
