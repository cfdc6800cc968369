// `wheelins manifest DIR`: drafts a manifest for a directory of Wheel-INS-style
// recordings and lists the geometry the user must still measure.
#include <filesystem>
#include <iostream>
#include <string>

#include "cli.hpp"
#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/manifest_draft.hpp"
#include "wheelins/survey/draft.hpp"

namespace {

struct Options {
  std::string dir;
  std::string out;
  std::string vehicle_type;
  bool force = false;
};

/// Several IMU files side by side (the flat layout): what each module is, its axle, clock and
/// mounting come from the data (survey/draft.hpp), not from the single-Wheel-IMU robot the
/// layout was made for; the truth, odometer and start of the first draft are kept.
wheelins::ManifestDraft survey_draft(const wheelins::ManifestDraft& first, const std::string& vehicle_type) {
  using namespace wheelins;
  std::vector<survey::ModuleInput> in;
  std::vector<survey::DraftModule> mods;
  for (const ModuleSpec& s : first.manifest.modules) {
    survey::ModuleInput x;
    x.name = s.name;
    x.file = first.manifest.resolve(s.file);
    x.read = imu_read_options(s);
    x.read.pass_nonfinite = true;
    in.push_back(x);
    survey::DraftModule d;
    d.name = s.name;
    d.file = s.file;
    d.layout = s.layout;
    d.rate_hz = s.rate_hz;
    mods.push_back(d);
  }
  const survey::DatasetSurvey sv = survey::survey_modules(in);
  survey::DraftOptions o;
  if (!vehicle_type.empty()) {
    o.vehicle = survey::vehicle_type(vehicle_type);
    o.vehicle_type_given = true;
  }
  o.name = first.manifest.name;
  o.source = "the IMU files of " + first.manifest.name;
  if (first.manifest.truth_file) {
    o.truth_file = *first.manifest.truth_file;
    o.origin = first.manifest.origin;
  }
  ManifestDraft d = survey::draft_from_survey(sv, mods, o);
  d.manifest.path = first.manifest.path;
  d.manifest.odometer_file = first.manifest.odometer_file;
  if (first.manifest.heading_known && first.manifest.truth_file) {
    d.manifest.initial_heading = first.manifest.initial_heading;
    d.manifest.heading_known = true;
    d.notes.comments["initial.heading_deg"] = "from the truth at the start";
  }
  d.layout = first.layout;
  d.facts.insert(d.facts.begin(), first.facts.front());
  d.facts.push_back("what the data say:\n" + survey::survey_report(sv));
  return d;
}

int run(const Options& o) {
  using namespace wheelins;
  namespace fs = std::filesystem;
  const fs::path out = o.out.empty() ? fs::path(o.dir) / "manifest.yaml" : fs::path(o.out);
  check_output_target(out, o.force);
  ManifestDraft d = draft_manifest(o.dir, out);
  if (d.layout == "single-IMU" && (d.manifest.modules.size() > 1 || !o.vehicle_type.empty()))
    d = survey_draft(d, o.vehicle_type);
  save_manifest(d.manifest, out, d.notes);
  std::cout << "wrote " << out.string() << "\n";
  for (const auto& f : d.facts) std::cout << "  " << f << "\n";
  std::cout << "still to fill in (marked TODO in the file):\n";
  for (const auto& t : d.todo) std::cout << "  - " << t << "\n";
  if (!d.todo.empty())
    std::cerr << "warning: " << out.string() << ": " << d.todo.size()
              << " entries are placeholders (typical values, marked TODO), not measurements of "
              << "your vehicle; `wheelins run` navigates with them as they are, and the results "
              << "are only as good as they are\n";
  return 0;
}

const bool registered = wheelins::cli::register_command(
    15, "manifest", "Draft a manifest for a directory of Wheel-INS-style recordings",
    [](CLI::App& sub) {
      auto o = std::make_shared<Options>();
      sub.add_option("DIR", o->dir,
                     "directory with <name>_imu.bin + GINS.bin (single IMU); Wheel-IMU/, Body-IMU/, "
                     "'Ground Truth'/, Odometer/ (the public Wheel-INS layout); or body-imu/, "
                     "left-wheel-imu/, right-wheel-imu/ + ground_truth/ (multi-IMU)")
          ->required();
      sub.add_option("-o,--output", o->out, "manifest file to write (default: DIR/manifest.yaml)");
      sub.add_option("--vehicle-type", o->vehicle_type,
                     "car | robot: with several IMU files side by side, the modules are drafted from what "
                     "their data say and the typical values of this vehicle (default car)");
      sub.add_flag("--force", o->force, "overwrite an existing manifest");
      return [o]() { return run(*o); };
    });

}  // namespace
