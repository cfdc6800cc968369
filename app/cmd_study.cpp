// `wheelins study plan|run|report`: many runs declared in one file (docs/studies.md).
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <set>
#include <thread>

#include "cli.hpp"
#include "wheelins/study/job.hpp"
#include "wheelins/study/report.hpp"
#include "wheelins/study/spec.hpp"
#include "wheelins/util/interrupt.hpp"

namespace {
using namespace wheelins;
using namespace wheelins::study;
namespace fs = std::filesystem;

struct Args {
  std::string file, results, cache, jobs;
  int workers = 0;
  bool count = false, rerun = false, quiet = false, no_plots = false, no_report = false,
       strict = false;
};

Study load(const Args& a) {
  LoadOptions o;
  o.results_dir = a.results;
  o.cache_dir = a.cache;
  return Study::load(a.file, o);
}

std::string dims_text(const Study& s) {
  std::string d;
  for (const auto& ax : s.axes())
    d += (d.empty() ? "" : " x ") + std::to_string(ax.values.size()) + " " + ax.name;
  return d.empty() ? "one job" : d;
}

void print_report_lines(const Report& r, const Study& s) {
  for (const auto& f : r.files)
    if (f.parent_path() == s.results_dir() || f.extension() == ".png")
      std::cout << "wrote " << f.string() << "\n";
  if (!r.not_done.empty()) {
    std::cout << r.not_done.size() << " of " << r.jobs.size() << " jobs are not in the report:\n";
    const std::size_t shown = std::min<std::size_t>(r.not_done.size(), 20);
    for (std::size_t i = 0; i < shown; ++i) std::cout << "  " << r.not_done[i] << "\n";
    if (shown < r.not_done.size()) std::cout << "  ... (all of them in report.md / jobs.csv)\n";
  }
  std::printf(
      "%zu of %zu jobs in the report; their run time %.1f s in total, %.1f s from the first start "
      "to the "
      "last finish\n",
      r.done, r.jobs.size(), r.job_seconds, r.span_seconds);
}

int plan(const Args& a) {
  const Study s = load(a);
  if (a.count) {
    std::cout << s.job_count() << "\n";
    return 0;
  }
  const std::vector<Job> jobs = s.check_all();
  std::printf("study %s ('%s'): %zu jobs = %s\n", s.name().c_str(), s.file().c_str(), jobs.size(),
              dims_text(s).c_str());
  std::printf("results  %s\ncache    %s\n", s.results_dir().c_str(), s.cache_dir().c_str());
  std::set<std::string> data, cached;
  std::size_t states[5] = {0, 0, 0, 0, 0};
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> head{"job"};
  for (const auto& ax : s.axes()) head.push_back(ax.name);
  head.push_back("data");
  head.push_back("state");
  rows.push_back(head);
  for (const auto& j : jobs) {
    if (j.dataset.sim && data.insert(j.dataset.cache_name).second) {
      std::string text;
      if (read_file(s.cache_dir() / j.dataset.cache_name / "settings.txt", text) &&
          text == j.dataset.canonical)
        cached.insert(j.dataset.cache_name);
    }
    const JobStatus st = job_status(s, j);
    ++states[static_cast<int>(st.state)];
    std::vector<std::string> row{std::to_string(j.index)};
    for (const auto& l : j.labels) row.push_back(l);
    row.push_back(j.dataset.describe());
    row.push_back(job_state_name(st.state));
    rows.push_back(row);
  }
  if (!data.empty())
    std::printf("datasets %zu to simulate (%zu of them already in the cache)\n", data.size(),
                cached.size());
  std::printf(
      "state    %zu done, %zu failed, %zu stale, %zu unreadable, %zu to run\n\n",
      states[static_cast<int>(JobState::kDone)], states[static_cast<int>(JobState::kFailed)],
      states[static_cast<int>(JobState::kStale)], states[static_cast<int>(JobState::kUnreadable)],
      states[static_cast<int>(JobState::kMissing)]);
  std::vector<std::size_t> width(head.size(), 0);
  for (const auto& r : rows)
    for (std::size_t i = 0; i < r.size(); ++i) width[i] = std::max(width[i], r[i].size());
  for (const auto& r : rows) {
    std::string line;
    for (std::size_t i = 0; i < r.size(); ++i) {
      std::string cell = r[i];
      if (i == 0)
        cell = std::string(width[i] - cell.size(), ' ') + cell;
      else if (i + 1 < r.size())
        cell += std::string(width[i] - cell.size(), ' ');
      line += (i ? "  " : "") + cell;
    }
    std::cout << line << "\n";
  }
  return 0;
}

int run(const Args& a) {
  const Study s = load(a);
  std::vector<std::size_t> list;
  if (!a.jobs.empty()) list = parse_job_list(a.jobs, s.job_count());
  RunOptions o;
  o.workers = a.workers > 0    ? a.workers
              : a.jobs.empty() ? static_cast<int>(std::max(1u, std::thread::hardware_concurrency()))
                               : 1;
  o.rerun = a.rerun;
  o.progress = !a.quiet;
  o.log = a.quiet ? nullptr : &std::cout;
  o.job.warn = stderr_sink();
  o.job.progress = !a.quiet && list.size() == 1 && ::isatty(STDERR_FILENO);
  if (!a.quiet && list.empty())
    std::printf("study %s: %zu jobs (%s) on %d threads; results in %s\n", s.name().c_str(),
                s.job_count(), dims_text(s).c_str(), o.workers, s.results_dir().c_str());
  std::cout << std::flush;
  RunSummary r;
  try {
    r = run_jobs(s, list, o);
  } catch (const Interrupted&) {
    std::size_t done = 0;
    for (std::size_t k = 0; k < s.job_count(); ++k) done += job_status(s, s.job(k)).state == JobState::kDone;
    std::cerr << "\nerror: interrupted; " << done << " of " << s.job_count()
              << " jobs are done and kept (the running ones wrote nothing): run the same command again to do "
                 "the rest\n";
    return 130;
  }
  if (!a.quiet) {
    if (r.already_done == r.requested)
      std::printf("%s already done (--rerun runs again)\n",
                  r.requested == 1 ? ("job " + a.jobs).c_str()
                                   : ("all " + std::to_string(r.requested) + " jobs").c_str());
    else
      std::printf("%zu jobs run in %.1f s: %zu done, %zu failed%s\n", r.done + r.failed, r.seconds,
                  r.done, r.failed,
                  r.already_done
                      ? (" (" + std::to_string(r.already_done) + " were done before)").c_str()
                      : "");
  }
  for (const auto& [k, e] : r.failures) std::cerr << "error: job " << k << " failed: " << e << "\n";
  if (list.empty() && !a.no_report && r.done + r.already_done > 0) {
    ReportOptions ro;
    ro.plots = !a.no_plots;
    ro.warn = stderr_sink();
    const Report rep = write_report(s, ro);
    if (!a.quiet) print_report_lines(rep, s);
  }
  return r.failed ? 1 : 0;
}

int report(const Args& a) {
  const Study s = load(a);
  ReportOptions ro;
  ro.plots = !a.no_plots;
  ro.warn = stderr_sink();
  const Report r = write_report(s, ro);
  if (!a.quiet) {
    std::cout << r.markdown;
    print_report_lines(r, s);
  }
  return a.strict && !r.not_done.empty() ? 3 : 0;
}

void common(CLI::App* c, Args& a) {
  c->add_option("study", a.file, "Study file (YAML; docs/studies.md)")->required();
  c->add_option("--results", a.results, "Results directory (default: the study's `results`)");
  c->add_option("--cache", a.cache, "Dataset cache directory (default: the study's `cache`)");
}

const bool registered = cli::register_command(
    45, "study", "Sweeps and Monte-Carlo studies: plan, run (sharded or on all cores), report",
    [](CLI::App& sub) {
      auto a = std::make_shared<Args>();
      sub.require_subcommand(1);
      CLI::App* p = sub.add_subcommand("plan", "List the study's jobs, their count and state");
      common(p, *a);
      p->add_flag("--count", a->count, "Print only the number of jobs (for job arrays)");
      CLI::App* r =
          sub.add_subcommand("run", "Run the study's jobs (all not done on all cores, or --job K)");
      common(r, *a);
      r->add_option("--job", a->jobs,
                    "Only these jobs: K, A-B or a comma list (0-based, as `plan` lists)");
      r->add_option("--threads,-j", a->workers, "Jobs at once (default: all cores; 1 with --job)")
          ->check(CLI::Range(1, 1024));
      r->add_flag("--rerun", a->rerun, "Run jobs that are done too (their results are replaced)");
      r->add_flag("--no-report", a->no_report, "Do not write the report after running every job");
      r->add_flag("--no-plots", a->no_plots, "Report without plots");
      r->add_flag("--quiet,-q", a->quiet, "No progress and no summary");
      CLI::App* rep =
          sub.add_subcommand("report", "Merge the finished jobs: tables, CSV, JSON and plots");
      common(rep, *a);
      rep->add_flag("--no-plots", a->no_plots, "Skip the plots");
      rep->add_flag("--strict", a->strict, "Exit 3 when a job is not done");
      rep->add_flag("--quiet,-q", a->quiet, "Do not print the report");
      return [a, p, r]() {
        if (p->parsed()) return plan(*a);
        if (r->parsed()) return run(*a);
        return report(*a);
      };
    });
}  // namespace
