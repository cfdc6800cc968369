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

// What the generic report's parts read: the study, its jobs laid out, and the jobs not done.
struct ReportContext {
  ReportContext(const Study& study, const std::vector<JobEntry>& jobs);

  const Study& s;
  const Layout L;
  const Grid g;
  const IntervalOptions& io;
  std::vector<std::string> cond_names;  ///< the condition axes' names
  std::string rep_names;                ///< the replicate axes' names ("a x b")
  std::vector<const JobEntry*> not_done;
};

ReportContext::ReportContext(const Study& study, const std::vector<JobEntry>& jobs)
    : s(study), L(study), g(grid_of(study, L, jobs)), io(study.interval()) {
  const auto& axes = s.axes();
  for (std::size_t a : L.cond) cond_names.push_back(axes[a].name);
  for (std::size_t a : L.rep) rep_names += (rep_names.empty() ? "" : " x ") + axes[a].name;
  for (const auto& e : jobs)
    if (!e.record) not_done.push_back(&e);
}

/// "job 7 (robot | 3 | triple): failed: ..." (Report::not_done).
std::string not_done_line(const JobEntry& e) {
  return "job " + std::to_string(e.job.index) + " (" + e.job.describe() +
         "): " + job_state_name(e.status.state) +
         (e.status.detail.empty() ? "" : ": " + e.status.detail);
}

/// The header of a markdown table: the condition columns (one "data" column if there is no
/// condition axis), then `columns`.
void table_header(std::ostream& os, const ReportContext& x,
                  const std::vector<std::string>& columns) {
  os << "|";
  if (x.cond_names.empty()) os << " data |";
  for (const auto& c : x.cond_names) os << " " << md_cell(c) << " |";
  for (const auto& c : columns) os << " " << md_cell(c) << " |";
  os << "\n|";
  for (std::size_t i = 0; i < std::max<std::size_t>(1, x.cond_names.size()) + columns.size(); ++i)
    os << "---|";
  os << "\n";
}

/// The start of condition `c`'s row in a markdown table: its labels (the study's name if
/// there is no condition axis).
void row_start(std::ostream& os, const ReportContext& x, std::size_t c) {
  os << "|";
  if (x.cond_names.empty()) os << " " << md_cell(x.s.name()) << " |";
  for (const auto& l : x.L.labels(c, x.L.cond, x.s)) os << " " << md_cell(l) << " |";
}

/// report.md's title and what the study and the cells of its tables are.
void markdown_intro(std::ostream& md, const ReportContext& x, std::size_t jobs, std::size_t done) {
  const Study& s = x.s;
  const IntervalOptions& io = x.io;
  md << "# Study: " << s.name() << "\n\n";
  if (!s.description().empty()) md << s.description() << "\n\n";
  md << "Study file `" << s.file().string() << "`: " << jobs << " jobs";
  {
    std::string dims;
    for (const auto& a : s.axes())
      dims += (dims.empty() ? "" : " x ") + std::to_string(a.values.size()) + " " + a.name;
    if (!dims.empty()) md << " (" << dims << ")";
  }
  md << "; " << done << " in this report";
  if (!x.not_done.empty()) md << ", **" << x.not_done.size() << " not done** (listed at the end)";
  md << ".\n\n";
  md << "Each cell: mean ± standard deviation ["
     << interval_description(io.method, io.confidence, io.resamples) << "] over the "
     << (x.rep_names.empty() ? "jobs" : x.rep_names + " replicates") << " (n = " << x.L.replicates
     << " per cell unless noted). Drift rate: paper Section VI-B (l = 100 m) in % of the distance; "
        "heading RMSE "
        "in degrees; every run evaluated against the truth as `wheelins evaluate` does.\n\n";
}

/// The drift rate and heading RMSE tables: per condition and configuration, the summary over
/// the replicates.
void markdown_metrics(std::ostream& md, const ReportContext& x) {
  const Layout& L = x.L;
  for (int metric : {kDrift, kHeading}) {
    const Metric& m = kMetrics[metric];
    md << "## " << m.title << " (" << m.unit << ")\n\n";
    table_header(md, x, L.config_labels);
    for (std::size_t c = 0; c < L.conditions; ++c) {
      row_start(md, x, c);
      for (std::size_t k = 0; k < L.configurations; ++k)
        md << " "
           << cell(summarize(values_of(x.g.records[c][k], metric), x.io), m.decimals, L.replicates)
           << " |";
      md << "\n";
    }
    md << "\n";
  }
}

/// The index of the configuration labelled `label`.
std::size_t config_index(const Layout& L, const std::string& label) {
  return static_cast<std::size_t>(std::find(L.config_labels.begin(), L.config_labels.end(), label) -
                                  L.config_labels.begin());
}

using Pairs = std::vector<std::pair<std::size_t, std::size_t>>;

struct Comparisons {
  Pairs pairs;                      ///< the study's `compare`: (A, B) configuration indices
  std::vector<std::string> titles;  ///< "B - A" per pair
  Pairs plot_pairs;                 ///< the pairs in the paired plot
};

// The pairs compared: the study's `compare`, else every configuration against the first.
Comparisons comparisons(const ReportContext& x) {
  Comparisons cmp;
  for (const auto& [a, b] : x.s.compare()) {
    cmp.pairs.emplace_back(config_index(x.L, a), config_index(x.L, b));
    cmp.titles.push_back(b + " - " + a);
  }
  cmp.plot_pairs = cmp.pairs;
  if (cmp.plot_pairs.empty())
    for (std::size_t k = 1; k < x.L.configurations; ++k) cmp.plot_pairs.emplace_back(0, k);
  return cmp;
}

/// The tables of the paired differences of the study's `compare` pairs.
void markdown_differences(std::ostream& md, const ReportContext& x, const Comparisons& cmp) {
  const IntervalOptions& io = x.io;
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
    table_header(md, x, cmp.titles);
    for (std::size_t c = 0; c < x.L.conditions; ++c) {
      row_start(md, x, c);
      for (const auto& [a, b] : cmp.pairs) {
        const Paired p = paired(x.g.records[c][a], x.g.records[c][b], metric, io);
        md << " " << cell(p.s, m.decimals, x.L.replicates);
        if (p.s.n > 0) md << "; lower in " << p.b_lower << "/" << p.s.n;
        md << " |";
      }
      md << "\n";
    }
    md << "\n";
  }
}

/// The consistency table: per condition and configuration, the means of the share of epochs
/// within 3 sigma and of the horizontal NEES.
void markdown_consistency(std::ostream& md, const ReportContext& x) {
  const Layout& L = x.L;
  md << "## Consistency (means over the replicates)\n\n"
     << "Share of epochs whose horizontal error is within 3 sigma of the filter's own north/east "
        "covariance "
        "(>= 89 % if the filter is consistent) / mean horizontal NEES (2 if consistent).\n\n";
  table_header(md, x, L.config_labels);
  for (std::size_t c = 0; c < L.conditions; ++c) {
    row_start(md, x, c);
    for (std::size_t k = 0; k < L.configurations; ++k) {
      const Summary a = summarize(values_of(x.g.records[c][k], k3Sigma), x.io);
      const Summary b = summarize(values_of(x.g.records[c][k], kNees), x.io);
      md << " " << (a.n ? fmt(a.mean, 1) + " % / " + fmt(b.mean, 2) : std::string("-")) << " |";
    }
    md << "\n";
  }
  md << "\n";
}

/// The plots' files, and their section of report.md.
PlotFiles plots_section(std::ostream& md, const ReportContext& x, const Pairs& plot_pairs) {
  const Study& s = x.s;
  const IntervalOptions& io = x.io;
  PlotFiles plots;
  add_metric_plot(plots, s, x.L, x.g, kDrift, "drift");
  add_metric_plot(plots, s, x.L, x.g, kHeading, "heading");
  md << "## Plots\n\n`plots/drift.png`, `plots/heading.png`: per condition (x axis) and "
        "configuration, the mean (square) and its "
     << interval_description(io.method, io.confidence, io.resamples)
     << " (error bars), with every job as a small point";
  if (!plot_pairs.empty()) {
    add_paired_plot(plots, s, x.L, x.g, kDrift, plot_pairs, "paired_drift");
    md << "; `plots/paired_drift.png`: the paired differences B - A of the drift rate, run by run "
          "on the "
          "same data ("
       << (s.compare().empty() ? "every configuration against the first"
                               : "the study's `compare` pairs")
       << "), each pair a small point, their mean and its interval; below the dashed zero line B "
          "is better";
  }
  md << " (data in `plots/data/`, gnuplot scripts `plots/*.gp`).\n\n";
  return plots;
}

/// The table of the jobs not in the report.
void markdown_not_done(std::ostream& md, const ReportContext& x) {
  const auto& axes = x.s.axes();
  md << "## Jobs not in this report\n\n| job | state | ";
  for (const auto& a : axes) md << md_cell(a.name) << " | ";
  md << "detail |\n|---|---|";
  for (std::size_t i = 0; i < axes.size(); ++i) md << "---|";
  md << "---|\n";
  for (const auto* e : x.not_done) {
    md << "| " << e->job.index << " | " << job_state_name(e->status.state) << " | ";
    for (const auto& l : e->job.labels) md << md_cell(l) << " | ";
    md << md_cell(e->status.detail) << " |\n";
  }
  md << "\n";
}

// summary.csv, differences.csv and report.json.
struct DataTables {
  std::string summary_csv, diff_csv;
  JsonWriter js;
};

/// Condition `c`'s CSV fields, each followed by a comma.
std::string cond_csv(const ReportContext& x, std::size_t c) {
  std::string t;
  for (const auto& l : x.L.labels(c, x.L.cond, x.s)) t += csv_field(l) + ",";
  return t;
}

/// Condition `c`'s labels as the JSON object "condition".
void cond_json(JsonWriter& js, const ReportContext& x, std::size_t c) {
  js.begin_object("condition");
  const auto labels = x.L.labels(c, x.L.cond, x.s);
  for (std::size_t i = 0; i < labels.size(); ++i) js.str(x.cond_names[i].c_str(), labels[i]);
  js.end_object();
}

/// `sm` as the JSON object `key`, left open.
void stat_json(JsonWriter& js, const char* key, const Summary& sm) {
  js.begin_object(key)
      .integer("n", static_cast<std::int64_t>(sm.n))
      .num("mean", sm.mean)
      .num("sd", sm.sd)
      .num("ci_lo", sm.lo)
      .num("ci_hi", sm.hi);
}

/// report.json's head: the study, the interval, the axes and the jobs (the object left open).
void json_head(JsonWriter& js, const ReportContext& x, std::size_t jobs, std::size_t done) {
  const Study& s = x.s;
  const IntervalOptions& io = x.io;
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
  for (const auto& a : s.axes()) {
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
      .integer("total", static_cast<std::int64_t>(jobs))
      .integer("done", static_cast<std::int64_t>(done));
  js.begin_array("not_done");
  for (const auto* e : x.not_done)
    js.begin_object()
        .integer("job", static_cast<std::int64_t>(e->job.index))
        .str("state", job_state_name(e->status.state))
        .strings("labels", e->job.labels)
        .str("detail", e->status.detail)
        .end_object();
  js.end_array().end_object();
}

/// Per condition and configuration, the summary of every metric: summary.csv's rows and
/// report.json's "summary".
void summary_rows(DataTables& t, const ReportContext& x) {
  const Layout& L = x.L;
  JsonWriter& js = t.js;
  js.begin_array("summary");
  for (std::size_t c = 0; c < L.conditions; ++c)
    for (std::size_t k = 0; k < L.configurations; ++k) {
      js.begin_object();
      cond_json(js, x, c);
      js.str("configuration", L.config_labels[k]);
      js.begin_object("metrics");
      for (int m = 0; m < kMetricCount; ++m) {
        const Summary sm = summarize(values_of(x.g.records[c][k], m), x.io);
        t.summary_csv += cond_csv(x, c) + csv_field(L.config_labels[k]) + "," + kMetrics[m].key +
                         "," + std::to_string(sm.n) + "," + exact(sm.mean) + "," + exact(sm.sd) +
                         "," + exact(sm.lo) + "," + exact(sm.hi) + "\n";
        stat_json(js, kMetrics[m].key, sm);
        js.end_object();
      }
      js.end_object().end_object();
    }
  js.end_array();
}

/// Per condition and `compare` pair, the paired differences of every metric:
/// differences.csv's rows and report.json's "differences".
void difference_rows(DataTables& t, const ReportContext& x) {
  JsonWriter& js = t.js;
  js.begin_array("differences");
  for (std::size_t c = 0; c < x.L.conditions; ++c)
    for (const auto& [a, b] : x.s.compare()) {
      const std::size_t ia = config_index(x.L, a);
      const std::size_t ib = config_index(x.L, b);
      js.begin_object();
      cond_json(js, x, c);
      js.str("a", a).str("b", b);
      js.begin_object("metrics");
      for (int m = 0; m < kMetricCount; ++m) {
        const Paired p = paired(x.g.records[c][ia], x.g.records[c][ib], m, x.io);
        t.diff_csv += cond_csv(x, c) + csv_field(a) + "," + csv_field(b) + "," + kMetrics[m].key +
                      "," + std::to_string(p.s.n) + "," + exact(p.s.mean) + "," + exact(p.s.sd) +
                      "," + exact(p.s.lo) + "," + exact(p.s.hi) + "," + std::to_string(p.b_lower) +
                      "\n";
        stat_json(js, kMetrics[m].key, p.s);
        js.integer("b_lower", static_cast<std::int64_t>(p.b_lower));
        js.end_object();
      }
      js.end_object().end_object();
    }
  js.end_array();
}

DataTables data_tables(const ReportContext& x, std::size_t jobs, std::size_t done) {
  std::string header_csv;
  for (const auto& c : x.cond_names) header_csv += csv_field(c) + ",";
  DataTables t;
  t.summary_csv = header_csv + "configuration,metric,n,mean,sd,ci_lo,ci_hi\n";
  t.diff_csv = header_csv + "a,b,metric,n,mean_b_minus_a,sd,ci_lo,ci_hi,b_lower\n";
  json_head(t.js, x, jobs, done);
  summary_rows(t, x);
  difference_rows(t, x);
  t.js.end_object();
  return t;
}

// jobs.csv and timing.csv
struct JobTables {
  std::string jobs_csv, timing_csv;
};

/// Job `e`'s row of jobs.csv.
std::string jobs_row(const JobEntry& e) {
  std::string row = std::to_string(e.job.index) + ",";
  for (const auto& l : e.job.labels) row += csv_field(l) + ",";
  row += std::string(job_state_name(e.status.state)) + ",";
  std::string mods;
  if (e.record) {
    for (const auto& m : kMetrics) row += exact(m.get(*e.record)) + ",";
    row += exact(e.record->eval.distance) + "," + std::to_string(e.record->stats.epochs) + "," +
           std::to_string(e.record->fault_events) + ",";
    for (const auto& m : e.record->modules) mods += (mods.empty() ? "" : "+") + m;
  } else {
    for (int m = 0; m < kMetricCount; ++m) row += ",";
    row += ",,,";
  }
  return row + csv_field(mods) + "," + csv_field(e.job.dataset.describe()) + "," +
         csv_field(e.status.detail) + "\n";
}

/// Done job `e`'s row of timing.csv.
std::string timing_row(const JobEntry& e) {
  const JobTiming& t = e.record->timing;
  return std::to_string(e.job.index) + ",done," + csv_field(t.host) + "," +
         (t.generated ? "1" : "0") + "," + exact(t.dataset) + "," + exact(t.setup) + "," +
         exact(t.navigate) + "," + exact(t.finish) + "," + exact(t.filter) + "," +
         exact(t.started) + "," + exact(t.finished) + "\n";
}

/// jobs.csv and timing.csv; the done jobs' time and their span into `rep`.
JobTables job_tables(const Study& s, const std::vector<JobEntry>& jobs, Report& rep) {
  JobTables t;
  t.jobs_csv = "job,";
  for (const auto& a : s.axes()) t.jobs_csv += csv_field(a.name) + ",";
  t.jobs_csv += "state,";
  for (const auto& m : kMetrics) t.jobs_csv += std::string(m.key) + ",";
  t.jobs_csv += "distance_m,epochs,fault_events,modules,data,detail\n";
  t.timing_csv =
      "job,state,host,dataset_generated,dataset_s,setup_s,navigate_s,finish_s,filter_s,started_"
      "unix,finished_unix\n";
  double first = INFINITY, last = -INFINITY;
  for (const auto& e : jobs) {
    t.jobs_csv += jobs_row(e);
    if (!e.record) continue;
    const JobTiming& tm = e.record->timing;
    t.timing_csv += timing_row(e);
    rep.job_seconds += tm.finished - tm.started;
    first = std::min(first, tm.started);
    last = std::max(last, tm.finished);
  }
  rep.span_seconds = rep.done ? last - first : 0.0;
  return t;
}

using TextFiles = std::vector<std::pair<std::string, std::string>>;

std::string first_line(const std::string& t) { return t.substr(0, t.find('\n')); }

// The report replaces only what a report wrote here (files.hpp): every file is checked
// before the first is written.
void write_report_files(Report& rep, const fs::path& dir, const TextFiles& files,
                        const PlotFiles& plots, const ReportOptions& o) {
  ReportFiles ours(dir);
  for (const auto& [name, text] : files) ours.check(name, first_line(text));
  std::vector<fs::path> written;
  if (!plots.names.empty()) {
    for (const auto& [rel, text] : plots.files)
      ours.check(fs::path("plots") / rel, first_line(text));
    if (o.plot.render)
      for (const auto& n : plots.names) ours.check(fs::path("plots") / (n + ".png"), "\x89PNG\r");
  }
  for (const auto& [name, text] : files) {
    write_file_atomic(dir / name, text, shared_file(dir / name));
    rep.files.push_back(dir / name);
    written.push_back(name);
  }
  if (!plots.names.empty()) {
    const fs::path pdir = dir / "plots";
    std::error_code ec;
    fs::create_directories(pdir / "data", ec);
    for (const auto& [rel, text] : plots.files) {
      write_file_atomic(pdir / rel, text, shared_file(pdir / rel));
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
}

Report generic_report(const Study& s, std::vector<JobEntry> jobs, const ReportOptions& o) {
  Report rep;
  const ReportContext x(s, jobs);
  const fs::path dir = s.results_dir();
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw InputError("'" + dir.string() + "': cannot create: " + ec.message());
  for (const auto& e : jobs)
    if (e.record) ++rep.done;

  // report.md
  std::ostringstream md;
  markdown_intro(md, x, jobs.size(), rep.done);
  markdown_metrics(md, x);
  const Comparisons cmp = comparisons(x);
  if (!s.compare().empty()) markdown_differences(md, x, cmp);
  markdown_consistency(md, x);
  // Plots.
  PlotFiles plots;
  if (o.plots && rep.done > 0) plots = plots_section(md, x, cmp.plot_pairs);
  if (!x.not_done.empty()) markdown_not_done(md, x);
  for (const auto* e : x.not_done) rep.not_done.push_back(not_done_line(*e));
  rep.markdown = md.str();

  const DataTables data = data_tables(x, jobs.size(), rep.done);
  const JobTables job = job_tables(s, jobs, rep);
  const TextFiles files = {{"report.md", rep.markdown},        {"summary.csv", data.summary_csv},
                           {"differences.csv", data.diff_csv}, {"jobs.csv", job.jobs_csv},
                           {"report.json", data.js.text()},    {"timing.csv", job.timing_csv}};
  write_report_files(rep, dir, files, plots, o);
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
      rep.not_done.push_back(not_done_line(e));
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
