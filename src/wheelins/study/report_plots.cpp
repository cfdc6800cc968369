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

void add_metric_plot(PlotFiles& out, const Study& s, const Layout& L, const Grid& g, int metric,
                     const std::string& name) {
  const Metric& m = kMetrics[metric];
  const IntervalOptions& io = s.interval();
  std::string summary = "condition,label";
  std::string jobs = "condition";
  for (const auto& c : L.config_labels) {
    summary += "," + c + "_mean," + c + "_lo," + c + "_hi";
    jobs += "," + c;
  }
  summary += "\n";
  jobs += "\n";
  double ymax = 0.0;
  auto condition_label = [&](std::size_t c) {
    std::string label;
    for (const auto& l : L.labels(c, L.cond, s)) label += (label.empty() ? "" : " / ") + l;
    return label.empty() ? s.name() : label;
  };
  for (std::size_t c = 0; c < L.conditions; ++c) {
    std::string label = condition_label(c);
    for (char& ch : label)
      if (ch == ',') ch = ';';
    summary += std::to_string(c) + "," + label;
    for (std::size_t k = 0; k < L.configurations; ++k) {
      const Summary sm = summarize(values_of(g.records[c][k], metric), io);
      summary += "," + exact(sm.mean) + "," + exact(sm.n >= 2 ? sm.lo : sm.mean) + "," +
                 exact(sm.n >= 2 ? sm.hi : sm.mean);
      if (sm.n >= 2 && std::isfinite(sm.hi)) ymax = std::max(ymax, sm.hi);
    }
    summary += "\n";
    for (std::size_t r = 0; r < L.replicates; ++r) {
      std::string row = std::to_string(c);
      bool any = false;
      for (std::size_t k = 0; k < L.configurations; ++k) {
        const JobRecord* rec = g.records[c][k][r];
        const double v = rec ? m.get(*rec) : std::nan("");
        if (std::isfinite(v)) any = true, ymax = std::max(ymax, v);
        row += "," + exact(v);
      }
      if (any) jobs += row + "\n";
    }
  }
  out.files.emplace_back(fs::path("data") / (name + "_summary.csv"), summary);
  out.files.emplace_back(fs::path("data") / (name + "_jobs.csv"), jobs);

  const std::size_t K = L.configurations;
  const double width = 0.7 / static_cast<double>(K);
  const int px = static_cast<int>(
      std::clamp<double>(200.0 + 70.0 * static_cast<double>(L.conditions * K), 1200.0, 4000.0));
  const std::string unit = m.unit[0] ? std::string(" [") + m.unit + "]" : "";
  std::string xtics;
  std::size_t longest = 0;
  for (std::size_t c = 0; c < L.conditions; ++c) {
    const std::string label = condition_label(c);
    longest = std::max(longest, label.size());
    xtics += (c ? ", " : "") + gq(label) + " " + std::to_string(c);
  }
  char top[32];
  std::snprintf(top, sizeof top, "%.4g", ymax > 0 ? 1.1 * ymax : 1.0);
  const int bmargin = static_cast<int>(std::clamp<std::size_t>(3 + longest / 2, 4, 16));
  std::string gp =
      "# " + std::string(m.title) + " by condition: mean and " +
      interval_description(io.method, io.confidence, io.resamples) +
      " per configuration; small points: the single jobs.\n"
      "# Written by `wheelins study report`; edit and re-run in this directory: gnuplot " +
      name +
      ".gp\n"
      "if (!exists(\"outfile\")) outfile = " +
      gq(name + ".png") +
      "\n"
      "set terminal pngcairo size " +
      std::to_string(px) +
      ",800 noenhanced font \"Sans,13\" linewidth 1.3\n"
      "set output outfile\nset datafile separator \",\"\nset grid ytics lc rgb \"#d0d0d0\"\n"
      "set title " +
      gq(std::string(m.title) + " by condition - " + s.name()) +
      " font \",15\"\n"
      "set ylabel " +
      gq(std::string(m.title) + unit) +
      "\n"
      "set xrange [-0.5:" +
      std::to_string(L.conditions) + "-0.5]\nset yrange [0:" + exact(ymax > 0 ? 1.1 * ymax : 1.0) +
      "]\n"
      "set xtics (" +
      xtics + ") rotate by -25 left nomirror\nset bmargin " + std::to_string(bmargin) +
      "\n"
      "set key outside top center horizontal samplen 2\nplot \\\n";
  std::vector<std::string> parts;
  for (std::size_t k = 0; k < K; ++k) {
    const double off = (static_cast<double>(k) - 0.5 * static_cast<double>(K - 1)) * width;
    char o[32], oj[32];
    std::snprintf(o, sizeof o, "%+.4f", off);
    std::snprintf(oj, sizeof oj, "%+.4f", off + 0.3 * width);
    const std::string color = gq(kColors[k % 10]);
    parts.push_back("  \"data/" + name + "_jobs.csv\" skip 1 using ($1" + oj +
                    "):" + std::to_string(k + 2) + " with points pt 7 ps 0.5 lc rgb " + color +
                    " notitle");
    parts.push_back("  \"data/" + name + "_summary.csv\" skip 1 using ($1" + o +
                    "):" + std::to_string(3 + 3 * k) + ":" + std::to_string(4 + 3 * k) + ":" +
                    std::to_string(5 + 3 * k) + " with yerrorbars pt 5 ps 1.1 lw 2 lc rgb " +
                    color + " title " + gq(L.config_labels[k]));
  }
  for (std::size_t i = 0; i < parts.size(); ++i)
    gp += parts[i] + (i + 1 < parts.size() ? ", \\\n" : "\n");
  out.files.emplace_back(name + ".gp", gp);
  out.names.push_back(name);
}

}  // namespace wheelins::study::report_detail
