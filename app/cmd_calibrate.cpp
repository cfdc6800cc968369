// `wheelins calibrate`: refines a manifest's installation geometry (each Wheel-IMU's axle
// direction, lever arm and relative radius, each Body-IMU's mounting) from a
// recording, and writes the refined manifest and the estimates with their 1 sigma
// (docs/filter.md section 15).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "cli.hpp"
#include "wheelins/io/atomic_file.hpp"
#include "wheelins/run/calibration.hpp"
#include "wheelins/run/reference_calibration.hpp"

namespace {
using namespace wheelins;
namespace fs = std::filesystem;

struct Options {
  std::string manifest;
  std::string modules;
  std::string out;
  std::string report;
  std::optional<double> duration;
  bool no_faults = false;
  bool reference = false;
  std::optional<double> align_length, min_speed;
  bool force = false;
  bool quiet = false;
};


int run(const Options& o) {
  if (o.duration && (!std::isfinite(*o.duration) || *o.duration <= 0.0))
    throw InputError("--duration " + std::to_string(*o.duration) + ": must be a positive number of seconds");
  const fs::path in = fs::path(o.manifest).filename().empty() || fs::is_directory(o.manifest)
                          ? fs::path(o.manifest) / "manifest.yaml"
                          : fs::path(o.manifest);
  const fs::path out(o.out);
  const fs::path report = o.report.empty() ? fs::path(out).replace_extension(".calibration.yaml")
                                           : fs::path(o.report);
  // No input (the manifest, its recordings and truth) is ever overwritten, --force or not.
  check_output_files({{out, "--out"}, {report, o.report.empty() ? "the report (--out with .calibration.yaml)" : "--report"}},
                     {{in, "the input manifest"}}, o.force);
  const Manifest m = load_manifest(in);
  check_output_files({{out, "--out"}, {report, "--report"}}, named_files(m.input_files(), "a data file of the manifest"),
                     o.force);
  std::vector<std::string> modules = cli::split_list(o.modules);
  if (modules.empty()) {
    for (const auto& s : m.modules) modules.push_back(s.name);
  } else {
    for (const auto& name : modules)
      if (!m.find(name)) throw InputError("--modules: '" + in.string() + "' has no module '" + name + "'");
  }

  const double t_end = o.duration ? m.static_end + *o.duration : std::numeric_limits<double>::infinity();
  const auto cal = calibrate_installation(m, modules, InstallationCalibrationOptions{}, !o.no_faults,
                                          !o.quiet, t_end);
  std::cout << calibration_report(cal);
  std::optional<ReferenceCalibration> ref;
  if (o.reference) {
    ReferenceCalibrationOptions ro;
    ro.progress = !o.quiet;
    if (o.align_length) ro.align_length = *o.align_length;
    if (o.min_speed) {
      if (!(*o.min_speed >= 0.1 && *o.min_speed <= 50.0))
        throw InputError("--min-speed " + std::to_string(*o.min_speed) + ": must be in [0.1, 50] m/s");
      ro.min_speed = *o.min_speed;
    }
    ref = calibrate_against_reference(m, modules, cal, ro, stderr_sink());
    std::cout << reference_calibration_report(*ref);
  }
  // What was estimated, what was kept and what is still a guess: one list for the table
  // above, calibration.yaml and the refined manifest's notes.
  std::size_t undetermined = 0;
  {
    std::vector<std::string> seen;
    for (const auto& d : calibration_decisions(cal))
      if (d.outcome != CalibrationOutcome::kEstimated && !d.without_effect &&
          std::find(seen.begin(), seen.end(), d.module) == seen.end())
        seen.push_back(d.module);
    undetermined = seen.size();
  }
  std::vector<std::string> measured;
  if (ref)
    for (const auto& w : ref->wheels)
      if (w.radius.observed) measured.push_back(w.module);
  ManifestAnnotations notes = calibration_notes(m, cal, read_manifest_notes(in), measured);
  notes.header.push_back("refined by `wheelins calibrate` from " + in.string() + " (the estimates: " +
                         report.filename().string() + ")");
  // Both files written in full before either is moved into place.
  for (const fs::path& f : {out, report})
    if (f.has_parent_path()) fs::create_directories(f.parent_path());
  AtomicTextFile refined(out, o.force), estimates(report, o.force);
  Manifest refined_manifest = apply_calibration(m, cal);
  if (ref) refined_manifest = apply_reference_calibration(refined_manifest, *ref);
  refined.write(manifest_to_yaml(refined_manifest, out.has_parent_path() ? out.parent_path() : fs::path("."), notes));
  estimates.write(calibration_yaml(cal, m) + (ref ? reference_calibration_yaml(*ref, m) : std::string()));
  refined.commit();
  estimates.commit();
  std::cout << "wrote " << out.string() << "\nwrote " << report.string() << "\n";
  if (undetermined > 0)
    std::cerr << "warning: " << undetermined << " of " << cal.wheels.size() + cal.bodies.size()
              << " modules have parts the recording does not determine (weak or kept in '" << report.string()
              << "' and in the table above); a weak part is drawn towards the manifest's value, a kept one is it\n";
  return 0;
}

const bool registered = cli::register_command(
    28, "calibrate",
    "Refine a manifest's installation geometry (mountings, lever arms, radii) from its recording", [](CLI::App& sub) {
      auto o = std::make_shared<Options>();
      sub.add_option("-m,--manifest", o->manifest, "dataset directory (with manifest.yaml) or manifest file")
          ->required();
      sub.add_option("--out,-o", o->out, "refined manifest to write (never the input manifest)")->required();
      sub.add_option("--report", o->report,
                     "the estimates with 1 sigma (default: OUT with extension .calibration.yaml)");
      sub.add_option("--modules", o->modules, "modules to calibrate (default: all)");
      sub.add_option("--duration", o->duration, "seconds of the recording after the static period to use");
      sub.add_flag("--no-faults", o->no_faults, "no fault isolation of the input samples");
      sub.add_flag("--reference", o->reference,
                   "also estimate what only the manifest's truth (a GNSS track) shows: each wheel's "
                   "absolute rolling radius, the initial heading and the antenna's position");
      sub.add_option("--min-speed", o->min_speed,
                     "m/s: the reference epochs the radii are fitted on are faster (default 1.5; a slow robot "
                     "needs less)");
      sub.add_option("--align-length", o->align_length,
                     "metres of the reference's travel the initial heading is fitted on (default 300; 0: all)");
      sub.add_flag("--force,-f", o->force, "overwrite existing output files");
      sub.add_flag("--quiet,-q", o->quiet, "no progress line");
      return [o]() { return run(*o); };
    });

}  // namespace
