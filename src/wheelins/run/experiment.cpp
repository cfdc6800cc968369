// The paper's experiment (experiment.hpp): its run plan, and Tables 4-8 as Markdown, CSV
// and JSON from the runs' results (the study engine runs them).
#include "wheelins/run/experiment.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace wheelins::eval {
namespace fs = std::filesystem;

namespace {

struct Slots {
  std::vector<const ModuleSpec*> left, right, body;
};

Slots slots_of(const Manifest& m) {
  Slots s;
  for (const auto& mod : m.modules) {
    if (mod.kind == ModuleKind::kBody) s.body.push_back(&mod);
    else if (mod.p_inV.y() < 0.0) s.left.push_back(&mod);
    else s.right.push_back(&mod);
  }
  return s;
}

std::string chip_digit(const ModuleSpec& m) {
  const std::string& c = m.chip.empty() ? m.name : m.chip;
  return c.size() >= 1 && std::isdigit(static_cast<unsigned char>(c.back())) ? std::string(1, c.back()) : c;
}

bool wanted(const ExperimentOptions& o, const std::string& name) {
  return o.only.empty() || std::find(o.only.begin(), o.only.end(), name) != o.only.end();
}

double mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return v.empty() ? NAN : s / static_cast<double>(v.size());
}
double stddev(const std::vector<double>& v) {
  if (v.size() < 2) return NAN;
  const double m = mean(v);
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

std::string fmt(double v, int decimals) {
  if (!std::isfinite(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

}  // namespace

std::vector<ExperimentRun> experiment_plan(const Manifest& m, const ExperimentOptions& o) {
  const Slots s = slots_of(m);
  std::vector<ExperimentRun> plan;
  auto add = [&](const std::string& config, bool centralized,
                 const std::vector<const ModuleSpec*>& mods, const std::string& side) {
    ExperimentRun r;
    r.configuration = config;
    r.centralized = centralized;
    r.side = side;
    for (const auto* md : mods) {
      r.modules.push_back(md->name);
      r.label += chip_digit(*md);
    }
    plan.push_back(std::move(r));
  };
  if (wanted(o, "single")) {
    for (const auto* l : s.left) add("single", false, {l}, "left");
    for (const auto* rr : s.right) add("single", false, {rr}, "right");
  }
  if (wanted(o, "dual-wheel"))
    for (const auto* l : s.left)
      for (const auto* rr : s.right) add("dual-wheel", false, {l, rr}, "");
  if (wanted(o, "body-wheel"))
    for (const auto* l : s.left)
      for (const auto* b : s.body) add("body-wheel", false, {l, b}, "");
  std::vector<std::vector<const ModuleSpec*>> triples;
  if (!s.body.empty())
    for (std::size_t i = 0; i < s.left.size(); ++i)
      for (std::size_t j = 0; j < s.right.size(); ++j)
        // Body chip C(((i + j) mod n) + 1) with 1-based i, j: left C1 + right C2 -> body C4.
        triples.push_back({s.left[i], s.right[j], s.body[(i + j + 2) % s.body.size()]});
  if (wanted(o, "triple"))
    for (const auto& t : triples) add("triple", false, t, "");
  if (wanted(o, "centralized"))
    for (std::size_t k = 0; k < std::min<std::size_t>(8, triples.size()); ++k) add("triple", true, triples[k], "");

  // The paper's figure runs (Section VI-B-1): DW C1/C4, BW C2/C2, TW C1/C2/C4, and
  // every single Wheel-INS. Without the paper's combination in the plan (fewer chips,
  // or another body chip) the run whose chips agree with it on the most leading
  // slots is used (the first such run on a tie): e.g. TW "123" for "124".
  for (auto& r : plan) r.figure = !r.centralized && r.configuration == "single";
  const std::pair<std::string, std::string> paper[] = {
      {"dual-wheel", "14"}, {"body-wheel", "22"}, {"triple", "124"}};
  for (const auto& [config, label] : paper) {
    ExperimentRun* pick = nullptr;
    std::size_t best = 0;
    for (auto& r : plan) {
      if (r.centralized || r.configuration != config) continue;
      std::size_t n = 0;
      while (n < r.label.size() && n < label.size() && r.label[n] == label[n]) ++n;
      if (!pick || n > best) {
        pick = &r;
        best = n;
      }
    }
    if (pick) pick->figure = true;
  }
  return plan;
}

namespace {

using Runs = std::vector<const ExperimentRun*>;

Runs runs_of(const ExperimentResult& r, const std::string& config, bool centralized) {
  Runs v;
  for (const auto& run : r.runs)
    if (run.configuration == config && run.centralized == centralized) v.push_back(&run);
  return v;
}

double pct(const ExperimentRun* x) { return 100.0 * x->eval.drift_rate; }
double deg(const ExperimentRun* x) { return x->eval.heading_rmse / kDeg; }

/// The runs of each table's configurations, in the plan's order.
struct ConfigRuns {
  Runs singles, dw, bw, tw, cent;
};

void markdown_header(std::ostream& o, const ExperimentResult& r) {
  o << "# Experiment: " << (r.dataset_name.empty() ? r.manifest.string() : r.dataset_name) << "\n\n"
    << "Dataset `" << r.manifest.string() << "`; " << r.runs.size() << " runs in "
    << fmt(r.wall_seconds, 1) << " s. Each run navigates "
    << (r.duration > 0.0 ? fmt(r.duration, 1) + " s after the static period (--duration)"
                         : std::string("all the data (no --duration)"))
    << ". Drift rate: paper Section VI-B (l = 100 m), in % of distance; heading RMSE in degrees.\n\n";
}

// Table 4
void table4(std::ostream& o, const Runs& singles) {
  if (singles.empty()) return;
  o << "## Table 4: single Wheel-INS\n\n| Test |";
  for (const auto* s : singles) o << " " << (s->side == "left" ? "L" : "R") << " C" << s->label << " |";
  o << "\n|---|";
  for (std::size_t k = 0; k < singles.size(); ++k) o << "---|";
  o << "\n| Drift rate (%) |";
  for (const auto* s : singles) o << " " << fmt(pct(s), 2) << " |";
  o << "\n| Heading RMSE (deg) |";
  for (const auto* s : singles) o << " " << fmt(deg(s), 2) << " |";
  o << "\n\n";
}

/// One metric's cells of a Table 5 row, the best in bold; "-" for a missing run.
void table5_cells(std::ostream& o, const ExperimentRun* const (&row)[3],
                  double (*metric)(const ExperimentRun*)) {
  double best = INFINITY;
  for (const auto* x : row)
    if (x) best = std::min(best, metric(x));
  for (const auto* x : row) {
    if (!x) {
      o << " - |";
      continue;
    }
    const double v = metric(x);
    const std::string t = fmt(v, 2);
    o << " " << (v == best ? "**" + t + "**" : t) << " |";
  }
}

// Table 5
void table5(std::ostream& o, const ConfigRuns& c) {
  const std::size_t n5 = std::max({c.dw.size(), c.bw.size(), c.tw.size()});
  if (n5 == 0) return;
  o << "## Table 5: Dual Wheel-INS (DW), Body/Wheel-INS (BW), Triple INS (TW)\n\n"
    << "Chips: DW left/right, BW left/body, TW left/right/body. Best of a row in bold.\n\n"
    << "| Test | DW chips | BW chips | TW chips | DW drift (%) | BW drift (%) | TW drift (%) | "
       "DW heading (deg) | BW heading (deg) | TW heading (deg) |\n"
    << "|---|---|---|---|---|---|---|---|---|---|\n";
  auto at = [](const Runs& v, std::size_t i) { return i < v.size() ? v[i] : nullptr; };
  for (std::size_t i = 0; i < n5; ++i) {
    const ExperimentRun* const row[3] = {at(c.dw, i), at(c.bw, i), at(c.tw, i)};
    o << "| " << i + 1 << " |";
    for (const auto* x : row) o << " " << (x ? x->label : "-") << " |";
    table5_cells(o, row, pct);
    table5_cells(o, row, deg);
    o << "\n";
  }
  o << "\n";
}

// Table 6
void table6(std::ostream& o, const ConfigRuns& c) {
  o << "## Table 6: all configurations (mean and standard deviation over the runs)\n\n"
    << "| Configuration | runs | drift MEAN (%) | drift STD (%) | heading MEAN (deg) | heading STD "
       "(deg) | within 3 sigma (%) |\n|---|---|---|---|---|---|---|\n";
  const std::pair<const char*, const Runs*> rows6[] = {
      {"Wheel-INS", &c.singles}, {"Dual Wheel-INS", &c.dw}, {"Body/Wheel-INS", &c.bw}, {"Triple INS", &c.tw},
      {"Triple INS (centralized)", &c.cent}};
  for (const auto& [name, v] : rows6) {
    if (v->empty()) continue;
    std::vector<double> d, h, w;
    for (const auto* x : *v) {
      d.push_back(pct(x));
      h.push_back(deg(x));
      w.push_back(100.0 * x->eval.within_3sigma);
    }
    o << "| " << name << " | " << v->size() << " | " << fmt(mean(d), 3) << " | " << fmt(stddev(d), 3)
      << " | " << fmt(mean(h), 3) << " | " << fmt(stddev(h), 3) << " | " << fmt(mean(w), 1) << " |\n";
  }
  o << "\n";
}

/// Per-run step times of Table 8 [microseconds].
struct Timings {
  std::vector<double> velocity, position, epoch;
};

void add_timing(const ExperimentRun* x, Timings& t) {
  const NavigatorStats& s = x->stats;
  if (s.velocity_steps) t.velocity.push_back(1e6 * s.velocity_step_seconds / s.velocity_steps);
  if (s.position_steps) t.position.push_back(1e6 * s.position_step_seconds / s.position_steps);
  if (s.epochs) t.epoch.push_back(1e6 * x->filter_seconds / s.epochs);
}

void table8(std::ostream& o, const Timings& dist, const Timings& cent) {
  o << "\n## Table 8: running time of the Triple INS (microseconds, this machine)\n\n"
    << "Velocity update: all three subsystems' velocity/NHC updates at one epoch; position "
       "update: the multi-IMU constraint for all three; per epoch: the whole filter time "
       "(mechanization, covariance, updates, output) divided by the epochs of one IMU. "
       "Means over the runs above; runs share the machine's cores.\n\n"
    << "| Vel. update dist. | Vel. update cent. | Pos. update dist. | Pos. update cent. | "
       "Per epoch dist. | Per epoch cent. |\n|---|---|---|---|---|---|\n"
    << "| " << fmt(mean(dist.velocity), 1) << " | " << fmt(mean(cent.velocity), 1) << " | "
    << fmt(mean(dist.position), 1) << " | " << fmt(mean(cent.position), 1) << " | " << fmt(mean(dist.epoch), 1)
    << " | " << fmt(mean(cent.epoch), 1) << " |\n\n";
}

// Tables 7 and 8
void tables7_8(std::ostream& o, const ConfigRuns& runs) {
  if (runs.cent.empty()) return;
  o << "## Table 7: Triple INS, distributed vs centralized filter\n\n"
    << "| Test | chips | drift distributed (%) | drift centralized (%) | heading distributed "
       "(deg) | heading centralized (deg) |\n|---|---|---|---|---|---|\n";
  Timings dist, cent;
  for (std::size_t i = 0; i < runs.cent.size(); ++i) {
    const ExperimentRun* c = runs.cent[i];
    const ExperimentRun* d = nullptr;
    for (const auto* x : runs.tw)
      if (x->label == c->label) d = x;
    o << "| " << i + 1 << " | " << c->label << " | " << (d ? fmt(pct(d), 2) : "-") << " | "
      << fmt(pct(c), 2) << " | " << (d ? fmt(deg(d), 2) : "-") << " | " << fmt(deg(c), 2) << " |\n";
    if (d) add_timing(d, dist);
    add_timing(c, cent);
  }
  table8(o, dist, cent);
}

}  // namespace

std::string experiment_markdown(const ExperimentResult& r) {
  std::ostringstream o;
  ConfigRuns runs;
  runs.singles = runs_of(r, "single", false);
  runs.dw = runs_of(r, "dual-wheel", false);
  runs.bw = runs_of(r, "body-wheel", false);
  runs.tw = runs_of(r, "triple", false);
  runs.cent = runs_of(r, "triple", true);
  markdown_header(o, r);
  table4(o, runs.singles);
  table5(o, runs);
  table6(o, runs);
  tables7_8(o, runs);
  return o.str();
}

std::string experiment_csv(const ExperimentResult& r) {
  std::ostringstream o;
  o << "configuration,filter,chips,modules,drift_rate_pct,heading_rmse_deg,max_error_m,final_error_m,"
       "distance_m,within_3sigma_pct,mean_nees,epochs,filter_seconds,us_per_epoch,"
       "velocity_update_us,position_update_us,fault_events\n";
  for (const auto& x : r.runs) {
    std::string mods;
    for (const auto& m : x.modules) mods += (mods.empty() ? "" : "+") + m;
    const NavigatorStats& s = x.stats;
    o << x.configuration << "," << (x.centralized ? "centralized" : "distributed") << "," << x.label
      << "," << mods << "," << fmt(100 * x.eval.drift_rate, 5) << "," << fmt(x.eval.heading_rmse / kDeg, 5)
      << "," << fmt(x.eval.max_error, 4) << "," << fmt(x.eval.final_error, 4) << ","
      << fmt(x.eval.distance, 2) << "," << fmt(100 * x.eval.within_3sigma, 2) << ","
      << fmt(x.eval.mean_nees, 3) << "," << s.epochs << "," << fmt(x.filter_seconds, 4) << ","
      << fmt(s.epochs ? 1e6 * x.filter_seconds / s.epochs : NAN, 3) << ","
      << fmt(s.velocity_steps ? 1e6 * s.velocity_step_seconds / s.velocity_steps : NAN, 3) << ","
      << fmt(s.position_steps ? 1e6 * s.position_step_seconds / s.position_steps : NAN, 3) << ","
      << x.fault_events << "\n";
  }
  return o.str();
}

std::string experiment_json(const ExperimentResult& r) {
  std::ostringstream o;
  o << "{\n  \"manifest\": \"" << r.manifest.string() << "\",\n  \"wall_seconds\": "
    << fmt(r.wall_seconds, 3) << ",\n  \"runs\": [\n";
  for (std::size_t i = 0; i < r.runs.size(); ++i) {
    const auto& x = r.runs[i];
    o << "    {\"configuration\": \"" << x.configuration << "\", \"filter\": \""
      << (x.centralized ? "centralized" : "distributed") << "\", \"chips\": \"" << x.label
      << "\", \"modules\": [";
    for (std::size_t k = 0; k < x.modules.size(); ++k) o << (k ? ", " : "") << "\"" << x.modules[k] << "\"";
    o << "], \"filter_seconds\": " << fmt(x.filter_seconds, 4) << ", \"epochs\": " << x.stats.epochs
      << ", \"fault_events\": " << x.fault_events
      << ", \"evaluation\": " << to_json(x.eval) << "}" << (i + 1 < r.runs.size() ? "," : "") << "\n";
  }
  o << "  ]\n}\n";
  return o.str();
}

}  // namespace wheelins::eval
