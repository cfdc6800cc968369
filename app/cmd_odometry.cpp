// `wheelins odometry`: the naive dead reckoning a user compares against (wheel speed times
// radius, heading from a body gyro or the wheels' speed difference; run/odometry.hpp),
// written and evaluated like a run.
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "cli.hpp"
#include "run_report.hpp"
#include "wheelins/io/output_dir.hpp"
#include "wheelins/io/trajectory.hpp"
#include "wheelins/run/odometry.hpp"
#include "wheelins/run/presets.hpp"

namespace {
using namespace wheelins;
namespace fs = std::filesystem;

struct Options {
  std::string manifest, wheels, gyro, out;
  std::optional<double> align_start;
  std::string antenna;
  bool force = false;
};


int run(const Options& o) {
  const fs::path in = fs::is_directory(o.manifest) ? fs::path(o.manifest) / "manifest.yaml" : fs::path(o.manifest);
  OdometryRequest req;
  req.manifest = load_manifest(in);
  const Manifest& m = req.manifest;
  // The rear pair (the dual-wheel configuration's wheels), else one wheel; the first body.
  req.wheels = cli::split_list(o.wheels);
  if (req.wheels.empty()) {
    try {
      req.wheels = configuration_modules(m, "dual-wheel", {});
    } catch (const InputError&) {
      req.wheels = configuration_modules(m, "single", {});
    }
  }
  if (o.gyro.empty()) {
    for (const auto& s : m.modules)
      if (s.kind == ModuleKind::kBody) {
        req.gyro = s.name;
        break;
      }
  } else if (o.gyro != "none") {
    req.gyro = o.gyro;
  }
  std::unique_ptr<OutputDir> dir;
  std::vector<std::unique_ptr<TrajectoryWriter>> writers;
  if (!o.out.empty()) {
    OutputDirOptions d;
    d.overwrite = o.force;
    d.inputs.push_back(in);
    d.notice = stderr_sink();
    dir = std::make_unique<OutputDir>(o.out, d);
    writers.push_back(make_trajectory_writer(TrajectoryFormat::kCsv, dir->staging() / "trajectory.csv"));
    TrajectoryWriterOptions tum;
    tum.origin = m.origin;
    writers.push_back(make_trajectory_writer(TrajectoryFormat::kTum, dir->staging() / "trajectory.tum", tum));
  }
  std::unique_ptr<eval::RunEvaluation> evaluation;
  if (m.truth_file)
    evaluation = std::make_unique<eval::RunEvaluation>(m.resolve(*m.truth_file), m.origin,
                                                       run_evaluation_options(m, RunEvaluationRequest{o.align_start, o.antenna, false, ""}));
  req.on_record = [&](const TrajectoryRecord& r) {
    for (auto& w : writers) w->write(r);
    if (evaluation) evaluation->add(r);
  };
  std::cout << "wheelins odometry: speed of [";
  for (std::size_t i = 0; i < req.wheels.size(); ++i) std::cout << (i ? ", " : "") << req.wheels[i];
  std::cout << "], heading from " << (req.gyro.empty() ? "their speed difference" : "the gyro of " + req.gyro)
            << " on '" << m.path.string() << "'\n";
  const OdometryResult res = run_wheel_odometry(req);
  std::printf("dead-reckoned %.1f s, %.1f m (%zu records)\n", res.t_end - res.t_start, res.distance, res.records);
  if (dir) {
    for (auto& w : writers) w->commit();
    dir->commit();
    std::cout << "wrote " << dir->final_path("trajectory.csv").string() << "\nwrote "
              << dir->final_path("trajectory.tum").string() << "\n";
  }
  if (evaluation) print_evaluation(evaluation->finish(), m.resolve(*m.truth_file).string(), res.t_start, res.t_end, false);
  return 0;
}

const bool registered = cli::register_command(
    22, "odometry",
    "The naive dead reckoning to compare with: wheel speed x radius, heading from a body gyro (no filter)",
    [](CLI::App& sub) {
      auto o = std::make_shared<Options>();
      sub.add_option("-m,--manifest", o->manifest, "dataset directory (with manifest.yaml) or manifest file")->required();
      sub.add_option("--wheels", o->wheels, "wheel modules whose speeds are averaged (default: the rear pair, else one)");
      sub.add_option("--gyro", o->gyro, "body module for the heading (default: the first body; none: the wheels' "
                                        "speed difference)");
      sub.add_option("--out,-o", o->out, "output directory (trajectory.csv, trajectory.tum); default: none");
      sub.add_option("--antenna", o->antenna, "evaluation: the truth's antenna X,Y,Z in the vehicle frame [m]");
      sub.add_option("--align-start", o->align_start,
                     "evaluation: align the first METRES of travel onto the truth (default as `run`)");
      sub.add_flag("--force,-f", o->force, "overwrite an earlier output directory");
      return [o]() { return run(*o); };
    });
}  // namespace
