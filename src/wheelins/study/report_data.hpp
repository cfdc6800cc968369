// The jobs' results laid out for a study's report (report.cpp and report_plots.cpp): the
// metrics a report gives, the study's axes as conditions x configurations x replicates, the
// results in that grid, and the plots' files.
#pragma once

#include <cmath>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "wheelins/io/atomic_file.hpp"
#include "wheelins/nav/types.hpp"
#include "wheelins/study/job.hpp"
#include "wheelins/study/report.hpp"
#include "wheelins/study/spec.hpp"

namespace wheelins::study::report_detail {

struct Metric {
  const char* key;
  const char* title;
  const char* unit;
  int decimals;
  double (*get)(const JobRecord&);
};

inline const Metric kMetrics[] = {
    {"drift_rate_pct", "Drift rate", "%", 3,
     [](const JobRecord& r) { return 100.0 * r.eval.drift_rate; }},
    {"heading_rmse_deg", "Heading RMSE", "deg", 2,
     [](const JobRecord& r) { return r.eval.heading_rmse / kDeg; }},
    {"max_error_m", "Max horizontal error", "m", 2,
     [](const JobRecord& r) { return r.eval.max_error; }},
    {"final_error_m", "Final horizontal error", "m", 2,
     [](const JobRecord& r) { return r.eval.final_error; }},
    {"rms_error_m", "RMS horizontal error", "m", 2,
     [](const JobRecord& r) { return r.eval.rms_error; }},
    {"within_3sigma_pct", "Within 3 sigma", "%", 1,
     [](const JobRecord& r) { return 100.0 * r.eval.within_3sigma; }},
    {"mean_nees_h", "Mean horizontal NEES", "", 2,
     [](const JobRecord& r) { return r.eval.mean_nees; }},
};
constexpr int kDrift = 0, kHeading = 1, k3Sigma = 5, kNees = 6;
constexpr int kMetricCount = static_cast<int>(sizeof kMetrics / sizeof kMetrics[0]);

inline std::string exact(double v) {
  std::string s;
  if (std::isfinite(v)) append_double(s, v);
  return s;
}

/// The study's layout: which axes are conditions, replicates, the configuration.
struct Layout {
  std::vector<std::size_t> cond, rep;
  int cfg = -1;
  std::size_t conditions = 1, replicates = 1, configurations = 1;
  std::vector<std::string> config_labels;

  explicit Layout(const Study& s) {
    const auto& axes = s.axes();
    for (std::size_t i = 0; i < axes.size(); ++i) {
      if (axes[i].role == AxisRole::kCondition)
        cond.push_back(i), conditions *= axes[i].values.size();
      else if (axes[i].role == AxisRole::kReplicate)
        rep.push_back(i), replicates *= axes[i].values.size();
      else
        cfg = static_cast<int>(i);
    }
    if (cfg >= 0) {
      configurations = axes[static_cast<std::size_t>(cfg)].values.size();
      for (const auto& v : axes[static_cast<std::size_t>(cfg)].values)
        config_labels.push_back(v.label);
    } else {
      config_labels.push_back("result");
    }
  }
  std::size_t index(const Job& j, const std::vector<std::size_t>& which, const Study& s) const {
    std::size_t id = 0;
    for (std::size_t a : which) id = id * s.axes()[a].values.size() + j.choice[a];
    return id;
  }
  /// The labels of condition `c` (one per condition axis).
  std::vector<std::string> labels(std::size_t c, const std::vector<std::size_t>& which,
                                  const Study& s) const {
    std::vector<std::string> out(which.size());
    for (std::size_t i = which.size(); i-- > 0;) {
      const auto& ax = s.axes()[which[i]];
      out[i] = ax.values[c % ax.values.size()].label;
      c /= ax.values.size();
    }
    return out;
  }
};

struct Grid {
  // records[condition][configuration][replicate]
  std::vector<std::vector<std::vector<const JobRecord*>>> records;
};

inline Grid grid_of(const Study& s, const Layout& L, const std::vector<JobEntry>& jobs) {
  Grid g;
  g.records.assign(L.conditions,
                   std::vector<std::vector<const JobRecord*>>(
                       L.configurations, std::vector<const JobRecord*>(L.replicates, nullptr)));
  for (const auto& e : jobs) {
    if (!e.record) continue;
    const std::size_t c = L.index(e.job, L.cond, s), r = L.index(e.job, L.rep, s);
    const std::size_t k = L.cfg >= 0 ? e.job.choice[static_cast<std::size_t>(L.cfg)] : 0;
    g.records[c][k][r] = &*e.record;
  }
  return g;
}

inline std::vector<double> values_of(const std::vector<const JobRecord*>& recs, int metric) {
  std::vector<double> v;
  for (const auto* r : recs)
    if (r) v.push_back(kMetrics[metric].get(*r));
  return v;
}

struct PlotFiles {
  std::vector<std::pair<std::filesystem::path, std::string>> files;  ///< relative to plots/
  std::vector<std::string> names;
};

/// Adds one plot per metric (`name`.gp and its data files): the mean and its interval per
/// condition and configuration, over the single jobs' values (small points).
void add_metric_plot(PlotFiles& out, const Study& s, const Layout& L, const Grid& g, int metric,
                     const std::string& name);
/// Adds a plot of the paired differences B - A of `metric` (`pairs`: (A, B) configuration
/// indices) per condition: every replicate's difference and their mean with its interval.
void add_paired_plot(PlotFiles& out, const Study& s, const Layout& L, const Grid& g, int metric,
                     const std::vector<std::pair<std::size_t, std::size_t>>& pairs, const std::string& name);

}  // namespace wheelins::study::report_detail
