// `wheelins experiment`: every configuration and chip combination of the paper's
// Section VI on one dataset; Tables 4-8 to the terminal, CSV/JSON/Markdown to files.
#include <iostream>
#include <sstream>

#include "cli.hpp"
#include "wheelins/eval/experiment.hpp"
#include "wheelins/fusion/run_config.hpp"
#include "wheelins/io/atomic_file.hpp"

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
};

void write_file(const fs::path& file, const std::string& text, bool overwrite) {
  AtomicTextFile f(file, overwrite);
  f.write(text);
  f.commit();
}

int run(const Args& a) {
  fs::path manifest = a.dataset;
  if (fs::is_directory(manifest)) manifest /= "manifest.yaml";
  const fs::path out = a.out.empty() ? manifest.parent_path() / "experiment" : fs::path(a.out);
  const std::vector<fs::path> files{out / "experiment.md", out / "runs.csv", out / "experiment.json"};
  for (const auto& f : files) check_output_target(f, a.force);

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
  std::cout << md;
  for (const auto& f : files) std::cout << "wrote " << f.string() << "\n";
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
      return [a]() { return run(*a); };
    });
}  // namespace
