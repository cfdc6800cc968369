// `wheelins experiment`: every configuration and chip combination of the paper's
// Section VI on one dataset; Tables 4-8 to the terminal, CSV/JSON/Markdown to files,
// and the plots of Fig. 7-10 (data + gnuplot scripts, PNGs when gnuplot is installed).
#include <iostream>
#include <sstream>

#include "cli.hpp"
#include "wheelins/run/experiment.hpp"
#include "wheelins/run/plots.hpp"
#include "wheelins/run/run_config.hpp"
#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/output_dir.hpp"
#include "wheelins/io/truth.hpp"

namespace {
using namespace wheelins;
namespace fs = std::filesystem;

struct Args {
  std::string dataset;
  std::string out;
  std::string speed = "mean";
  std::string only;
  int jobs = 2;
  double duration = 0.0;
  bool force = false;
  bool quiet = false;
  bool no_plots = false;
};

void write_file(const fs::path& file, const std::string& text, bool overwrite) {
  AtomicTextFile f(file, overwrite);
  f.write(text);
  f.commit();
}

int run(const Args& a) {
  fs::path manifest = a.dataset;
  if (fs::is_directory(manifest)) manifest /= "manifest.yaml";
  const fs::path final_out = a.out.empty() ? manifest.parent_path() / "experiment" : fs::path(a.out);
  if (!(a.duration >= 0.0 && a.duration <= 1e7))
    throw InputError("--duration " + std::to_string(a.duration) + ": must be in (0, 1e7] s (0: all the data)");
  // Checked, locked and staged before the runs: a refusal or an unwritable place costs
  // nothing, and the tables and plots appear together at the end (io/output_dir.hpp).
  OutputDirOptions out_opt;
  out_opt.overwrite = a.force;
  out_opt.kind = "experiment";
  out_opt.inputs.push_back(manifest);
  OutputDir out_dir(final_out, out_opt);
  const fs::path out = out_dir.staging();
  const std::vector<fs::path> files{out / "experiment.md", out / "runs.csv", out / "experiment.json"};

  eval::ExperimentOptions o;
  o.nav.fusion.speed = speed_sharing_from_name(a.speed);
  o.jobs = a.jobs;
  o.duration = a.duration;
  o.progress = !a.quiet;
  o.warn = stderr_sink();
  std::stringstream ss(a.only);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) o.only.push_back(item);

  const eval::ExperimentResult r = eval::run_experiment(manifest, o);
  const std::string md = eval::experiment_markdown(r);
  fs::create_directories(out);
  write_file(files[0], md, a.force);
  write_file(files[1], eval::experiment_csv(r), a.force);
  write_file(files[2], eval::experiment_json(r), a.force);
  std::vector<fs::path> plots;
  if (!a.no_plots) {
    const TruthData truth = read_truth(r.truth_file);
    plots = eval::write_experiment_plots(r, truth, earth::LocalFrame(r.origin), out, a.force, o.warn);
  }
  out_dir.commit();
  std::cout << md;
  std::size_t events = 0, runs_with = 0;
  for (const auto& x : r.runs) {
    events += x.fault_events;
    runs_with += x.fault_events > 0;
  }
  std::cout << "fault handling: " << events << " fault events in " << runs_with << " of "
            << r.runs.size() << " runs (runs.csv, column fault_events)\n";
  auto shown = [&](const fs::path& f) { return (final_out / f.lexically_relative(out)).string(); };
  for (const auto& f : files) std::cout << "wrote " << shown(f) << "\n";
  std::size_t data_files = 0;
  for (const auto& f : plots) {
    if (f.parent_path().filename() == "data") ++data_files;
    else std::cout << "wrote " << shown(f) << "\n";
  }
  if (data_files > 0)
    std::cout << "wrote " << data_files << " plot data files (CSV) in " << (final_out / "plots" / "data").string()
              << "\n";
  return 0;
}

const bool registered = cli::register_command(
    40, "experiment", "Run the paper's experiment (Tables 4-8) on a dataset", [](CLI::App& sub) {
      auto a = std::make_shared<Args>();
      sub.add_option("dataset", a->dataset, "Dataset directory (with manifest.yaml) or manifest file")
          ->required();
      sub.add_option("--out,-o", a->out, "Output directory (default: DATASET/experiment)");
      sub.add_option("--jobs,-j", a->jobs, "Runs in parallel (default 2)")->check(CLI::Range(1, 64));
      sub.add_option("--speed", a->speed, "Wheel speed sharing: mean (paper) | own");
      sub.add_option("--only", a->only,
                     "Subset: single,dual-wheel,body-wheel,triple,centralized (comma list)");
      sub.add_option("--duration", a->duration, "Seconds of navigation per run (default: all)");
      sub.add_flag("--force,-f", a->force, "Overwrite existing results");
      sub.add_flag("--quiet,-q", a->quiet, "No progress line");
      sub.add_flag("--no-plots", a->no_plots, "Skip the plots (OUT/plots: data, gnuplot scripts, PNGs)");
      return [a]() { return run(*a); };
    });
}  // namespace
