// The report of a study (report.hpp): the jobs' results merged per condition and
// configuration, statistics and paired differences, plots, and the experiment's tables.
#include "wheelins/study/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/manifest.hpp"
#include "wheelins/io/truth.hpp"
#include "wheelins/nav/types.hpp"
#include "wheelins/run/experiment.hpp"
#include "wheelins/study/json.hpp"
#include "wheelins/study/report_data.hpp"
#include "wheelins/study/stats.hpp"

namespace wheelins::study {
namespace fs = std::filesystem;
using namespace report_detail;

namespace {

std::string fmt(double v, int decimals) {
  if (!std::isfinite(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  const std::string t = buf;
  if (t[0] == '-' && t.find_first_of("123456789") == std::string::npos)
    return t.substr(1);  // no "-0.00"
  return t;
}
std::string csv_field(std::string s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string o = "\"";
  for (char c : s) o += c == '"' ? std::string("\"\"") : std::string(1, c);
  return o + "\"";
}
std::string md_cell(std::string s) {
  for (std::size_t p = 0; (p = s.find('|', p)) != std::string::npos; p += 2) s.replace(p, 1, "\\|");
  for (char& c : s)
    if (c == '\n') c = ' ';
  return s;
}

struct Paired {
  Summary s;
  std::size_t b_lower = 0;
};

Paired paired(const std::vector<const JobRecord*>& a, const std::vector<const JobRecord*>& b,
              int metric, const IntervalOptions& o) {
  std::vector<double> d;
  Paired p;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!a[i] || !b[i]) continue;
    const double x = kMetrics[metric].get(*a[i]), y = kMetrics[metric].get(*b[i]);
    if (!std::isfinite(x) || !std::isfinite(y)) continue;
    d.push_back(y - x);
    p.b_lower += y < x;
  }
  p.s = summarize(d, o);
  return p;
}

std::string cell(const Summary& s, int decimals, std::size_t full) {
  if (s.n == 0) return "-";
  std::string t = fmt(s.mean, decimals);
  if (s.n >= 2)
    t +=
        " ± " + fmt(s.sd, decimals) + " [" + fmt(s.lo, decimals) + ", " + fmt(s.hi, decimals) + "]";
  if (s.n < full) t += " (n = " + std::to_string(s.n) + ")";
  return t;
}

std::string axis_role_name(AxisRole r) {
  return r == AxisRole::kCondition   ? "condition"
         : r == AxisRole::kReplicate ? "replicate"
                                     : "configuration";
}

// --- The generic report -----------------------------------------------------------------

Report generic_report(const Study& s, std::vector<JobEntry> jobs, const ReportOptions& o) {
  Report rep;
  const Layout L(s);
  const Grid g = grid_of(s, L, jobs);
  const IntervalOptions& io = s.interval();
  const auto& axes = s.axes();
  const fs::path dir = s.results_dir();
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw InputError("'" + dir.string() + "': cannot create: " + ec.message());

  std::vector<std::string> cond_names;
  for (std::size_t a : L.cond) cond_names.push_back(axes[a].name);
  std::string rep_names;
  for (std::size_t a : L.rep) rep_names += (rep_names.empty() ? "" : " x ") + axes[a].name;

  for (const auto& e : jobs)
    if (e.record) ++rep.done;
  std::vector<const JobEntry*> not_done;
  for (const auto& e : jobs)
    if (!e.record) not_done.push_back(&e);

  // report.md
  std::ostringstream md;
  md << "# Study: " << s.name() << "\n\n";
  if (!s.description().empty()) md << s.description() << "\n\n";
  md << "Study file `" << s.file().string() << "`: " << jobs.size() << " jobs";
  {
    std::string dims;
    for (const auto& a : axes)
      dims += (dims.empty() ? "" : " x ") + std::to_string(a.values.size()) + " " + a.name;
    if (!dims.empty()) md << " (" << dims << ")";
  }
  md << "; " << rep.done << " in this report";
  if (!not_done.empty()) md << ", **" << not_done.size() << " not done** (listed at the end)";
  md << ".\n\n";
  md << "Each cell: mean ± standard deviation ["
     << interval_description(io.method, io.confidence, io.resamples) << "] over the "
     << (rep_names.empty() ? "jobs" : rep_names + " replicates") << " (n = " << L.replicates
     << " per cell unless noted). Drift rate: paper Section VI-B (l = 100 m) in % of the distance; "
        "heading RMSE "
        "in degrees; every run evaluated against the truth as `wheelins evaluate` does.\n\n";
  auto header = [&](std::ostream& os, const std::vector<std::string>& columns) {
    os << "|";
    if (cond_names.empty()) os << " data |";
    for (const auto& c : cond_names) os << " " << md_cell(c) << " |";
    for (const auto& c : columns) os << " " << md_cell(c) << " |";
    os << "\n|";
    for (std::size_t i = 0; i < std::max<std::size_t>(1, cond_names.size()) + columns.size(); ++i)
      os << "---|";
    os << "\n";
  };
  auto row_start = [&](std::ostream& os, std::size_t c) {
    os << "|";
    if (cond_names.empty()) os << " " << md_cell(s.name()) << " |";
    for (const auto& l : L.labels(c, L.cond, s)) os << " " << md_cell(l) << " |";
  };
  for (int metric : {kDrift, kHeading}) {
    const Metric& m = kMetrics[metric];
    md << "## " << m.title << " (" << m.unit << ")\n\n";
    header(md, L.config_labels);
    for (std::size_t c = 0; c < L.conditions; ++c) {
      row_start(md, c);
      for (std::size_t k = 0; k < L.configurations; ++k)
        md << " "
           << cell(summarize(values_of(g.records[c][k], metric), io), m.decimals, L.replicates)
           << " |";
      md << "\n";
    }
    md << "\n";
  }
  // The pairs compared: the study's `compare`, else every configuration against the first.
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  std::vector<std::string> titles;
  for (const auto& [a, b] : s.compare()) {
    const auto ia = std::find(L.config_labels.begin(), L.config_labels.end(), a) - L.config_labels.begin();
    const auto ib = std::find(L.config_labels.begin(), L.config_labels.end(), b) - L.config_labels.begin();
    pairs.emplace_back(static_cast<std::size_t>(ia), static_cast<std::size_t>(ib));
    titles.push_back(b + " - " + a);
  }
  std::vector<std::pair<std::size_t, std::size_t>> plot_pairs = pairs;
  if (plot_pairs.empty())
    for (std::size_t k = 1; k < L.configurations; ++k) plot_pairs.emplace_back(0, k);
  if (!s.compare().empty()) {
    md << "## Paired differences (B - A on the same data)\n\n"
       << "Each cell: mean of the differences B - A over the replicates both have ± their standard "
          "deviation ["
       << interval_description(io.method, io.confidence, io.resamples)
       << " of the differences]; then in how many pairs B was lower. Negative: B is better. An "
          "interval "
          "that excludes 0 means the difference is larger than the spread between replicates "
          "explains.\n\n";
    for (int metric : {kDrift, kHeading}) {
      const Metric& m = kMetrics[metric];
      md << "### " << m.title << " (" << m.unit << ")\n\n";
      header(md, titles);
      for (std::size_t c = 0; c < L.conditions; ++c) {
        row_start(md, c);
        for (const auto& [a, b] : pairs) {
          const Paired p = paired(g.records[c][a], g.records[c][b], metric, io);
          md << " " << cell(p.s, m.decimals, L.replicates);
          if (p.s.n > 0) md << "; lower in " << p.b_lower << "/" << p.s.n;
          md << " |";
        }
        md << "\n";
      }
      md << "\n";
    }
  }
  md << "## Consistency (means over the replicates)\n\n"
     << "Share of epochs whose horizontal error is within 3 sigma of the filter's own north/east "
        "covariance "
        "(>= 89 % if the filter is consistent) / mean horizontal NEES (2 if consistent).\n\n";
  header(md, L.config_labels);
  for (std::size_t c = 0; c < L.conditions; ++c) {
    row_start(md, c);
    for (std::size_t k = 0; k < L.configurations; ++k) {
      const Summary a = summarize(values_of(g.records[c][k], k3Sigma), io);
      const Summary b = summarize(values_of(g.records[c][k], kNees), io);
      md << " " << (a.n ? fmt(a.mean, 1) + " % / " + fmt(b.mean, 2) : std::string("-")) << " |";
    }
    md << "\n";
  }
  md << "\n";

  // Plots.
  PlotFiles plots;
  if (o.plots && rep.done > 0) {
    add_metric_plot(plots, s, L, g, kDrift, "drift");
    add_metric_plot(plots, s, L, g, kHeading, "heading");
    md << "## Plots\n\n`plots/drift.png`, `plots/heading.png`: per condition (x axis) and "
          "configuration, the mean (square) and its "
       << interval_description(io.method, io.confidence, io.resamples)
       << " (error bars), with every job as a small point";
    if (!plot_pairs.empty()) {
      add_paired_plot(plots, s, L, g, kDrift, plot_pairs, "paired_drift");
      md << "; `plots/paired_drift.png`: the paired differences B - A of the drift rate, run by run on the "
            "same data ("
         << (s.compare().empty() ? "every configuration against the first" : "the study's `compare` pairs")
         << "), each pair a small point, their mean and its interval; below the dashed zero line B is better";
    }
    md << " (data in `plots/data/`, gnuplot scripts `plots/*.gp`).\n\n";
  }

  if (!not_done.empty()) {
    md << "## Jobs not in this report\n\n| job | state | ";
    for (const auto& a : axes) md << md_cell(a.name) << " | ";
    md << "detail |\n|---|---|";
    for (std::size_t i = 0; i < axes.size(); ++i) md << "---|";
    md << "---|\n";
    for (const auto* e : not_done) {
      md << "| " << e->job.index << " | " << job_state_name(e->status.state) << " | ";
      for (const auto& l : e->job.labels) md << md_cell(l) << " | ";
      md << md_cell(e->status.detail) << " |\n";
      rep.not_done.push_back("job " + std::to_string(e->job.index) + " (" + e->job.describe() +
                             "): " + job_state_name(e->status.state) +
                             (e->status.detail.empty() ? "" : ": " + e->status.detail));
    }
    md << "\n";
  }
  rep.markdown = md.str();

  // summary.csv, differences.csv
  std::string header_csv;
  for (const auto& c : cond_names) header_csv += csv_field(c) + ",";
  auto cond_csv = [&](std::size_t c) {
    std::string t;
    for (const auto& l : L.labels(c, L.cond, s)) t += csv_field(l) + ",";
    return t;
  };
  std::string summary_csv = header_csv + "configuration,metric,n,mean,sd,ci_lo,ci_hi\n";
  std::string diff_csv = header_csv + "a,b,metric,n,mean_b_minus_a,sd,ci_lo,ci_hi,b_lower\n";
  JsonWriter js;
  js.begin_object();
  js.str("format", "wheelins-study-report-1");
  js.str("study", s.name());
  js.str("file", s.file().string());
  js.begin_object("interval")
      .str("method", interval_method_name(io.method))
      .num("confidence", io.confidence)
      .str("description", interval_description(io.method, io.confidence, io.resamples))
      .end_object();
  js.begin_array("axes");
  for (const auto& a : axes) {
    std::vector<std::string> labels;
    for (const auto& v : a.values) labels.push_back(v.label);
    js.begin_object()
        .str("name", a.name)
        .str("role", axis_role_name(a.role))
        .strings("values", labels)
        .end_object();
  }
  js.end_array();
  js.begin_object("jobs")
      .integer("total", static_cast<std::int64_t>(jobs.size()))
      .integer("done", static_cast<std::int64_t>(rep.done));
  js.begin_array("not_done");
  for (const auto* e : not_done)
    js.begin_object()
        .integer("job", static_cast<std::int64_t>(e->job.index))
        .str("state", job_state_name(e->status.state))
        .strings("labels", e->job.labels)
        .str("detail", e->status.detail)
        .end_object();
  js.end_array().end_object();
  auto cond_json = [&](std::size_t c) {
    js.begin_object("condition");
    const auto labels = L.labels(c, L.cond, s);
    for (std::size_t i = 0; i < labels.size(); ++i) js.str(cond_names[i].c_str(), labels[i]);
    js.end_object();
  };
  auto stat_json = [&](const char* key, const Summary& sm) {
    js.begin_object(key)
        .integer("n", static_cast<std::int64_t>(sm.n))
        .num("mean", sm.mean)
        .num("sd", sm.sd)
        .num("ci_lo", sm.lo)
        .num("ci_hi", sm.hi);
  };
  js.begin_array("summary");
  for (std::size_t c = 0; c < L.conditions; ++c)
    for (std::size_t k = 0; k < L.configurations; ++k) {
      js.begin_object();
      cond_json(c);
      js.str("configuration", L.config_labels[k]);
      js.begin_object("metrics");
      for (int m = 0; m < kMetricCount; ++m) {
        const Summary sm = summarize(values_of(g.records[c][k], m), io);
        summary_csv += cond_csv(c) + csv_field(L.config_labels[k]) + "," + kMetrics[m].key + "," +
                       std::to_string(sm.n) + "," + exact(sm.mean) + "," + exact(sm.sd) + "," +
                       exact(sm.lo) + "," + exact(sm.hi) + "\n";
        stat_json(kMetrics[m].key, sm);
        js.end_object();
      }
      js.end_object().end_object();
    }
  js.end_array();
  js.begin_array("differences");
  for (std::size_t c = 0; c < L.conditions; ++c)
    for (const auto& [a, b] : s.compare()) {
      const std::size_t ia = static_cast<std::size_t>(
          std::find(L.config_labels.begin(), L.config_labels.end(), a) - L.config_labels.begin());
      const std::size_t ib = static_cast<std::size_t>(
          std::find(L.config_labels.begin(), L.config_labels.end(), b) - L.config_labels.begin());
      js.begin_object();
      cond_json(c);
      js.str("a", a).str("b", b);
      js.begin_object("metrics");
      for (int m = 0; m < kMetricCount; ++m) {
        const Paired p = paired(g.records[c][ia], g.records[c][ib], m, io);
        diff_csv += cond_csv(c) + csv_field(a) + "," + csv_field(b) + "," + kMetrics[m].key + "," +
                    std::to_string(p.s.n) + "," + exact(p.s.mean) + "," + exact(p.s.sd) + "," +
                    exact(p.s.lo) + "," + exact(p.s.hi) + "," + std::to_string(p.b_lower) + "\n";
        stat_json(kMetrics[m].key, p.s);
        js.integer("b_lower", static_cast<std::int64_t>(p.b_lower));
        js.end_object();
      }
      js.end_object().end_object();
    }
  js.end_array();
  js.end_object();

  // jobs.csv and timing.csv
  std::string jobs_csv = "job,";
  for (const auto& a : axes) jobs_csv += csv_field(a.name) + ",";
  jobs_csv += "state,";
  for (const auto& m : kMetrics) jobs_csv += std::string(m.key) + ",";
  jobs_csv += "distance_m,epochs,fault_events,modules,data,detail\n";
  std::string timing_csv =
      "job,state,host,dataset_generated,dataset_s,setup_s,navigate_s,finish_s,filter_s,started_"
      "unix,finished_unix\n";
  double first = INFINITY, last = -INFINITY;
  for (const auto& e : jobs) {
    jobs_csv += std::to_string(e.job.index) + ",";
    for (const auto& l : e.job.labels) jobs_csv += csv_field(l) + ",";
    jobs_csv += std::string(job_state_name(e.status.state)) + ",";
    std::string mods;
    if (e.record) {
      for (const auto& m : kMetrics) jobs_csv += exact(m.get(*e.record)) + ",";
      jobs_csv += exact(e.record->eval.distance) + "," + std::to_string(e.record->stats.epochs) +
                  "," + std::to_string(e.record->fault_events) + ",";
      for (const auto& m : e.record->modules) mods += (mods.empty() ? "" : "+") + m;
      const JobTiming& t = e.record->timing;
      timing_csv += std::to_string(e.job.index) + ",done," + csv_field(t.host) + "," +
                    (t.generated ? "1" : "0") + "," + exact(t.dataset) + "," + exact(t.setup) +
                    "," + exact(t.navigate) + "," + exact(t.finish) + "," + exact(t.filter) + "," +
                    exact(t.started) + "," + exact(t.finished) + "\n";
      rep.job_seconds += t.finished - t.started;
      first = std::min(first, t.started);
      last = std::max(last, t.finished);
    } else {
      for (int m = 0; m < kMetricCount; ++m) jobs_csv += ",";
      jobs_csv += ",,,";
    }
    jobs_csv += csv_field(mods) + "," + csv_field(e.job.dataset.describe()) + "," +
                csv_field(e.status.detail) + "\n";
  }
  rep.span_seconds = rep.done ? last - first : 0.0;

  const std::vector<std::pair<std::string, std::string>> files = {
      {"report.md", rep.markdown}, {"summary.csv", summary_csv}, {"differences.csv", diff_csv},
      {"jobs.csv", jobs_csv},      {"report.json", js.text()},   {"timing.csv", timing_csv}};
  // The report replaces only what a report wrote here (files.hpp): every file is checked
  // before the first is written.
  ReportFiles ours(dir);
  auto first_line = [](const std::string& t) { return t.substr(0, t.find('\n')); };
  for (const auto& [name, text] : files) ours.check(name, first_line(text));
  std::vector<fs::path> written;
  if (!plots.names.empty()) {
    for (const auto& [rel, text] : plots.files) ours.check(fs::path("plots") / rel, first_line(text));
    if (o.plot.render)
      for (const auto& n : plots.names) ours.check(fs::path("plots") / (n + ".png"), "\x89PNG\r");
  }
  for (const auto& [name, text] : files) {
    write_file_atomic(dir / name, text);
    rep.files.push_back(dir / name);
    written.push_back(name);
  }
  if (!plots.names.empty()) {
    const fs::path pdir = dir / "plots";
    fs::create_directories(pdir / "data", ec);
    for (const auto& [rel, text] : plots.files) {
      write_file_atomic(pdir / rel, text);
      rep.files.push_back(pdir / rel);
      written.push_back(fs::path("plots") / rel);
    }
    if (o.plot.render)
      for (auto& f : eval::render_gnuplot(pdir, plots.names, o.warn, o.plot)) {
        written.push_back(fs::path("plots") / f.filename());
        rep.files.push_back(std::move(f));
      }
  }
  ours.add(written);
  rep.jobs = std::move(jobs);
  return rep;
}

// --- The experiment -----------------------------------------------------------------------

const char* const kExperimentFiles[] = {"experiment.md", "runs.csv", "experiment.json"};

Report experiment_report(const Study& s, std::vector<JobEntry> jobs, const ReportOptions& o) {
  Report rep;
  const ExperimentSpec& x = *s.experiment();
  const Manifest m = load_manifest(x.dataset, o.warn);
  if (!m.truth_file)
    throw InputError("'" + x.dataset.string() +
                     "': the experiment needs a truth file (key 'truth')");
  eval::ExperimentResult r;
  r.manifest = m.path;
  r.dataset_name = m.name;
  r.truth_file = m.resolve(*m.truth_file);
  r.origin = m.origin;
  r.duration = x.duration;
  double first = INFINITY, last = -INFINITY;
  for (const auto& e : jobs) {
    if (!e.record) {
      rep.not_done.push_back("job " + std::to_string(e.job.index) + " (" + e.job.describe() +
                             "): " + job_state_name(e.status.state) +
                             (e.status.detail.empty() ? "" : ": " + e.status.detail));
      continue;
    }
    ++rep.done;
    eval::ExperimentRun run = *e.job.experiment_run;
    const JobRecord& rec = *e.record;
    run.eval = rec.eval;
    run.eval.series = rec.series;
    run.track = rec.track;
    run.stats = rec.stats;
    run.fault_events = rec.fault_events;
    run.filter_seconds = rec.timing.filter;
    r.runs.push_back(std::move(run));
    rep.job_seconds += rec.timing.finished - rec.timing.started;
    first = std::min(first, rec.timing.started);
    last = std::max(last, rec.timing.finished);
  }
  if (r.runs.empty())
    throw InputError("'" + s.file().string() + "': no run of the experiment is done yet");
  rep.span_seconds = last - first;
  r.wall_seconds = rep.span_seconds;
  std::string md = eval::experiment_markdown(r);
  if (!rep.not_done.empty()) {
    md += "## Runs not in these tables\n\n";
    for (const auto& l : rep.not_done) md += "- " + l + "\n";
    md += "\n";
  }
  rep.markdown = md;
  const fs::path dir = s.results_dir();
  std::error_code ec;
  fs::create_directories(dir, ec);
  const std::string texts[] = {md, eval::experiment_csv(r), eval::experiment_json(r)};
  for (const char* f : kExperimentFiles) check_output_target(dir / f, o.overwrite);
  for (int i = 0; i < 3; ++i) {
    AtomicTextFile f(dir / kExperimentFiles[i], o.overwrite);
    f.write(texts[i]);
    f.commit();
    rep.files.push_back(dir / kExperimentFiles[i]);
  }
  if (o.plots) {
    const TruthData truth = read_truth(r.truth_file);
    for (auto& f : eval::write_experiment_plots(r, truth, earth::LocalFrame(r.origin), dir,
                                                o.overwrite, o.warn, o.plot))
      rep.files.push_back(std::move(f));
  }
  rep.jobs = std::move(jobs);
  return rep;
}

}  // namespace

std::vector<JobEntry> collect_jobs(const Study& s, bool with_series) {
  std::vector<JobEntry> out;
  const std::size_t n = s.job_count();
  out.reserve(n);
  for (std::size_t k = 0; k < n; ++k) {
    JobEntry e;
    e.job = s.job(k);
    e.status = job_status(s, e.job);
    if (e.status.state == JobState::kDone) {
      std::string error;
      e.record = read_job_record(s.jobs_dir() / (std::to_string(k) + ".json"), error,
                                 with_series && e.job.keep_series);
      if (!e.record) {
        e.status.state = JobState::kUnreadable;
        e.status.detail = error;
      } else if (e.record->canonical != e.job.canonical) {
        e.status.state = JobState::kStale;
        e.status.detail = "jobs/" + std::to_string(k) + ".json holds a result of other settings";
        e.record.reset();
      }
    }
    out.push_back(std::move(e));
  }
  return out;
}

std::vector<fs::path> experiment_report_targets(const Study& s, bool plots) {
  std::vector<fs::path> v;
  for (const char* f : kExperimentFiles) v.push_back(s.results_dir() / f);
  if (plots)
    for (auto& f : eval::experiment_plot_targets(s.results_dir())) v.push_back(std::move(f));
  return v;
}

Report write_report(const Study& s, const ReportOptions& o) {
  if (s.experiment()) return experiment_report(s, collect_jobs(s, true), o);
  return generic_report(s, collect_jobs(s), o);
}

}  // namespace wheelins::study
