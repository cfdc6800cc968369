// `wheelins experiment`: every configuration and chip combination of the paper's
// Section VI on one dataset; Tables 4-8 to the terminal, CSV/JSON/Markdown to files,
// and the plots of Fig. 7-10 (data + gnuplot scripts, PNGs when gnuplot is installed).
// It is a built-in study (docs/studies.md): OUT/study.yaml declares the runs and each run is
// a job whose result lands in OUT/jobs/; --prepare writes only the study, so that a large
// experiment shards (and resumes) like any study: `wheelins study run OUT/study.yaml`.
#include <iostream>
#include <sstream>

#include "cli.hpp"
#include "wheelins/io/output_dir.hpp"
#include "wheelins/run/run_config.hpp"
#include "wheelins/study/files.hpp"
#include "wheelins/study/job.hpp"
#include "wheelins/study/report.hpp"
#include "wheelins/study/spec.hpp"

namespace {
using namespace wheelins;
namespace fs = std::filesystem;

struct Args {
  std::string dataset;
  std::string out;
  std::string speed = "own";
  std::string only;
  std::string calibration = "estimate";
  int jobs = 2;
  double duration = 0.0;
  bool force = false;
  bool quiet = false;
  bool no_plots = false;
  bool prepare = false;
};

// The experiment as a study spec; the options checked first.
study::ExperimentSpec experiment_spec(const Args& a, const fs::path& manifest) {
  if (!(a.duration >= 0.0 && a.duration <= 1e7))
    throw InputError("--duration " + std::to_string(a.duration) + ": must be in (0, 1e7] s (0: all the data)");
  speed_sharing_from_name(a.speed);  // checks the name

  study::ExperimentSpec spec;
  spec.dataset = fs::absolute(manifest).lexically_normal();
  spec.speed = a.speed;
  spec.duration = a.duration;
  calibration_mode_from_name(a.calibration);  // checks the name
  spec.calibration = a.calibration;
  std::stringstream ss(a.only);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) spec.only.push_back(item);
  study::check_experiment_only(spec.only, "--only");
  return spec;
}

// --prepare. Only the study file: its jobs run with `wheelins study run` (sharded, resumable) and
// `wheelins study report` writes the tables into the same directory.
int prepare_study(const fs::path& final_out, const std::string& text, bool force) {
  const fs::path study_file = final_out / "study.yaml";
  if (fs::exists(final_out / kOutputMarker))
    throw InputError("'" + final_out.string() + "': holds the finished output of `wheelins experiment`; "
                     "prepare the study in another directory");
  std::string existing;
  if (study::read_file(study_file, existing)) {
    if (existing != text && !force)
      throw InputError("'" + study_file.string() + "': holds the study of another experiment (other dataset "
                       "or options); use --force to replace it, or choose another --out");
  } else if (fs::exists(final_out) && !fs::is_empty(final_out)) {
    throw InputError("'" + final_out.string() + "': is not empty; --prepare writes a study into an empty or new "
                     "directory");
  }
  fs::create_directories(final_out);
  if (existing != text) write_file_atomic(study_file, text, study::shared_file(study_file));
  const study::Study s = study::Study::load(study_file);
  std::cout << "wrote " << study_file.string() << ": " << s.job_count() << " runs (jobs 0.." << s.job_count() - 1
            << "); run them with `wheelins study run " << study_file.string()
            << "` (all cores, resumable), scripts/study-parallel.sh or scripts/study.sbatch, then: "
               "wheelins study report "
            << study_file.string() << "\n";
  return 0;
}

// Every job of the study; a failed one stops the command.
void run_all_jobs(const study::Study& s, const Args& a) {
  study::RunOptions ro;
  ro.workers = a.jobs;
  ro.progress = !a.quiet;
  ro.job.warn = stderr_sink();
  const study::RunSummary sum = study::run_jobs(s, {}, ro);
  if (sum.failed) {
    for (const auto& [k, e] : sum.failures) std::cerr << "error: run " << k << " failed: " << e << "\n";
    throw InputError(std::to_string(sum.failed) + " of " + std::to_string(sum.requested) +
                     " runs failed; nothing was written");
  }
}

void print_fault_events(const study::Report& r) {
  std::size_t events = 0, runs_with = 0;
  for (const auto& e : r.jobs)
    if (e.record) {
      events += e.record->fault_events;
      runs_with += e.record->fault_events > 0;
    }
  std::cout << "fault handling: " << events << " fault events in " << runs_with << " of " << r.done
            << " runs (runs.csv, column fault_events)\n";
}

// The report's files as they are named after the commit, in `final_out`; plot data counted.
void print_written(const study::Report& r, const study::Study& s, const fs::path& final_out) {
  auto shown = [&](const fs::path& f) { return (final_out / f.lexically_relative(s.results_dir())).string(); };
  std::size_t data_files = 0;
  for (const auto& f : r.files) {
    if (f.parent_path().filename() == "data") ++data_files;
    else std::cout << "wrote " << shown(f) << "\n";
  }
  if (data_files > 0)
    std::cout << "wrote " << data_files << " plot data files (CSV) in " << (final_out / "plots" / "data").string()
              << "\n";
}

int run(const Args& a) {
  fs::path manifest = a.dataset;
  if (fs::is_directory(manifest)) manifest /= "manifest.yaml";
  const fs::path final_out = a.out.empty() ? manifest.parent_path() / "experiment" : fs::path(a.out);
  const std::string text = study::experiment_study_yaml(experiment_spec(a, manifest));
  if (a.prepare) return prepare_study(final_out, text, a.force);

  // Checked, locked and staged before the runs: a refusal or an unwritable place costs
  // nothing, and the study, its jobs' results, the tables and the plots appear together at
  // the end (io/output_dir.hpp).
  OutputDirOptions out_opt;
  out_opt.overwrite = a.force;
  out_opt.kind = "experiment";
  out_opt.inputs.push_back(manifest);
  out_opt.notice = stderr_sink();
  OutputDir out_dir(final_out, out_opt);
  const fs::path out = out_dir.staging();
  write_file_atomic(out / "study.yaml", text, study::shared_file(out / "study.yaml"));
  const study::Study s = study::Study::load(out / "study.yaml");
  run_all_jobs(s, a);

  study::ReportOptions rep;
  rep.plots = !a.no_plots;
  rep.warn = stderr_sink();
  const study::Report r = study::write_report(s, rep);
  out_dir.commit();
  std::cout << r.markdown;
  print_fault_events(r);
  print_written(r, s, final_out);
  return 0;
}

const bool registered = cli::register_command(
    40, "experiment", "Run the paper's experiment (Tables 4-8) on a dataset", [](CLI::App& sub) {
      auto a = std::make_shared<Args>();
      sub.add_option("dataset", a->dataset,
                     "Dataset directory (with manifest.yaml) or manifest file")
          ->required();
      sub.add_option("--out,-o", a->out, "Output directory (default: DATASET/experiment)");
      sub.add_option("--jobs,-j", a->jobs, "Runs in parallel (default 2)")
          ->check(CLI::Range(1, 64));
      sub.add_option("--speed", a->speed, "Wheel speed sharing: own (default) | mean (paper)");
      sub.add_option("--only", a->only,
                     "Subset: single,dual-wheel,body-wheel,triple,centralized (comma list)");
      sub.add_option("--duration", a->duration, "Seconds of navigation per run (default: all)");
      sub.add_option("--calibration", a->calibration,
                     "installation geometry: estimate (default: from the data) | manifest (as given)");
      sub.add_flag("--force,-f", a->force, "Overwrite existing results");
      sub.add_flag("--quiet,-q", a->quiet, "No progress line");
      sub.add_flag("--no-plots", a->no_plots,
                   "Skip the plots (OUT/plots: data, gnuplot scripts, PNGs)");
      sub.add_flag(
          "--prepare", a->prepare,
          "Only write OUT/study.yaml (the experiment as a study) to shard its runs over processes "
          "or machines (docs/studies.md); `wheelins study report OUT/study.yaml` then writes the "
          "tables");
      return [a]() { return run(*a); };
    });
}  // namespace
