// Running a study's jobs (job.hpp): one job's dataset, run and evaluation written as its
// result or failure record, the job states, and every job not done on all cores. The
// results are read back in job_record.cpp.
#include "wheelins/study/job.hpp"

#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <ostream>
#include <set>
#include <sstream>
#include <thread>

#include "wheelins/eval/run_evaluation.hpp"
#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/file_lock.hpp"
#include "wheelins/io/truth.hpp"
#include "wheelins/io/yaml_reader.hpp"
#include "wheelins/nav/types.hpp"
#include "wheelins/run/run.hpp"
#include "wheelins/run/run_config.hpp"
#include "wheelins/study/dataset.hpp"
#include "wheelins/study/json.hpp"
#include "wheelins/util/interrupt.hpp"

namespace wheelins::study {
namespace fs = std::filesystem;

namespace {

double unix_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}
double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
fs::path result_file(const Study& s, std::size_t k) {
  return s.jobs_dir() / (std::to_string(k) + ".json");
}
fs::path failure_file(const Study& s, std::size_t k) {
  return s.jobs_dir() / (std::to_string(k) + ".failed.json");
}
fs::path side_file(const Study& s, std::size_t k, const char* what) {
  return s.jobs_dir() / (std::to_string(k) + "." + what + ".csv");
}

/// The "key" of a job file, read from its text ("" if none).
std::string key_in(const std::string& text) {
  const std::string tag = "\"key\": \"";
  const auto p = text.find(tag);
  if (p == std::string::npos) return "";
  const auto e = text.find('"', p + tag.size());
  return e == std::string::npos ? "" : text.substr(p + tag.size(), e - p - tag.size());
}

std::string fmt(double v, int decimals) {
  if (!std::isfinite(v)) return "n/a";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

void write_labels(JsonWriter& w, const Study& s, const Job& j) {
  w.begin_object("labels");
  for (std::size_t i = 0; i < j.labels.size(); ++i) w.str(s.axes()[i].name.c_str(), j.labels[i]);
  w.end_object();
}

/// Moves a result of other settings to jobs/stale/ (never deletes a result).
void move_stale(const Study& s, const Job& j) {
  const fs::path file = result_file(s, j.index);
  std::string text;
  if (!read_file(file, text)) return;
  const std::string old = key_in(text);
  if (old == j.key) return;
  std::error_code ec;
  const fs::path dir = s.jobs_dir() / "stale";
  fs::create_directories(dir, ec);
  fs::path target =
      dir / (std::to_string(j.index) + "-" + (old.empty() ? "unknown" : old) + ".json");
  for (int n = 2; fs::exists(target, ec); ++n)
    target = dir / (std::to_string(j.index) + "-" + old + "-" + std::to_string(n) + ".json");
  fs::rename(file, target, ec);
  if (ec && fs::exists(file))
    throw InputError("'" + file.string() +
                     "': holds a result of other settings and cannot be moved to '" +
                     target.string() + "': " + ec.message());
}

std::string series_csv(const std::vector<eval::EpochError>& series) {
  std::string s =
      "t_s,distance_m,err_n_m,err_e_m,err_d_m,err_h_m,heading_err_rad,sigma_h_m,nees_h\n";
  for (const auto& e : series) {
    const double v[9] = {e.t,     e.distance,    e.err_ned.x(), e.err_ned.y(), e.err_ned.z(),
                         e.err_h, e.heading_err, e.sigma_h,     e.nees_h};
    for (int k = 0; k < 9; ++k) {
      if (k) s += ',';
      append_double(s, v[k]);
    }
    s += '\n';
  }
  return s;
}

std::string track_csv(const std::vector<TrajectoryRecord>& track) {
  std::string s = "t_s,lat_rad,lon_rad,h_m\n";
  for (const auto& r : track) {
    const double v[4] = {r.t, r.lla.lat, r.lla.lon, r.lla.h};
    for (int k = 0; k < 4; ++k) {
      if (k) s += ',';
      append_double(s, v[k]);
    }
    s += '\n';
  }
  return s;
}

}  // namespace

bool delete_dataset_when_done(const Study& s, const Job& j) {
  // Every job on these data done.
  std::vector<Job> siblings;
  for (std::size_t k : s.data_siblings(j.index)) {
    if (k == j.index) continue;
    Job other = s.job(k);
    if (other.dataset.cache_name != j.dataset.cache_name) continue;
    if (job_status(s, other).state != JobState::kDone) return false;
    siblings.push_back(std::move(other));
  }
  const fs::path dir = s.cache_dir() / j.dataset.cache_name;
  const FileLock lock(s.cache_dir() / (j.dataset.cache_name + ".lock"), FileLock::Wait::kUntilFree);
  for (const auto& o : siblings)  // again under the lock: a rerun may have started
    if (job_status(s, o).state != JobState::kDone) return false;
  std::error_code ec;
  fs::remove_all(dir, ec);
  return !ec;
}

const char* job_state_name(JobState s) {
  switch (s) {
    case JobState::kDone:
      return "done";
    case JobState::kFailed:
      return "failed";
    case JobState::kStale:
      return "stale";
    case JobState::kUnreadable:
      return "unreadable";
    default:
      return "missing";
  }
}

namespace {

/// The navigator's statistics and the fault count, as a job's result holds them.
void write_run_stats(JsonWriter& w, const RunResult& rr) {
  const NavigatorStats& st = rr.stats;
  auto count = [](std::uint64_t n) { return static_cast<std::int64_t>(n); };
  w.begin_object("stats")
      .integer("samples", count(st.samples))
      .integer("epochs", count(st.epochs))
      .integer("records", count(st.records))
      .num("t_start_s", st.t_start)
      .num("t_end_s", st.t_end)
      .integer("velocity_updates", count(st.velocity_updates))
      .integer("velocity_rejected", count(st.velocity_rejected))
      .num("max_velocity_test_ratio", st.max_velocity_test_ratio)
      .integer("position_updates", count(st.position_updates))
      .integer("position_rejected", count(st.position_rejected))
      .num("max_position_test_ratio", st.max_position_test_ratio)
      .integer("velocity_steps", count(st.velocity_steps))
      .integer("position_steps", count(st.position_steps))
      .integer("covariance_checks", count(st.covariance_checks))
      .integer("covariance_not_pd", count(st.covariance_not_pd))
      .num("max_covariance_asymmetry", st.max_covariance_asymmetry)
      .integer("fault_events", count(rr.fault_events.size()))
      .end_object();
}

void write_timing(JsonWriter& w, const JobTiming& tm, double total, const NavigatorStats& st) {
  w.begin_object("timing")
      .num("total_s", total)
      .num("dataset_s", tm.dataset)
      .boolean("dataset_generated", tm.generated)
      .num("setup_s", tm.setup)
      .num("navigate_s", tm.navigate)
      .num("finish_s", tm.finish)
      .num("filter_s", tm.filter)
      .num("velocity_step_s", st.velocity_step_seconds)
      .num("position_step_s", st.position_step_seconds)
      .num("started_unix", tm.started)
      .num("finished_unix", tm.finished)
      .str("host", tm.host)
      .end_object();
}

/// A job's result (kJobResultFormat); the time since `t_finish` is the job's finish time and
/// since `t0` its total.
std::string result_json(const Study& s, const Job& j, const PreparedDataset& data,
                        const std::vector<std::string>& modules, const eval::EvalResult& e, const RunResult& rr,
                        const std::vector<std::string>& warnings, JobTiming& tm,
                        std::chrono::steady_clock::time_point t_finish, std::chrono::steady_clock::time_point t0) {
  JsonWriter w;
  w.begin_object();
  w.str("format", kJobResultFormat);
  w.integer("job", static_cast<std::int64_t>(j.index));
  w.str("key", j.key);
  w.str("study", s.name());
  write_labels(w, s, j);
  w.str("configuration", j.configuration);
  w.begin_object("dataset").str("data", j.dataset.describe()).str("manifest", data.manifest.string());
  if (!j.dataset.cache_name.empty()) w.str("cache", j.dataset.cache_name);
  w.end_object();
  w.strings("modules", modules);
  w.raw("evaluation", eval::to_json(e));
  write_run_stats(w, rr);
  w.str("fault_report", rr.fault_report);
  w.strings("warnings", warnings);
  w.str("run_config", "dataset: " + data.manifest.string() + "\n" + j.run_yaml);
  w.str("canonical", j.canonical);
  tm.finish = since(t_finish);
  tm.finished = unix_now();
  write_timing(w, tm, since(t0), rr.stats);
  w.str("status", "done");
  w.end_object();
  return w.text();
}

/// A failed job's record (wheelins-study-failure-1).
std::string failure_json(const Study& s, const Job& j, const std::string& error,
                         const std::vector<std::string>& warnings, const JobTiming& tm) {
  JsonWriter w;
  w.begin_object();
  w.str("format", "wheelins-study-failure-1");
  w.integer("job", static_cast<std::int64_t>(j.index));
  w.str("key", j.key);
  w.str("study", s.name());
  write_labels(w, s, j);
  w.str("error", error);
  w.strings("warnings", warnings);
  w.str("canonical", j.canonical);
  w.num("started_unix", tm.started);
  w.num("failed_unix", unix_now());
  w.str("host", tm.host);
  w.str("status", "failed");
  w.end_object();
  return w.text();
}

/// A job's run request: its run settings over the dataset's manifest, nothing written, the
/// warnings collected (and, after manifest edits, a warning of the manifest an error).
RunRequest job_request(const Study& s, const Job& j, const JobOptions& o, const PreparedDataset& data,
                       const std::string& who, std::vector<std::string>& warnings) {
  const std::string where = "'" + s.file().string() + "': run settings of " + who;
  const RunConfig cfg = load_run_yaml(j.run_yaml, data.manifest, where);
  const WarningSink collect = [&warnings, who, warn = o.warn](const std::string& m) {
    warnings.push_back(m);
    if (warn) warn(who + ": " + m);
  };
  // An edited manifest must read without warnings: a misspelt key would be ignored.
  const WarningSink manifest_warn =
      j.dataset.manifest_edits.empty() ? collect : WarningSink([](const std::string& m) {
        throw InputError(m + " (after the study's manifest edits)");
      });
  RunRequest req = make_run_request(cfg, manifest_warn);
  req.output_dir.clear();
  req.progress = o.progress;
  req.warn = collect;
  if (!req.manifest.truth_file)
    throw InputError("'" + req.manifest.path.string() +
                     "': no truth file (key `truth`): a study evaluates every run against it");
  return req;
}

}  // namespace

JobOutcome run_job(const Study& s, const Job& j, const JobOptions& o) {
  JobOutcome out;
  JobTiming& tm = out.timing;
  tm.started = unix_now();
  tm.host = host_name();
  const auto t0 = std::chrono::steady_clock::now();
  const std::string who = "job " + std::to_string(j.index);
  std::error_code ec;
  fs::create_directories(s.jobs_dir(), ec);
  if (ec) throw InputError("'" + s.jobs_dir().string() + "': cannot create: " + ec.message());
  move_stale(s, j);
  // A result of these settings is being replaced (a rerun): it no longer counts as done.
  fs::remove(result_file(s, j.index), ec);

  std::vector<std::string> warnings;
  try {
    auto t = std::chrono::steady_clock::now();
    const PreparedDataset data = prepare_dataset(j.dataset, s.cache_dir());
    tm.dataset = since(t);
    tm.generated = data.generated;
    t = std::chrono::steady_clock::now();
    RunRequest req = job_request(s, j, o, data, who, warnings);
    // The evaluation `wheelins run` makes (run/evaluation.hpp): the truth streamed in step
    // with the run, so memory stays flat however long the data.
    req.evaluation = RunEvaluationRequest{std::nullopt, "", j.keep_series, "the vehicle solution of " + who};
    std::vector<TrajectoryRecord> track;
    std::size_t records = 0;
    req.on_record = [&](const TrajectoryRecord& r) {
      if (j.keep_series && records % 20 == 0) track.push_back(r);  // 1 Hz of the 20 Hz records
      ++records;
    };
    tm.setup = since(t);
    t = std::chrono::steady_clock::now();
    const RunResult rr = run_navigation(req);
    tm.navigate = since(t);
    tm.filter = rr.filter_seconds;
    t = std::chrono::steady_clock::now();
    if (!rr.evaluation_error.empty()) throw InputError(rr.evaluation_error);
    eval::EvalResult e = rr.evaluation.value();  // job_request made sure of the truth file
    std::vector<std::pair<fs::path, std::string>> side;
    if (j.keep_series) {
      std::vector<eval::EpochError> kept;  // 10 Hz of the 200 Hz truth epochs
      for (std::size_t k = 0; k < e.series.size(); k += 20) kept.push_back(e.series[k]);
      side.emplace_back(side_file(s, j.index, "series"), series_csv(kept));
      side.emplace_back(side_file(s, j.index, "track"), track_csv(track));
      e.series.clear();
    }
    out.summary = "drift " + fmt(100.0 * e.drift_rate, 3) + " %, heading " +
                  fmt(e.heading_rmse / kDeg, 2) + " deg";

    const std::string result = result_json(s, j, data, req.modules, e, rr, warnings, tm, t, t0);

    t = std::chrono::steady_clock::now();
    for (const auto& [file, text] : side) write_file_atomic(file, text, shared_file(file));
    const fs::path path = result_file(s, j.index);
    write_file_atomic(path, result, shared_file(path), o.write_chunk);
    tm.write = since(t);
  } catch (const Interrupted&) {
    throw;  // Ctrl-C or a kill: not a failure of the job (nothing of it is written)
  } catch (const std::exception& e) {
    out.error = e.what();
    // A result of these settings from before (a rerun) is not this run's: leave none behind.
    fs::remove(result_file(s, j.index), ec);
    const fs::path path = failure_file(s, j.index);
    write_file_atomic(path, failure_json(s, j, out.error, warnings, tm), shared_file(path));
    return out;
  }
  fs::remove(failure_file(s, j.index), ec);
  out.ok = true;
  if (!s.keep_datasets() && j.dataset.sim) delete_dataset_when_done(s, j);
  return out;
}

JobStatus job_status(const Study& s, const Job& j) {
  JobStatus st;
  std::string text;
  if (read_file(result_file(s, j.index), text)) {
    const std::string key = key_in(text);
    if (!key.empty() && key != j.key) {
      st.state = JobState::kStale;
      st.detail = "jobs/" + std::to_string(j.index) +
                  ".json holds a result of other settings (key " + key + ", the study now gives " +
                  j.key + ")";
      return st;
    }
    const std::string tail = kJobResultTail;
    if (key.empty() || text.size() < tail.size() ||
        text.compare(text.size() - tail.size(), tail.size(), tail) != 0) {
      st.state = JobState::kUnreadable;
      st.detail = "jobs/" + std::to_string(j.index) + ".json is not a complete result";
      return st;
    }
    st.state = JobState::kDone;
    return st;
  }
  if (read_file(failure_file(s, j.index), text) && key_in(text) == j.key) {
    st.state = JobState::kFailed;
    try {
      const YAML::Node n = parse_yaml(text, "failure record", "failure record");
      st.detail = n["error"].as<std::string>();
    } catch (const YAML::Exception&) {
      st.detail = "(the failure record cannot be read)";
    } catch (const InputError&) {
      st.detail = "(the failure record cannot be read)";
    }
  }
  return st;
}

std::vector<std::size_t> parse_job_list(const std::string& text, std::size_t count) {
  std::vector<std::size_t> out;
  std::stringstream ss(text);
  auto number = [&](const std::string& s) {
    std::size_t used = 0;
    unsigned long long v = 0;
    try {
      v = std::stoull(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (s.empty() || used != s.size() || s[0] == '-' || s[0] == '+')
      throw InputError("--job '" + text + "': '" + s + "' is not a job number");
    if (v >= count)
      throw InputError("--job '" + text + "': job " + s +
                       " does not exist (the study has jobs 0.." + std::to_string(count - 1) + ")");
    return static_cast<std::size_t>(v);
  };
  for (std::string item; std::getline(ss, item, ',');) {
    if (item.empty()) continue;
    const auto dash = item.find('-', 1);
    if (dash == std::string::npos) {
      out.push_back(number(item));
      continue;
    }
    const std::size_t a = number(item.substr(0, dash)), b = number(item.substr(dash + 1));
    if (b < a) throw InputError("--job '" + text + "': the range " + item + " is empty");
    for (std::size_t k = a; k <= b; ++k) out.push_back(k);
  }
  if (out.empty()) throw InputError("--job '" + text + "': no job given");
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

namespace {

/// The jobs of `given` (all when empty) to run: those not done (all with `rerun`), their run
/// settings checked. Counts them into `sum`.
std::vector<Job> pending_jobs(const Study& s, const std::vector<std::size_t>& given, bool rerun,
                              RunSummary& sum) {
  std::vector<std::size_t> indices = given;
  if (indices.empty())
    for (std::size_t k = 0; k < s.job_count(); ++k) indices.push_back(k);
  sum.requested = indices.size();
  std::vector<Job> pending;
  std::set<std::string> checked;
  for (std::size_t k : indices) {
    Job j = s.job(k);
    if (!rerun && job_status(s, j).state == JobState::kDone) {
      ++sum.already_done;
      continue;
    }
    if (checked.insert(j.run_yaml).second)
      check_run_yaml(j.run_yaml, "'" + s.file().string() + "': run settings of job " +
                                     std::to_string(k) + " (" + j.describe() + ")");
    pending.push_back(std::move(j));
  }
  return pending;
}

/// The worker threads of run_jobs: each takes the next pending job until none is left, an
/// error that is not a job's failure happens (`fatal_`) or an interrupt; the counts, the
/// summary and the progress line are shared under `mutex_`.
class JobWorkers {
 public:
  JobWorkers(const Study& s, const RunOptions& o, const std::vector<Job>& pending,
             RunSummary& sum, std::chrono::steady_clock::time_point t0)
      : s_(s), o_(o), pending_(pending), sum_(sum), t0_(t0),
        tty_(o.progress && ::isatty(STDERR_FILENO)), total_(pending.size()) {}

  /// Runs the jobs on `workers` threads; rethrows `fatal_`, or Interrupted.
  void run(int workers);

 private:
  void progress_line();
  void work();
  void finished_job(const Job& j, const JobOutcome& r);

  const Study& s_;
  const RunOptions& o_;
  const std::vector<Job>& pending_;
  RunSummary& sum_;
  const std::chrono::steady_clock::time_point t0_;
  const bool tty_;
  const std::size_t total_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::atomic<std::size_t> next_{0};
  std::size_t finished_ = 0, running_ = 0;
  std::exception_ptr fatal_;
};

void JobWorkers::progress_line() {
  const double el = since(t0_);
  std::string line = "\rstudy " + s_.name() + ": " + std::to_string(finished_) + "/" +
                     std::to_string(total_) + " jobs";
  if (sum_.already_done) line += " (+" + std::to_string(sum_.already_done) + " done before)";
  if (sum_.failed) line += ", " + std::to_string(sum_.failed) + " failed";
  line += ", " + std::to_string(running_) + " running, " + fmt(el, 0) + " s elapsed";
  if (finished_ > 0 && finished_ < total_)
    line += ", ~" +
            fmt(el * static_cast<double>(total_ - finished_) / static_cast<double>(finished_), 0) +
            " s left";
  std::fprintf(stderr, "%s   ", line.c_str());
  std::fflush(stderr);
}

void JobWorkers::work() {
  for (std::size_t i = next_++; i < total_; i = next_++) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (fatal_ || interrupt_requested()) return;
      ++running_;
    }
    JobOutcome r;
    try {
      r = run_job(s_, pending_[i], o_.job);
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!fatal_) fatal_ = std::current_exception();
      --running_;
      cv_.notify_all();
      return;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    finished_job(pending_[i], r);
  }
}

/// Counts and logs a finished job (under `mutex_`).
void JobWorkers::finished_job(const Job& j, const JobOutcome& r) {
  --running_;
  ++finished_;
  std::string line = "[" + std::to_string(finished_) + "/" + std::to_string(total_) + "] job " +
                     std::to_string(j.index) + " (" + j.describe() + "): ";
  if (r.ok) {
    ++sum_.done;
    line += r.summary + " (" + fmt(r.timing.finished - r.timing.started, 1) + " s" +
            (r.timing.generated ? ", dataset simulated" : "") + ")";
  } else {
    ++sum_.failed;
    sum_.failures.emplace_back(j.index, r.error);
    line += "FAILED: " + r.error;
  }
  if (o_.log && (!tty_ || !r.ok)) {
    if (tty_) std::fprintf(stderr, "\r%*s\r", 100, "");
    *o_.log << line << std::endl;
  }
  if (tty_) progress_line();
  cv_.notify_all();
}

void JobWorkers::run(int workers) {
  std::vector<std::thread> threads;
  for (int k = 0; k < workers; ++k) threads.emplace_back([this] { work(); });
  {
    std::unique_lock<std::mutex> lock(mutex_);
    while (finished_ < total_ && !((fatal_ || interrupt_requested()) && running_ == 0)) {
      cv_.wait_for(lock, std::chrono::milliseconds(interrupt_requested() ? 50 : 1000));
      if (tty_) progress_line();
    }
  }
  for (auto& t : threads) t.join();
  if (tty_) std::fprintf(stderr, "\n");
  if (fatal_) std::rethrow_exception(fatal_);
  check_interrupt();  // interrupted between jobs
}

}  // namespace

RunSummary run_jobs(const Study& s, const std::vector<std::size_t>& given, const RunOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  RunSummary sum;
  // Resolved before the workers start: a bad setting stops the run before any job.
  const std::vector<Job> pending = pending_jobs(s, given, o.rerun, sum);
  if (pending.empty()) {
    sum.seconds = since(t0);
    return sum;
  }
  std::error_code ec;
  fs::create_directories(s.jobs_dir(), ec);
  if (ec) throw InputError("'" + s.jobs_dir().string() + "': cannot create: " + ec.message());

  JobWorkers pool(s, o, pending, sum, t0);
  pool.run(std::max(1, std::min<int>(o.workers, static_cast<int>(pending.size()))));
  std::sort(sum.failures.begin(), sum.failures.end());
  sum.seconds = since(t0);
  return sum;
}

}  // namespace wheelins::study
