// The plots of a study's report (report_data.hpp): per metric, the mean and its interval per
// condition and configuration with every job as a small point, as CSV data and a gnuplot
// script (rendered by run/plots' render_gnuplot).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "wheelins/study/report_data.hpp"
#include "wheelins/study/stats.hpp"

namespace wheelins::study::report_detail {
namespace fs = std::filesystem;

namespace {

const char* const kColors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                               "#8c564b", "#e377c2", "#17becf", "#7f7f7f", "#bcbd22"};

/// A gnuplot double-quoted string.
std::string gq(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

}  // namespace

namespace {

// One plot of groups: per condition (x) and series (offset within the condition), the mean and
// its interval (error bars) over the replicates, and every replicate's value as a small point.
struct GroupPlot {
  std::string name, title, ylabel, what;  // `what`: the small points, for the key
  std::vector<std::string> series;        // the key's titles
  // values[condition][series][replicate] (NaN: none)
  std::vector<std::vector<std::vector<double>>> values;
  bool zero_line = false;
};

/// Condition `c`'s label: its labels joined by " / " (the study's name if there is no
/// condition axis).
std::string condition_label(const Study& s, const Layout& L, std::size_t c) {
  std::string label;
  for (const auto& l : L.labels(c, L.cond, s)) label += (label.empty() ? "" : " / ") + l;
  return label.empty() ? s.name() : label;
}

/// The range of the values drawn (0 always in it).
struct YRange {
  double ymax = 0.0, ymin = 0.0;
  void grow(double v) {
    if (std::isfinite(v)) ymax = std::max(ymax, v), ymin = std::min(ymin, v);
  }
};

/// Condition `c`'s fields of the summary CSV: per series the mean and its interval (the mean
/// alone below two values).
std::string summary_fields(const GroupPlot& p, std::size_t c, const IntervalOptions& io, YRange& y) {
  std::string fields;
  for (std::size_t k = 0; k < p.series.size(); ++k) {
    std::vector<double> v;
    for (double x : p.values[c][k])
      if (std::isfinite(x)) v.push_back(x);
    const Summary sm = summarize(v, io);
    fields += "," + exact(sm.mean) + "," + exact(sm.n >= 2 ? sm.lo : sm.mean) + "," +
              exact(sm.n >= 2 ? sm.hi : sm.mean);
    if (sm.n >= 2) y.grow(sm.hi), y.grow(sm.lo);
  }
  return fields;
}

/// Condition `c`'s rows of the jobs CSV: one per replicate with a value, per series.
std::string job_rows(const GroupPlot& p, std::size_t c, YRange& y) {
  const std::size_t K = p.series.size();
  std::size_t reps = 0;
  for (std::size_t k = 0; k < K; ++k) reps = std::max(reps, p.values[c][k].size());
  std::string rows;
  for (std::size_t r = 0; r < reps; ++r) {
    std::string row = std::to_string(c);
    bool any = false;
    for (std::size_t k = 0; k < K; ++k) {
      const double v = r < p.values[c][k].size() ? p.values[c][k][r] : std::nan("");
      if (std::isfinite(v)) any = true, y.grow(v);
      row += "," + exact(v);
    }
    if (any) rows += row + "\n";
  }
  return rows;
}

/// The plot's data files: data/`name`_summary.csv (per condition, each series' mean and
/// interval) and data/`name`_jobs.csv (every replicate's values). Returns the range drawn.
YRange write_group_data(PlotFiles& out, const Study& s, const Layout& L, const GroupPlot& p) {
  std::string summary = "condition,label";
  std::string jobs = "condition";
  for (const auto& c : p.series) {
    summary += "," + c + "_mean," + c + "_lo," + c + "_hi";
    jobs += "," + c;
  }
  summary += "\n";
  jobs += "\n";
  YRange y;
  for (std::size_t c = 0; c < L.conditions; ++c) {
    std::string label = condition_label(s, L, c);
    for (char& ch : label)
      if (ch == ',') ch = ';';
    summary += std::to_string(c) + "," + label + summary_fields(p, c, s.interval(), y) + "\n";
    jobs += job_rows(p, c, y);
  }
  out.files.emplace_back(fs::path("data") / (p.name + "_summary.csv"), summary);
  out.files.emplace_back(fs::path("data") / (p.name + "_jobs.csv"), jobs);
  return y;
}

/// The gnuplot script up to its plot command: the terminal, the titles, the axes and the key.
/// `bars`: what the error bars are.
std::string script_settings(const Study& s, const Layout& L, const GroupPlot& p, const YRange& y,
                            const std::string& bars) {
  const std::size_t K = p.series.size();
  const int px = static_cast<int>(
      std::clamp<double>(200.0 + 70.0 * static_cast<double>(L.conditions * K), 1200.0, 4000.0));
  std::string xtics, xlabel;
  std::size_t longest = 0;
  for (std::size_t c = 0; c < L.conditions; ++c) {
    const std::string label = condition_label(s, L, c);
    longest = std::max(longest, label.size());
    xtics += (c ? ", " : "") + gq(label) + " " + std::to_string(c);
  }
  for (std::size_t a : L.cond) xlabel += (xlabel.empty() ? "" : " / ") + s.axes()[a].name;
  xlabel = xlabel.empty() ? "the study (one condition)" : "condition: " + xlabel;
  const double ymin = y.ymin, ymax = y.ymax;
  const double lo = ymin < 0.0 ? 1.1 * ymin : 0.0, hi = ymax > 0.0 ? 1.1 * ymax : (ymin < 0.0 ? 0.0 : 1.0);
  const int bmargin = static_cast<int>(std::clamp<std::size_t>(5 + longest / 2, 6, 18));
  return "# " + p.title + ": mean and " + bars + " per series; small points: " + p.what +
         ".\n"
         "# Written by `wheelins study report`; edit and re-run in this directory: gnuplot " +
         p.name + ".gp\n" + "if (!exists(\"outfile\")) outfile = " + gq(p.name + ".png") +
         "\nset terminal pngcairo size " + std::to_string(px) +
         ",800 noenhanced font \"Sans,13\" linewidth 1.3\n"
         "set output outfile\nset datafile separator \",\"\nset grid ytics lc rgb \"#d0d0d0\"\n"
         "set title " + gq(p.title + " - " + s.name()) + " font \",15\"\n" +
         "set ylabel " + gq(p.ylabel) + "\nset xlabel " + gq(xlabel) + "\n" +
         "set xrange [-0.5:" + std::to_string(L.conditions) + "-0.5]\nset yrange [" + exact(lo) + ":" +
         exact(hi) + "]\n" + "set xtics (" + xtics + ") rotate by -25 left nomirror\nset bmargin " +
         std::to_string(bmargin) + "\n" + "set key outside top center horizontal samplen 2\n" +
         (p.zero_line ? "set arrow from graph 0, first 0 to graph 1, first 0 nohead lc rgb \"#404040\" dt 2\n"
                      : "");
}

/// The gnuplot script's plot command: per series the jobs' points and the means with their
/// error bars, then what the marks are. `bars`: what the error bars are.
std::string plot_command(const GroupPlot& p, const std::string& bars) {
  const std::size_t K = p.series.size();
  const double width = 0.7 / static_cast<double>(K);
  std::vector<std::string> parts;
  for (std::size_t k = 0; k < K; ++k) {
    const double off = (static_cast<double>(k) - 0.5 * static_cast<double>(K - 1)) * width;
    char o[32], oj[32];
    std::snprintf(o, sizeof o, "%+.4f", off);
    std::snprintf(oj, sizeof oj, "%+.4f", off + 0.3 * width);
    const std::string color = gq(kColors[k % 10]);
    parts.push_back("  \"data/" + p.name + "_jobs.csv\" skip 1 using ($1" + oj + "):" + std::to_string(k + 2) +
                    " with points pt 7 ps 0.5 lc rgb " + color + " notitle");
    parts.push_back("  \"data/" + p.name + "_summary.csv\" skip 1 using ($1" + o + "):" + std::to_string(3 + 3 * k) +
                    ":" + std::to_string(4 + 3 * k) + ":" + std::to_string(5 + 3 * k) +
                    " with yerrorbars pt 5 ps 1.1 lw 2 lc rgb " + color + " title " + gq(p.series[k]));
  }
  // What the marks are, in the key itself.
  parts.push_back("  NaN with yerrorbars pt 5 ps 1.1 lw 2 lc rgb \"#000000\" title " +
                  gq("square and bars: mean and its " + bars));
  parts.push_back("  NaN with points pt 7 ps 0.5 lc rgb \"#000000\" title " + gq("small points: " + p.what));
  std::string gp = "plot \\\n";
  for (std::size_t i = 0; i < parts.size(); ++i) gp += parts[i] + (i + 1 < parts.size() ? ", \\\n" : "\n");
  return gp;
}

void write_group_plot(PlotFiles& out, const Study& s, const Layout& L, const GroupPlot& p) {
  const YRange y = write_group_data(out, s, L, p);
  const IntervalOptions& io = s.interval();
  const std::string bars = interval_description(io.method, io.confidence, io.resamples);
  out.files.emplace_back(p.name + ".gp", script_settings(s, L, p, y, bars) + plot_command(p, bars));
  out.names.push_back(p.name);
}

}  // namespace

void add_metric_plot(PlotFiles& out, const Study& s, const Layout& L, const Grid& g, int metric,
                     const std::string& name) {
  const Metric& m = kMetrics[metric];
  GroupPlot p;
  p.name = name;
  p.title = std::string(m.title) + " by condition";
  p.ylabel = std::string(m.title) + (m.unit[0] ? std::string(" [") + m.unit + "]" : "");
  p.what = "one run each";
  p.series = L.config_labels;
  p.values.assign(L.conditions, std::vector<std::vector<double>>(L.configurations));
  for (std::size_t c = 0; c < L.conditions; ++c)
    for (std::size_t k = 0; k < L.configurations; ++k)
      for (const JobRecord* rec : g.records[c][k]) p.values[c][k].push_back(rec ? m.get(*rec) : std::nan(""));
  write_group_plot(out, s, L, p);
}

void add_paired_plot(PlotFiles& out, const Study& s, const Layout& L, const Grid& g, int metric,
                     const std::vector<std::pair<std::size_t, std::size_t>>& pairs, const std::string& name) {
  const Metric& m = kMetrics[metric];
  GroupPlot p;
  p.name = name;
  p.title = std::string(m.title) + ": paired differences B - A on the same runs";
  p.ylabel = "B - A, " + std::string(m.title) + (m.unit[0] ? std::string(" [") + m.unit + "]" : "") +
             " (below 0: B better)";
  p.what = "one pair of runs on the same data each";
  p.zero_line = true;
  p.values.assign(L.conditions, std::vector<std::vector<double>>(pairs.size()));
  for (const auto& [a, b] : pairs) p.series.push_back(L.config_labels[b] + " - " + L.config_labels[a]);
  for (std::size_t c = 0; c < L.conditions; ++c)
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const auto& A = g.records[c][pairs[k].first];
      const auto& B = g.records[c][pairs[k].second];
      for (std::size_t r = 0; r < A.size(); ++r)
        p.values[c][k].push_back(A[r] && B[r] ? m.get(*B[r]) - m.get(*A[r]) : std::nan(""));
    }
  write_group_plot(out, s, L, p);
}

}  // namespace wheelins::study::report_detail
