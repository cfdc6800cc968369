// The experiment's plots (plots.hpp): the data and gnuplot scripts of Fig. 7-10 and the
// trajectory, and running gnuplot on them.
#include "wheelins/run/plots.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <utility>

#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/math/rotation.hpp"
#include "wheelins/nav/types.hpp"

extern char** environ;

namespace wheelins::eval {
namespace fs = std::filesystem;

namespace {

// --- Look and feel ----------------------------------------------------------

constexpr const char* kTerminal =
    "set terminal pngcairo size 1200,800 noenhanced font \"Sans,13\" linewidth 1.3\n";
constexpr const char* kColorConfig = "#000000";  // the multi-IMU configuration
constexpr const char* kColorLeft = "#1f77b4";    // left Wheel-INS
constexpr const char* kColorRight = "#d62728";   // right Wheel-INS
// Trajectory plot: Dual, Body/Wheel, Triple, single; truth in grey underneath.
constexpr const char* kTrackColors[] = {"#1f77b4", "#2ca02c", "#d62728", "#ff7f0e"};
// Fig. 10: up to 16 curves per panel (8 colours, solid then dashed).
constexpr const char* kCurveColors[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728",
                                        "#9467bd", "#8c564b", "#e377c2", "#17becf"};

/// A gnuplot double-quoted string (backslash escapes apply: "\n" is a line break
/// when the caller writes the two characters).
std::string gq(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += "\\\"";
    else out += c;
  }
  return out + "\"";
}
/// A gnuplot string holding `s` literally (no escapes): single quotes, '' for '.
std::string gq_literal(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

std::string num(double v, int significant = 0) {
  std::string s;
  append_double(s, v, significant);
  return s;
}

// --- Runs -----------------------------------------------------------------------

const char* const kConfigs[] = {"single", "dual-wheel", "body-wheel", "triple"};

std::string config_title(const std::string& config) {
  if (config == "single") return "single Wheel-INS";
  if (config == "dual-wheel") return "Dual Wheel-INS";
  if (config == "body-wheel") return "Body/Wheel-INS";
  if (config == "triple") return "Triple INS";
  return config;
}

/// Chip names of a run's modules in order ("C1", ...), or the module names when
/// the label is not one digit per module.
std::vector<std::string> chips_of(const ExperimentRun& run) {
  std::vector<std::string> c;
  for (std::size_t i = 0; i < run.modules.size(); ++i)
    c.push_back(run.label.size() == run.modules.size() ? "C" + std::string(1, run.label[i])
                                                       : run.modules[i]);
  return c;
}

/// File-name id: "single-left-C1", "dual-wheel-14".
std::string run_id(const ExperimentRun& run) {
  std::string id = run.configuration == "single"
                       ? "single-" + run.side + "-" + (chips_of(run).empty() ? run.label : chips_of(run)[0])
                       : run.configuration + "-" + run.label;
  for (char& c : id)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  return id;
}

/// "left C1, right C4" (wheel slots as in the paper: DW left/right, BW left/body,
/// TW left/right/body).
std::string chips_text(const ExperimentRun& run) {
  const auto chips = chips_of(run);
  std::vector<std::string> roles;
  if (run.configuration == "single") roles = {run.side};
  else if (run.configuration == "dual-wheel") roles = {"left", "right"};
  else if (run.configuration == "body-wheel") roles = {"left", "body"};
  else if (run.configuration == "triple") roles = {"left", "right", "body"};
  std::string s;
  for (std::size_t i = 0; i < chips.size(); ++i)
    s += (i ? ", " : "") + (i < roles.size() ? roles[i] + " " : std::string()) + chips[i];
  return s;
}

std::string run_title(const ExperimentRun& run) {
  if (run.configuration == "single") {
    std::string side = run.side;
    if (!side.empty()) side[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(side[0])));
    return side + " Wheel-INS (" + (chips_of(run).empty() ? run.label : chips_of(run)[0]) + ")";
  }
  return config_title(run.configuration) + " (" + chips_text(run) + ")";
}

/// The figure run of a multi-IMU configuration (distributed filter, series kept).
const ExperimentRun* figure_run(const ExperimentResult& r, const std::string& config) {
  for (const auto& run : r.runs)
    if (run.configuration == config && !run.centralized && run.figure && !run.eval.series.empty())
      return &run;
  return nullptr;
}

/// The stand-alone single Wheel-INS of `module`, if it was run with its series kept.
const ExperimentRun* single_of(const ExperimentResult& r, const std::string& module) {
  for (const auto& run : r.runs)
    if (run.configuration == "single" && run.modules.size() == 1 && run.modules[0] == module &&
        !run.eval.series.empty())
      return &run;
  return nullptr;
}

double nav_start(const ExperimentRun& run) {
  if (!run.track.empty()) return run.track.front().t;
  if (!run.eval.series.empty()) return std::min(run.eval.t_start, run.eval.series.front().t);
  return run.eval.t_start;
}

std::string dataset_text(const ExperimentResult& r) {
  return r.dataset_name.empty() ? r.manifest.filename().string() : r.dataset_name;
}

// --- What gets written ------------------------------------------------------

struct Output {
  std::vector<std::pair<fs::path, std::string>> files;  ///< relative to plots/, with content
  std::vector<std::string> plots;                       ///< script names without ".gp"
  std::vector<std::string> notes;                       ///< warnings (plots left out)
};

/// data/series_ID.csv (once per run).
std::string add_series(Output& out, const ExperimentRun& run, double t0) {
  const std::string rel = "data/series_" + run_id(run) + ".csv";
  for (const auto& f : out.files)
    if (f.first == rel) return rel;
  std::string s = "t_s,time_s,distance_m,err_h_m,heading_err_deg,sigma_h_m\n";
  for (const auto& e : run.eval.series) {
    s += num(e.t) + "," + num(e.t - t0, 9) + "," + num(e.distance, 9) + "," + num(e.err_h, 6) + "," +
         num(e.heading_err / kDeg, 6) + "," + num(e.sigma_h, 6) + "\n";
  }
  out.files.emplace_back(rel, std::move(s));
  return rel;
}

std::string script_head(const std::string& name, const std::string& what) {
  return "# " + what + "\n# Written by `wheelins experiment`; edit and re-run in this directory: gnuplot " +
         name + ".gp\nif (!exists(\"outfile\")) outfile = " + gq(name + ".png") + "\n" + kTerminal +
         "set output outfile\nset datafile separator \",\"\nset grid lc rgb \"#d0d0d0\"\n";
}

/// Fig. 7-9: the configuration and its wheel subsystems, error against time.
void add_error_figure(Output& out, const ExperimentResult& r, const std::string& config,
                      const std::string& name, const std::string& fig) {
  const ExperimentRun* run = figure_run(r, config);
  if (!run) {
    out.notes.push_back(name + ".png not drawn: no " + config_title(config) +
                        " run with a kept error series in this experiment");
    return;
  }
  struct Curve {
    const ExperimentRun* run;
    std::string title, color;
    double lw;
  };
  std::vector<Curve> curves;
  std::vector<std::string> missing;
  const auto chips = chips_of(*run);
  const bool has_right = config == "dual-wheel" || config == "triple";
  // Subsystems: the left Wheel-IMU (module 0), the right one (module 1) if any.
  for (std::size_t k = 0; k < (has_right ? 2u : 1u) && k < run->modules.size(); ++k) {
    const ExperimentRun* s = single_of(r, run->modules[k]);
    const std::string who = std::string(k == 0 ? "Left" : "Right") + " Wheel-INS (" + chips[k] + ")";
    if (s) curves.push_back({s, who, k == 0 ? kColorLeft : kColorRight, 1.5});
    else missing.push_back(who);
  }
  curves.push_back({run, config_title(config), kColorConfig, 2.5});  // chips: in the title

  double t0 = std::numeric_limits<double>::infinity(), tmax = 0.0;
  for (const auto& c : curves) t0 = std::min(t0, nav_start(*c.run));
  bool heading = false;
  for (const auto& c : curves) {
    tmax = std::max(tmax, c.run->eval.series.back().t - t0);
    for (const auto& e : c.run->eval.series) heading = heading || std::isfinite(e.heading_err);
  }

  std::string title = fig + ": " + run_title(*run) + " and its subsystems - " + dataset_text(r);
  std::vector<std::string> note_lines;
  if (config == "body-wheel" || config == "triple")
    note_lines.push_back(
        "No stand-alone Body-INS run in the experiment (the Body-IMU needs a Wheel-IMU's speed)");
  if (!missing.empty()) {
    std::string m;
    for (const auto& w : missing) m += (m.empty() ? "" : ", ") + w;
    note_lines.push_back("Not in this experiment: " + m);
  }
  if (!heading) note_lines.push_back("No heading errors: the truth has no attitude");
  for (const auto& n : note_lines) title += "\\n" + n;

  std::string s = script_head(name, fig + " of the paper: horizontal position and heading error of " +
                                        run_title(*run) + " and its single Wheel-INS subsystems.");
  s += "set multiplot layout " + std::string(heading ? "2" : "1") + ",1 title " + gq(title) +
       " font \",15\"\nset lmargin 12\nset rmargin 4\nset xrange [0:" + num(std::max(tmax, 1.0), 6) +
       "]\nset xlabel \"Time since start of navigation [s]\"\n"
       "# One legend, above the top panel (the bottom panel has the same curves).\n"
       "set key outside top center horizontal nobox samplen 3 spacing 1.2\n";
  auto panel = [&](int column, const std::string& ylabel) {
    s += "set ylabel " + gq(ylabel) + "\nplot \\\n";
    for (std::size_t i = 0; i < curves.size(); ++i) {
      const auto& c = curves[i];
      s += "  " + gq(add_series(out, *c.run, t0)) + " skip 1 using 2:" + std::to_string(column) +
           " with lines lw " + num(c.lw) + " lc rgb " + gq(c.color) + " title " + gq(c.title) +
           (i + 1 < curves.size() ? ", \\\n" : "\n");
    }
  };
  panel(4, "Horizontal position error [m]");
  s += "unset key\n";
  if (heading) panel(5, "Heading error [deg]");
  s += "unset multiplot\n";
  out.files.emplace_back(name + ".gp", std::move(s));
  out.plots.push_back(name);
}

/// The runs the trajectory plot draws: the figure runs with a kept track, then a single Wheel-INS.
std::vector<const ExperimentRun*> track_runs(const ExperimentResult& r) {
  std::vector<const ExperimentRun*> runs;
  for (const char* config : {"dual-wheel", "body-wheel", "triple"}) {
    for (const auto& run : r.runs)
      if (run.configuration == config && !run.centralized && run.figure && !run.track.empty()) {
        runs.push_back(&run);
        break;
      }
  }
  // The single Wheel-INS: on the Dual Wheel-INS run's left chip, else the first left one.
  const ExperimentRun* single = nullptr;
  const ExperimentRun* dw = figure_run(r, "dual-wheel");
  for (const auto& run : r.runs)
    if (run.configuration == "single" && !run.track.empty() && run.side == "left" &&
        (!single || (dw && run.modules == std::vector<std::string>{dw->modules[0]})))
      single = &run;
  if (single) runs.push_back(single);
  return runs;
}

/// The trajectory plot as it is put together: its plot commands and the east/north extent
/// of the points drawn.
struct TrackPlot {
  explicit TrackPlot(const earth::LocalFrame& f) : frame(f) {}

  /// `lla` in the local frame, the extent grown to hold it.
  Vec3 point(const earth::Geodetic& lla) {
    const Vec3 p = frame.ned_from_geodetic(lla);
    e_lo = std::min(e_lo, p.y());
    e_hi = std::max(e_hi, p.y());
    n_lo = std::min(n_lo, p.x());
    n_hi = std::max(n_hi, p.x());
    return p;
  }

  const earth::LocalFrame& frame;
  std::vector<std::string> parts;  ///< plot commands, in drawing order
  double e_lo = std::numeric_limits<double>::infinity(), e_hi = -e_lo, n_lo = e_lo, n_hi = -e_lo;
};

/// data/truth.csv over the runs' time span (and a second either side), with the start marked;
/// false when the truth has no record there.
bool add_truth_path(Output& out, TrackPlot& plot, const TruthData& truth,
                    const std::vector<const ExperimentRun*>& runs) {
  double t_lo = std::numeric_limits<double>::infinity(), t_hi = -t_lo;
  for (const auto* run : runs) {
    t_lo = std::min(t_lo, run->track.front().t);
    t_hi = std::max(t_hi, run->track.back().t);
  }
  std::string tr = "t_s,east_m,north_m\n";
  double last = -std::numeric_limits<double>::infinity();
  std::size_t n_truth = 0;
  for (std::size_t i = 0; i < truth.records.size(); ++i) {
    const TruthRecord& rec = truth.records[i];
    if (rec.t < t_lo - 1.0 || rec.t > t_hi + 1.0) continue;
    if (rec.t - last < 0.2 && i + 1 < truth.records.size()) continue;  // 5 Hz is plenty
    last = rec.t;
    const Vec3 p = plot.point(rec.lla);
    tr += num(rec.t) + "," + num(p.y(), 9) + "," + num(p.x(), 9) + "\n";
    ++n_truth;
  }
  if (n_truth == 0) return false;
  out.files.emplace_back("data/truth.csv", std::move(tr));
  plot.parts.push_back("  \"data/truth.csv\" skip 1 using 2:3 with lines lw 5 lc rgb \"#b0b0b0\" title \"Truth\"");
  plot.parts.push_back("  \"data/truth.csv\" skip 1 every ::0::0 using 2:3 with points pt 7 ps 2 "
                       "lc rgb \"#000000\" title \"Start\"");
  return true;
}

/// data/track_ID.csv, the `i`-th track drawn.
void add_track(Output& out, TrackPlot& plot, const ExperimentRun& run, std::size_t i) {
  const std::string rel = "data/track_" + run_id(run) + ".csv";
  std::string t = "t_s,east_m,north_m\n";
  for (const auto& rec : run.track) {
    const Vec3 p = plot.point(rec.lla);
    t += num(rec.t) + "," + num(p.y(), 9) + "," + num(p.x(), 9) + "\n";
  }
  out.files.emplace_back(rel, std::move(t));
  const std::size_t color = run.configuration == "dual-wheel"   ? 0
                            : run.configuration == "body-wheel" ? 1
                            : run.configuration == "triple"     ? 2
                                                                : 3;
  // None may hide another where the tracks lie on top of each other: the first drawn is the
  // widest, each later one narrower, dashed differently and a little transparent (ARGB).
  const double lw = std::max(1.2, 4.2 - 0.9 * static_cast<double>(i));
  const char* dash[] = {"1", "(12,5)", "(4,4)", "(14,4,3,4)"};
  plot.parts.push_back("  " + gq(rel) + " skip 1 using 2:3 with lines lw " + num(lw) + " dt " + dash[color] +
                       " lc rgb " + gq("#30" + std::string(kTrackColors[color] + 1)) + " title " +
                       gq(run_title(run)));
}

/// Truth path and the figure runs' tracks.
void add_trajectory(Output& out, const ExperimentResult& r, const TruthData& truth,
                    const earth::LocalFrame& frame) {
  const std::string name = "trajectory";
  const std::vector<const ExperimentRun*> runs = track_runs(r);
  if (runs.empty()) {
    out.notes.push_back(name + ".png not drawn: no run with a kept track in this experiment");
    return;
  }
  TrackPlot plot(frame);
  if (!add_truth_path(out, plot, truth, runs))
    out.notes.push_back(name + ".png: the truth does not cover the runs' time span (drawn without it)");
  for (std::size_t i = 0; i < runs.size(); ++i) add_track(out, plot, *runs[i], i);
  // Equal scale on a 3:2 canvas: the legend goes where the path leaves room.
  const bool wide = (plot.e_hi - plot.e_lo) > 1.2 * (plot.n_hi - plot.n_lo);
  std::string s = script_head(name, "Truth path and the experiment's figure runs (local east/north).");
  s += "set title " + gq("Trajectory: truth and dead reckoning - " + dataset_text(r)) +
       " font \",15\"\nset size ratio -1\n" +
       (wide ? "set key outside bottom center horizontal Left reverse box samplen 3 spacing 1.2\n"
             : "set key outside right top vertical Left reverse box samplen 3 spacing 1.2\n") +
       "set xlabel \"East [m]\"\nset ylabel \"North [m]\"\nplot \\\n";
  const auto& parts = plot.parts;
  for (std::size_t i = 0; i < parts.size(); ++i) s += parts[i] + (i + 1 < parts.size() ? ", \\\n" : "\n");
  out.files.emplace_back(name + ".gp", std::move(s));
  out.plots.push_back(name);
}

/// Fig. 10's curves: each run's drift rate every `step` metres.
struct DriftCurves {
  bool fine = false;  ///< from the per-epoch errors (a short drive), for the figure runs only
  double step = 0.0;

  bool shows(const ExperimentRun& run) const { return !run.centralized && (!fine || run.figure); }
  std::vector<double> of(const ExperimentRun& run) const {
    if (!fine) return run.eval.drift_curve;
    std::vector<double> dist, err;
    for (const auto& e : run.eval.series) dist.push_back(e.distance), err.push_back(e.err_h);
    return drift_rate_curve(dist, err, step);
  }
};

/// data/drift_CONFIG.csv: one column per run, `kplot` rows.
std::string drift_data(const std::vector<const ExperimentRun*>& runs, const DriftCurves& curves,
                       std::size_t kplot) {
  std::string d = "distance_m";
  for (const auto* run : runs) d += "," + run_id(*run) + "_pct";
  d += "\n";
  std::vector<std::vector<double>> values;
  for (const auto* run : runs) values.push_back(curves.of(*run));
  for (std::size_t k = 0; k < kplot; ++k) {
    d += num(static_cast<double>(k + 1) * curves.step);
    for (const auto& c : values) d += "," + (k < c.size() ? num(100.0 * c[k], 6) : "");
    d += "\n";
  }
  return d;
}

/// Fig. 10's panel `p` (a configuration): its data file added to `out`, its script returned.
std::string drift_panel(Output& out, const ExperimentResult& r, const DriftCurves& curves, std::size_t kplot,
                        int p) {
  const std::string key = "set key top right font \",10\" maxrows 8 opaque box\n";
  const char letters[] = {'a', 'b', 'c', 'd'};
  const std::string config = kConfigs[p];
  std::vector<const ExperimentRun*> runs;
  for (const auto& run : r.runs)
    if (run.configuration == config && curves.shows(run) && !curves.of(run).empty()) runs.push_back(&run);
  std::string s = "set title " + gq("(" + std::string(1, letters[p]) + ") " + config_title(config)) + "\n";
  if (runs.empty())
    return s + "unset key\nset label 1 \"no run in this experiment\" at graph 0.5,0.5 center\n"
               "plot [][0:1] NaN notitle\nunset label 1\n";
  const std::string rel = "data/drift_" + config + ".csv";
  out.files.emplace_back(rel, drift_data(runs, curves, kplot));
  s += key + "plot \\\n";
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const ExperimentRun& run = *runs[i];
    const std::string label =
        config == "single" ? run.side + " " + (chips_of(run).empty() ? run.label : chips_of(run)[0])
                           : run.label;
    s += "  " + gq(rel) + " skip 1 using 1:" + std::to_string(i + 2) + " with linespoints lw 1.5 pt " +
         std::to_string(5 + static_cast<int>(i % 4)) + " ps 0.8 dt " + (i < 8 ? "1" : "2") +
         " lc rgb " + gq(kCurveColors[i % 8]) + " title " + gq(label) +
         (i + 1 < runs.size() ? ", \\\n" : "\n");
  }
  return s;
}

/// Fig. 10: drift rate against distance, one panel per configuration.
void add_drift_figure(Output& out, const ExperimentResult& r) {
  const std::string name = "fig10_drift_rate";
  double segment = 100.0;
  std::size_t kmax = 0;
  for (const auto& run : r.runs)
    if (!run.centralized && !run.eval.drift_curve.empty()) {
      kmax = std::max(kmax, run.eval.drift_curve.size());
      segment = run.eval.segment_length;
    }
  if (kmax == 0) {
    out.notes.push_back(name + ".png not drawn: no run covered " + num(segment) +
                        " m (the drift rate needs at least one segment)");
    return;
  }
  // A short drive (fewer than 5 segments) would leave each curve one or two points: the
  // curve is then drawn every l/10 from the per-epoch errors, which the figure runs keep.
  DriftCurves curves;
  curves.fine = kmax < 5;
  curves.step = curves.fine ? segment / 10.0 : segment;
  std::size_t kplot = 0;
  for (const auto& run : r.runs)
    if (curves.shows(run)) kplot = std::max(kplot, curves.of(run).size());
  if (kplot == 0) {
    out.notes.push_back(name + ".png not drawn: the drive is shorter than " + num(curves.step) + " m");
    return;
  }
  if (curves.fine)
    out.notes.push_back(name + ".png: the drive covers " + std::to_string(kmax) + " segment(s) of " + num(segment) +
                        " m only, so the curves are drawn every " + num(curves.step) + " m, for the figure runs");
  std::string s = script_head(name, "Fig. 10 of the paper: drift rate r_k = max horizontal error within "
                                    "k*l / (k*l) against the distance k*l, every run.");
  s += "set multiplot layout 2,2 title " +
       gq(curves.fine ? "Fig. 10: position drift rate against distance, every " + num(curves.step) +
                            " m (a short drive: the figure runs) - " + dataset_text(r)
                      : "Fig. 10: position drift rate against distance, every run - " + dataset_text(r)) +
       " font \",15\"\nset xlabel \"Distance [m]\"\nset ylabel \"Drift rate [%]\"\n"
       "set xrange [0:" + num(static_cast<double>(kplot + 1) * curves.step) + "]\nset yrange [0:*]\n";
  for (int p = 0; p < 4; ++p) s += drift_panel(out, r, curves, kplot, p);
  s += "unset multiplot\n";
  out.files.emplace_back(name + ".gp", std::move(s));
  out.plots.push_back(name);
}

// --- Running gnuplot ------------------------------------------------------------

struct ProgramResult {
  bool not_found = false;
  int exit_code = -1;  ///< -1 when it did not exit normally
  std::string output;  ///< stdout and stderr together
};

/// Runs `argv[0]` (searched on PATH) with stdin from /dev/null, capturing its output.
ProgramResult run_program(const std::vector<std::string>& argv) {
  ProgramResult res;
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0)
    throw InputError(std::string("cannot create a pipe for gnuplot: ") + std::strerror(errno));
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&fa, fds[1], 1);
  posix_spawn_file_actions_adddup2(&fa, fds[1], 2);
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int rc = ::posix_spawnp(&pid, args[0], &fa, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  ::close(fds[1]);
  if (rc != 0) {
    ::close(fds[0]);
    res.not_found = rc == ENOENT || rc == EACCES || rc == ENOTDIR;
    res.output = std::strerror(rc);
    return res;
  }
  char buf[4096];
  for (;;) {
    const ssize_t n = ::read(fds[0], buf, sizeof buf);
    if (n > 0) res.output.append(buf, static_cast<std::size_t>(n));
    else if (n == 0 || errno != EINTR) break;
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status)) res.exit_code = WEXITSTATUS(status);
  return res;
}

std::string first_lines(const std::string& text, int lines) {
  std::string out;
  int n = 0;
  for (char c : text) {
    if (c == '\n') {
      if (++n == lines) break;
      out += " | ";
      continue;
    }
    out += c;
  }
  while (out.size() >= 3 && out.compare(out.size() - 3, 3, " | ") == 0) out.resize(out.size() - 3);
  return out;
}

}  // namespace

std::vector<fs::path> experiment_plot_targets(const fs::path& dir) {
  std::vector<fs::path> v;
  for (const char* name :
       {"trajectory", "fig7_dual_wheel", "fig8_body_wheel", "fig9_triple", "fig10_drift_rate"}) {
    v.push_back(dir / "plots" / (std::string(name) + ".gp"));
    v.push_back(dir / "plots" / (std::string(name) + ".png"));
  }
  return v;
}

std::vector<fs::path> write_experiment_plots(const ExperimentResult& r, const TruthData& truth,
                                             const earth::LocalFrame& frame, const fs::path& dir,
                                             bool overwrite, const WarningSink& warn,
                                             const PlotOptions& options) {
  const fs::path plots = dir / "plots";
  Output out;
  add_trajectory(out, r, truth, frame);
  add_error_figure(out, r, "dual-wheel", "fig7_dual_wheel", "Fig. 7");
  add_error_figure(out, r, "body-wheel", "fig8_body_wheel", "Fig. 8");
  add_error_figure(out, r, "triple", "fig9_triple", "Fig. 9");
  add_drift_figure(out, r);

  // Nothing is written when anything would be replaced without permission.
  for (const auto& [rel, text] : out.files) check_output_target(plots / rel, overwrite);
  for (const auto& name : out.plots) check_output_target(plots / (name + ".png"), overwrite);

  std::vector<fs::path> written;
  for (const auto& [rel, text] : out.files) {
    AtomicTextFile f(plots / rel, overwrite);
    f.write(text);
    f.commit();
    written.push_back(plots / rel);
  }
  if (warn)
    for (const auto& n : out.notes) warn(n);
  if (!options.render || out.plots.empty()) return written;
  for (auto& f : render_gnuplot(plots, out.plots, warn, options)) written.push_back(std::move(f));
  return written;
}

std::vector<fs::path> render_gnuplot(const fs::path& plots, const std::vector<std::string>& names,
                                     const WarningSink& warn, const PlotOptions& options) {
  std::vector<fs::path> written;
  const fs::path abs_plots = fs::absolute(plots);
  for (const auto& name : names) {
    const fs::path png = abs_plots / (name + ".png");
    // A name of its own: two reports drawing into one directory never share a temporary.
    const fs::path partial = io_detail::unique_partial(png);
    const ProgramResult pr = run_program(
        {options.gnuplot, "-e",
         "cd " + gq_literal(abs_plots.string()) + "; outfile = " + gq_literal(partial.filename().string()),
         (abs_plots / (name + ".gp")).string()});
    if (pr.not_found) {
      if (warn)
        warn("gnuplot ('" + options.gnuplot + "') not found (" + pr.output + "): the plots' data and "
             "scripts are in " + plots.string() + " but no PNG was drawn; install gnuplot (Debian: "
             "apt-get install gnuplot-nox, or scripts/setup.sh), then run: cd " + plots.string() +
             " && for f in *.gp; do gnuplot \"$f\"; done");
      return written;
    }
    std::error_code ec;
    if (pr.exit_code != 0 || !fs::exists(partial, ec)) {
      fs::remove(partial, ec);
      if (warn)
        warn("gnuplot failed on " + (plots / (name + ".gp")).string() +
             (pr.exit_code == 0 ? std::string(" (it exited 0 but wrote no image)")
                                : " (exit " + std::to_string(pr.exit_code) + ")") +
             (pr.output.empty() ? std::string() : ": " + first_lines(pr.output, 6)));
      continue;
    }
    move_into_place(partial, png, true);
    written.push_back(plots / (name + ".png"));
  }
  return written;
}

}  // namespace wheelins::eval
