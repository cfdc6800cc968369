// The experiment's plots: data files and gnuplot scripts from an in-memory
// ExperimentResult (no simulation), the refusal to overwrite, the warning when
// gnuplot is missing, and the PNGs when gnuplot is installed.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "io_test_util.hpp"
#include "wheelins/run/experiment.hpp"
#include "wheelins/run/plots.hpp"
#include "wheelins/io/manifest.hpp"
#include "wheelins/math/rotation.hpp"

namespace wheelins {
namespace {
namespace fs = std::filesystem;
using iotest::ScratchDir;

const earth::Geodetic kOrigin{30.5 * kDeg, 114.3 * kDeg, 20.0};

/// A 50 m circle driven at 1.5 m/s for 400 s (600 m: 6 drift segments), 10 Hz.
TruthData circle_truth(const earth::LocalFrame& frame) {
  TruthData t;
  t.file = "truth.bin";
  for (int i = 0; i <= 4000; ++i) {
    const double time = 1000.0 + 0.1 * i, a = 1.5 * 0.1 * i / 50.0;
    TruthRecord r;
    r.t = time;
    r.lla = frame.geodetic_from_ned(Vec3(50.0 * std::sin(a), 50.0 - 50.0 * std::cos(a), 0.0));
    r.rpy = Vec3(0.0, 0.0, a);
    t.records.push_back(r);
  }
  return t;
}

eval::ExperimentRun make_run(const std::string& config, const std::vector<std::string>& modules,
                             const std::string& label, const std::string& side, double error_scale,
                             const earth::LocalFrame& frame, bool figure) {
  eval::ExperimentRun run;
  run.configuration = config;
  run.modules = modules;
  run.label = label;
  run.side = side;
  run.figure = figure;
  run.eval.segment_length = 100.0;
  for (int k = 1; k <= 6; ++k) run.eval.drift_curve.push_back(error_scale * 0.01 / k);
  run.eval.drift_rate = error_scale * 0.005;
  run.eval.has_heading = true;
  if (!figure) return run;
  run.eval.t_start = 1000.5;
  for (int i = 5; i <= 4000; i += 10) {  // 1 Hz is enough here
    eval::EpochError e;
    e.t = 1000.0 + 0.1 * i;
    e.distance = 1.5 * 0.1 * i;
    e.err_h = error_scale * 0.01 * e.distance;
    e.heading_err = error_scale * 0.5 * kDeg;
    e.sigma_h = 1.0;
    run.eval.series.push_back(e);
  }
  for (int s = 0; s <= 400; ++s) {
    const double a = 1.5 * s / 50.0;
    TrajectoryRecord rec;
    rec.t = 1000.0 + s;
    rec.p_inN = Vec3(50.0 * std::sin(a) + error_scale * 0.01 * s, 50.0 - 50.0 * std::cos(a), 0.0);
    rec.lla = frame.geodetic_from_ned(rec.p_inN);
    run.track.push_back(rec);
  }
  return run;
}

/// Four singles (left/right C1, C2), the first Dual/Body/Triple combinations as
/// figure runs, one more non-figure run each, and a centralized run.
eval::ExperimentResult synthetic_result(const earth::LocalFrame& frame) {
  eval::ExperimentResult r;
  r.manifest = "/data/synthetic/manifest.yaml";
  r.dataset_name = "synthetic_circle";
  r.origin = kOrigin;
  auto& v = r.runs;
  v.push_back(make_run("single", {"left-C1"}, "1", "left", 1.0, frame, true));
  v.push_back(make_run("single", {"left-C2"}, "2", "left", 2.0, frame, true));
  v.push_back(make_run("single", {"right-C1"}, "1", "right", 1.5, frame, true));
  v.push_back(make_run("single", {"right-C2"}, "2", "right", 0.8, frame, true));
  v.push_back(make_run("dual-wheel", {"left-C1", "right-C2"}, "12", "", 0.9, frame, true));
  v.push_back(make_run("dual-wheel", {"left-C2", "right-C1"}, "21", "", 1.2, frame, false));
  v.push_back(make_run("body-wheel", {"left-C2", "body-C2"}, "22", "", 0.7, frame, true));
  v.push_back(make_run("body-wheel", {"left-C1", "body-C1"}, "11", "", 0.6, frame, false));
  v.push_back(make_run("triple", {"left-C1", "right-C2", "body-C2"}, "122", "", 0.5, frame, true));
  v.push_back(make_run("triple", {"left-C2", "right-C1", "body-C2"}, "212", "", 0.4, frame, false));
  auto c = make_run("triple", {"left-C1", "right-C2", "body-C2"}, "122", "", 9.0, frame, false);
  c.centralized = true;
  v.push_back(c);
  return r;
}

std::string read_all(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
std::vector<std::string> lines_of(const fs::path& f) {
  std::vector<std::string> v;
  std::ifstream in(f);
  for (std::string l; std::getline(in, l);) v.push_back(l);
  return v;
}
std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> v;
  std::stringstream ss(s);
  for (std::string x; std::getline(ss, x, ',');) v.push_back(x);
  if (!s.empty() && s.back() == ',') v.push_back("");
  return v;
}

bool gnuplot_available() {
  return std::system("gnuplot --version > /dev/null 2>&1") == 0;
}

struct Written {
  std::vector<fs::path> files;
  std::vector<std::string> warnings;
};

Written write(const ScratchDir& dir, bool overwrite, const eval::PlotOptions& o) {
  const earth::LocalFrame frame(kOrigin);
  Written w;
  w.files = eval::write_experiment_plots(
      synthetic_result(frame), circle_truth(frame), frame, dir.path(), overwrite,
      [&](const std::string& m) { w.warnings.push_back(m); }, o);
  return w;
}

TEST(EvalPlots, DataAndScriptsHaveTheExpectedColumns) {
  ScratchDir dir;
  eval::PlotOptions o;
  o.render = false;
  const Written w = write(dir, false, o);
  EXPECT_TRUE(w.warnings.empty()) << w.warnings.front();
  const fs::path p = dir / "plots";
  for (const char* name :
       {"trajectory", "fig7_dual_wheel", "fig8_body_wheel", "fig9_triple", "fig10_drift_rate"}) {
    EXPECT_TRUE(fs::exists(p / (std::string(name) + ".gp"))) << name;
    EXPECT_FALSE(fs::exists(p / (std::string(name) + ".png"))) << name;
  }
  for (const auto& f : w.files) EXPECT_TRUE(fs::exists(f)) << f;

  // Error series: time from the start of navigation (the tracks start at 1000 s).
  const auto series = lines_of(p / "data/series_single-left-C1.csv");
  ASSERT_EQ(series.size(), 401u);
  EXPECT_EQ(series[0], "t_s,time_s,distance_m,err_h_m,heading_err_deg,sigma_h_m");
  auto row = split(series[1]);
  ASSERT_EQ(row.size(), 6u);
  EXPECT_DOUBLE_EQ(std::stod(row[0]), 1000.5);
  EXPECT_NEAR(std::stod(row[1]), 0.5, 1e-9);
  EXPECT_NEAR(std::stod(row[3]), 0.01 * 0.75, 1e-9);
  EXPECT_NEAR(std::stod(row[4]), 0.5, 1e-9);  // degrees
  for (const char* f : {"series_single-right-C2.csv", "series_dual-wheel-12.csv",
                        "series_single-left-C2.csv", "series_body-wheel-22.csv",
                        "series_triple-122.csv"})
    EXPECT_TRUE(fs::exists(p / "data" / f)) << f;
  EXPECT_FALSE(fs::exists(p / "data/series_dual-wheel-21.csv"));  // not a figure run

  // Fig. 7: the configuration and both wheel subsystems, both panels.
  const std::string fig7 = read_all(p / "fig7_dual_wheel.gp");
  EXPECT_NE(fig7.find("set terminal pngcairo size 1200,800"), std::string::npos);
  EXPECT_NE(fig7.find("layout 2,1"), std::string::npos);
  for (const char* s : {"\"data/series_dual-wheel-12.csv\" skip 1 using 2:4",
                        "\"data/series_single-left-C1.csv\" skip 1 using 2:5",
                        "\"data/series_single-right-C2.csv\" skip 1 using 2:4",
                        "Dual Wheel-INS (left C1, right C2)", "Heading error [deg]",
                        "Horizontal position error [m]", "Time since start of navigation [s]"})
    EXPECT_NE(fig7.find(s), std::string::npos) << s;
  // Fig. 8: left C2 single; no Body-INS run, and the plot says so.
  const std::string fig8 = read_all(p / "fig8_body_wheel.gp");
  EXPECT_NE(fig8.find("series_single-left-C2.csv"), std::string::npos);
  EXPECT_EQ(fig8.find("series_single-right"), std::string::npos);
  EXPECT_NE(fig8.find("No stand-alone Body-INS run"), std::string::npos);
  const std::string fig9 = read_all(p / "fig9_triple.gp");
  EXPECT_NE(fig9.find("Triple INS (left C1, right C2, body C2)"), std::string::npos);

  // Trajectory: truth in east/north of the local frame, clipped to the tracks' span.
  const auto truth = lines_of(p / "data/truth.csv");
  ASSERT_GT(truth.size(), 100u);
  EXPECT_EQ(truth[0], "t_s,east_m,north_m");
  row = split(truth[1]);
  EXPECT_NEAR(std::stod(row[1]), 0.0, 1e-6);
  EXPECT_NEAR(std::stod(row[2]), 0.0, 1e-6);
  const auto track = lines_of(p / "data/track_dual-wheel-12.csv");
  ASSERT_EQ(track.size(), 402u);
  EXPECT_EQ(track[0], "t_s,east_m,north_m");
  row = split(track[101]);  // t = 1100 s: north = 50 sin(3) + 0.9, east = 50 - 50 cos(3)
  EXPECT_NEAR(std::stod(row[0]), 1100.0, 1e-9);
  EXPECT_NEAR(std::stod(row[1]), 50.0 - 50.0 * std::cos(3.0), 1e-4);
  EXPECT_NEAR(std::stod(row[2]), 50.0 * std::sin(3.0) + 0.9, 1e-4);
  for (const char* f : {"track_body-wheel-22.csv", "track_triple-122.csv", "track_single-left-C1.csv"})
    EXPECT_TRUE(fs::exists(p / "data" / f)) << f;
  const std::string traj = read_all(p / "trajectory.gp");
  EXPECT_NE(traj.find("set size ratio -1"), std::string::npos);  // equal axis scale
  EXPECT_NE(traj.find("East [m]"), std::string::npos);

  // Fig. 10: one column per distributed run, r_k in percent, the centralized run left out.
  const auto single = lines_of(p / "data/drift_single.csv");
  ASSERT_EQ(single.size(), 7u);
  EXPECT_EQ(single[0],
            "distance_m,single-left-C1_pct,single-left-C2_pct,single-right-C1_pct,single-right-C2_pct");
  row = split(single[2]);
  EXPECT_DOUBLE_EQ(std::stod(row[0]), 200.0);
  EXPECT_NEAR(std::stod(row[2]), 100.0 * 2.0 * 0.01 / 2, 1e-9);
  const auto triple = lines_of(p / "data/drift_triple.csv");
  EXPECT_EQ(triple[0], "distance_m,triple-122_pct,triple-212_pct");
  EXPECT_NEAR(std::stod(split(triple[1])[1]), 0.5, 1e-9);  // distributed, not the centralized 9.0
  const std::string fig10 = read_all(p / "fig10_drift_rate.gp");
  EXPECT_NE(fig10.find("layout 2,2"), std::string::npos);
  for (const char* s : {"title \"left C1\"", "title \"12\"", "title \"22\"", "title \"212\"",
                        "Drift rate [%]", "Distance [m]"})
    EXPECT_NE(fig10.find(s), std::string::npos) << s;
}

TEST(EvalPlots, RefusesToOverwriteUnlessAsked) {
  ScratchDir dir;
  eval::PlotOptions o;
  o.render = false;
  write(dir, false, o);
  const auto before = read_all(dir / "plots/fig7_dual_wheel.gp");
  const std::string err = iotest::error_of([&] { write(dir, false, o); });
  EXPECT_NE(err.find("already exists"), std::string::npos) << err;
  EXPECT_NO_THROW(write(dir, true, o));
  EXPECT_EQ(read_all(dir / "plots/fig7_dual_wheel.gp"), before);
}

TEST(EvalPlots, MissingGnuplotLeavesDataAndOneWarning) {
  ScratchDir dir;
  eval::PlotOptions o;
  o.gnuplot = "wheelins-test-no-such-gnuplot";
  const Written w = write(dir, false, o);
  ASSERT_EQ(w.warnings.size(), 1u);
  EXPECT_NE(w.warnings[0].find("gnuplot-nox"), std::string::npos) << w.warnings[0];
  EXPECT_NE(w.warnings[0].find((dir / "plots").string()), std::string::npos) << w.warnings[0];
  EXPECT_TRUE(fs::exists(dir / "plots/fig10_drift_rate.gp"));
  EXPECT_TRUE(fs::exists(dir / "plots/data/drift_single.csv"));
  for (const auto& f : w.files) EXPECT_NE(f.extension(), ".png") << f;
  for (const auto& e : fs::recursive_directory_iterator(dir.path()))
    EXPECT_EQ(e.path().string().find(".png"), std::string::npos) << e.path();
}

TEST(EvalPlots, GnuplotDrawsPngs) {
  if (!gnuplot_available()) GTEST_SKIP() << "gnuplot is not installed (apt-get install gnuplot-nox)";
  ScratchDir dir;
  const Written w = write(dir, false, {});
  EXPECT_TRUE(w.warnings.empty()) << w.warnings.front();
  int pngs = 0;
  for (const char* name :
       {"trajectory", "fig7_dual_wheel", "fig8_body_wheel", "fig9_triple", "fig10_drift_rate"}) {
    const fs::path png = dir / "plots" / (std::string(name) + ".png");
    ASSERT_TRUE(fs::exists(png)) << png;
    EXPECT_GT(fs::file_size(png), 10000u) << png;
    const std::string head = read_all(png).substr(0, 8);
    EXPECT_EQ(head, std::string("\x89PNG\r\n\x1a\n", 8)) << png;
    EXPECT_FALSE(iotest::partial_left(png));
    ++pngs;
  }
  int listed = 0;
  for (const auto& f : w.files) listed += f.extension() == ".png";
  EXPECT_EQ(listed, pngs);
}

// Overlaid tracks stay visible where they lie on top of each other (issue 34): the first
// drawn is the widest, each later one narrower and dashed differently, all a little
// transparent.
TEST(EvalPlots, OverlaidTracksDifferInWidthAndDash) {
  ScratchDir dir;
  eval::PlotOptions o;
  o.render = false;
  write(dir, false, o);
  std::vector<double> widths;
  std::set<std::string> dashes;
  for (const auto& l : lines_of(dir / "plots" / "trajectory.gp")) {
    const auto lw = l.find(" with lines lw ");
    if (lw == std::string::npos || l.find("track_") == std::string::npos) continue;
    widths.push_back(std::stod(l.substr(lw + 15)));
    const auto dt = l.find(" dt ");
    ASSERT_NE(dt, std::string::npos) << l;
    dashes.insert(l.substr(dt + 4, l.find(' ', dt + 4) - dt - 4));
    EXPECT_NE(l.find("lc rgb \"#30"), std::string::npos) << l;  // ARGB: a little transparent
  }
  ASSERT_GE(widths.size(), 4u);
  for (std::size_t i = 1; i < widths.size(); ++i) EXPECT_LE(widths[i], widths[i - 1]);
  EXPECT_GT(widths.front(), widths.back());
  EXPECT_EQ(dashes.size(), 4u);  // one dash pattern per configuration
}

// Fig. 10 on a short drive (fewer than 5 segments of l, issue 34): each curve would be one or
// two points; it is drawn every l/10 from the figure runs' per-epoch errors instead, and a
// note says so.
TEST(EvalPlots, ShortDriveDrawsFig10EveryTenthOfASegment) {
  ScratchDir dir;
  const earth::LocalFrame frame(kOrigin);
  eval::ExperimentResult r = synthetic_result(frame);
  for (auto& run : r.runs) {
    run.eval.drift_curve.resize(2);  // 2 segments of 100 m
    std::erase_if(run.eval.series, [](const eval::EpochError& e) { return e.distance > 250.0; });
  }
  std::vector<std::string> notes;
  eval::PlotOptions o;
  o.render = false;
  eval::write_experiment_plots(r, circle_truth(frame), frame, dir.path(), false,
                               [&](const std::string& m) { notes.push_back(m); }, o);
  bool said = false;
  for (const auto& n : notes) said = said || n.find("curves are drawn every 10 m") != std::string::npos;
  EXPECT_TRUE(said);
  const auto single = lines_of(dir / "plots/data/drift_single.csv");
  ASSERT_GT(single.size(), 20u);  // every 10 m up to 250 m, not two points
  EXPECT_DOUBLE_EQ(std::stod(split(single[1])[0]), 10.0);
  // The per-epoch errors grow as 1 % of the distance for error scale 1 (left C1).
  const auto row = split(single[10]);
  EXPECT_DOUBLE_EQ(std::stod(row[0]), 100.0);
  EXPECT_NEAR(std::stod(row[1]), 1.0, 0.05);
  EXPECT_NE(read_all(dir / "plots/fig10_drift_rate.gp").find("a short drive"), std::string::npos);
}

// Two reports drawing the same figures into one directory at once (issue 33, item 17): each
// gnuplot writes its own temporary, so neither finds its image gone nor warns "exit 0".
TEST(EvalPlots, TwoRendersIntoOneDirectoryAtOnceShareNoTemporary) {
  if (!gnuplot_available()) GTEST_SKIP() << "gnuplot is not installed (apt-get install gnuplot-nox)";
  ScratchDir dir;
  eval::PlotOptions o;
  o.render = false;
  write(dir, false, o);
  const std::vector<std::string> names = {"trajectory", "fig7_dual_wheel", "fig8_body_wheel", "fig9_triple",
                                          "fig10_drift_rate"};
  for (int round = 0; round < 3; ++round) {
    std::vector<std::string> warnings[2];
    std::vector<fs::path> drawn[2];
    std::vector<std::thread> both;
    for (int k = 0; k < 2; ++k)
      both.emplace_back([&, k] {
        drawn[k] = eval::render_gnuplot(dir / "plots", names, [&, k](const std::string& m) {
          warnings[k].push_back(m);
        });
      });
    for (auto& t : both) t.join();
    for (int k = 0; k < 2; ++k) {
      EXPECT_TRUE(warnings[k].empty()) << warnings[k].front();
      EXPECT_EQ(drawn[k].size(), names.size());
    }
  }
  for (const auto& n : names) {
    const fs::path png = dir / "plots" / (n + ".png");
    ASSERT_TRUE(fs::exists(png)) << png;
    EXPECT_EQ(read_all(png).substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << png;
    EXPECT_FALSE(iotest::partial_left(png));
  }
}

TEST(EvalPlots, FigureRunsArePaperChipsOrTheClosestCombination) {
  auto manifest = [](int chips) {
    Manifest m;
    const std::pair<const char*, double> groups[] = {{"left", -0.2}, {"right", 0.2}, {"body", 0.0}};
    for (const auto& [g, y] : groups)
      for (int c = 1; c <= chips; ++c) {
        ModuleSpec s;
        s.name = std::string(g) + "-C" + std::to_string(c);
        s.chip = "C" + std::to_string(c);
        s.kind = std::string(g) == "body" ? ModuleKind::kBody : ModuleKind::kWheel;
        s.p_inV = Vec3(0.0, y, 0.0);
        m.modules.push_back(s);
      }
    return m;
  };
  auto figures = [](const std::vector<eval::ExperimentRun>& plan) {
    std::vector<std::string> v;
    for (const auto& r : plan)
      if (r.figure && r.configuration != "single") v.push_back(r.configuration + " " + r.label);
    return v;
  };
  // The paper's DW 14, BW 22 and TW 124 (body chip C(((i + j) mod 4) + 1)); with two chips
  // per module the closest: DW 11 and TW 122 (left C1, right C2, body C2).
  EXPECT_EQ(figures(eval::experiment_plan(manifest(4), {})),
            (std::vector<std::string>{"dual-wheel 14", "body-wheel 22", "triple 124"}));
  EXPECT_EQ(figures(eval::experiment_plan(manifest(2), {})),
            (std::vector<std::string>{"dual-wheel 11", "body-wheel 22", "triple 122"}));
  for (const auto& r : eval::experiment_plan(manifest(2), {})) {
    if (r.configuration == "single") {
      EXPECT_TRUE(r.figure);
    } else if (r.centralized) {
      EXPECT_FALSE(r.figure);
    }
  }
}

}  // namespace
}  // namespace wheelins
