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

std::string experiment_markdown(const ExperimentResult& r) {
  std::ostringstream o;
  auto runs_of = [&](const std::string& config, bool centralized) {
    std::vector<const ExperimentRun*> v;
    for (const auto& run : r.runs)
      if (run.configuration == config && run.centralized == centralized) v.push_back(&run);
    return v;
  };
  auto pct = [](const ExperimentRun* x) { return 100.0 * x->eval.drift_rate; };
  auto deg = [](const ExperimentRun* x) { return x->eval.heading_rmse / kDeg; };

  o << "# Experiment: " << (r.dataset_name.empty() ? r.manifest.string() : r.dataset_name) << "\n\n"
    << "Dataset `" << r.manifest.string() << "`; " << r.runs.size() << " runs in "
    << fmt(r.wall_seconds, 1) << " s. Each run navigates "
    << (r.duration > 0.0 ? fmt(r.duration, 1) + " s after the static period (--duration)"
                         : std::string("all the data (no --duration)"))
    << ". Drift rate: paper Section VI-B (l = 100 m), in % of distance; heading RMSE in degrees.\n\n";

  // Table 4
  const auto singles = runs_of("single", false);
  if (!singles.empty()) {
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

  // Table 5
  const auto dw = runs_of("dual-wheel", false), bw = runs_of("body-wheel", false),
             tw = runs_of("triple", false);
  const std::size_t n5 = std::max({dw.size(), bw.size(), tw.size()});
  if (n5 > 0) {
    o << "## Table 5: Dual Wheel-INS (DW), Body/Wheel-INS (BW), Triple INS (TW)\n\n"
      << "Chips: DW left/right, BW left/body, TW left/right/body. Best of a row in bold.\n\n"
      << "| Test | DW chips | BW chips | TW chips | DW drift (%) | BW drift (%) | TW drift (%) | "
         "DW heading (deg) | BW heading (deg) | TW heading (deg) |\n"
      << "|---|---|---|---|---|---|---|---|---|---|\n";
    auto at = [](const std::vector<const ExperimentRun*>& v, std::size_t i) {
      return i < v.size() ? v[i] : nullptr;
    };
    for (std::size_t i = 0; i < n5; ++i) {
      const ExperimentRun* row[3] = {at(dw, i), at(bw, i), at(tw, i)};
      o << "| " << i + 1 << " |";
      for (const auto* x : row) o << " " << (x ? x->label : "-") << " |";
      for (int metric = 0; metric < 2; ++metric) {
        double best = INFINITY;
        for (const auto* x : row)
          if (x) best = std::min(best, metric == 0 ? pct(x) : deg(x));
        for (const auto* x : row) {
          if (!x) {
            o << " - |";
            continue;
          }
          const double v = metric == 0 ? pct(x) : deg(x);
          const std::string t = fmt(v, 2);
          o << " " << (v == best ? "**" + t + "**" : t) << " |";
        }
      }
      o << "\n";
    }
    o << "\n";
  }

  // Table 6
  o << "## Table 6: all configurations (mean and standard deviation over the runs)\n\n"
    << "| Configuration | runs | drift MEAN (%) | drift STD (%) | heading MEAN (deg) | heading STD "
       "(deg) | within 3 sigma (%) |\n|---|---|---|---|---|---|---|\n";
  const std::pair<const char*, std::vector<const ExperimentRun*>> rows6[] = {
      {"Wheel-INS", singles}, {"Dual Wheel-INS", dw}, {"Body/Wheel-INS", bw}, {"Triple INS", tw},
      {"Triple INS (centralized)", runs_of("triple", true)}};
  for (const auto& [name, v] : rows6) {
    if (v.empty()) continue;
    std::vector<double> d, h, c;
    for (const auto* x : v) {
      d.push_back(pct(x));
      h.push_back(deg(x));
      c.push_back(100.0 * x->eval.within_3sigma);
    }
    o << "| " << name << " | " << v.size() << " | " << fmt(mean(d), 3) << " | " << fmt(stddev(d), 3)
      << " | " << fmt(mean(h), 3) << " | " << fmt(stddev(h), 3) << " | " << fmt(mean(c), 1) << " |\n";
  }
  o << "\n";

  // Tables 7 and 8
  const auto cent = runs_of("triple", true);
  if (!cent.empty()) {
    o << "## Table 7: Triple INS, distributed vs centralized filter\n\n"
      << "| Test | chips | drift distributed (%) | drift centralized (%) | heading distributed "
         "(deg) | heading centralized (deg) |\n|---|---|---|---|---|---|\n";
    std::vector<double> vd, vc, pd, pc, ed, ec;
    for (std::size_t i = 0; i < cent.size(); ++i) {
      const ExperimentRun* c = cent[i];
      const ExperimentRun* d = nullptr;
      for (const auto* x : tw)
        if (x->label == c->label) d = x;
      o << "| " << i + 1 << " | " << c->label << " | " << (d ? fmt(pct(d), 2) : "-") << " | "
        << fmt(pct(c), 2) << " | " << (d ? fmt(deg(d), 2) : "-") << " | " << fmt(deg(c), 2) << " |\n";
      auto timing = [](const ExperimentRun* x, std::vector<double>& v, std::vector<double>& p,
                       std::vector<double>& e) {
        const NavigatorStats& s = x->stats;
        if (s.velocity_steps) v.push_back(1e6 * s.velocity_step_seconds / s.velocity_steps);
        if (s.position_steps) p.push_back(1e6 * s.position_step_seconds / s.position_steps);
        if (s.epochs) e.push_back(1e6 * x->filter_seconds / s.epochs);
      };
      if (d) timing(d, vd, pd, ed);
      timing(c, vc, pc, ec);
    }
    o << "\n## Table 8: running time of the Triple INS (microseconds, this machine)\n\n"
      << "Velocity update: all three subsystems' velocity/NHC updates at one epoch; position "
         "update: the multi-IMU constraint for all three; per epoch: the whole filter time "
         "(mechanization, covariance, updates, output) divided by the epochs of one IMU. "
         "Means over the runs above; runs share the machine's cores.\n\n"
      << "| Vel. update dist. | Vel. update cent. | Pos. update dist. | Pos. update cent. | "
         "Per epoch dist. | Per epoch cent. |\n|---|---|---|---|---|---|\n"
      << "| " << fmt(mean(vd), 1) << " | " << fmt(mean(vc), 1) << " | " << fmt(mean(pd), 1) << " | "
      << fmt(mean(pc), 1) << " | " << fmt(mean(ed), 1) << " | " << fmt(mean(ec), 1) << " |\n\n";
  }
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
