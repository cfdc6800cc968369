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

int run(const Options& o) {
  using namespace wheelins;
  namespace fs = std::filesystem;
  const fs::path out = o.out.empty() ? fs::path(o.dir) / "manifest.yaml" : fs::path(o.out);
  const OutputFile target{out, o.out.empty() ? "the manifest (DIR/manifest.yaml)" : "-o"};
  check_output_files({target}, {}, o.force);
  ManifestDraft d = draft_manifest(o.dir, out);
  // Several IMU files side by side (the flat layout): what each module is, its axle, clock
  // and mounting come from the data (survey/draft.hpp), not from the single-Wheel-IMU robot
  // the layout was made for.
  if (d.layout == "single-IMU" && (d.manifest.modules.size() > 1 || !o.vehicle_type.empty())) {
    survey::DraftOptions so;
    if (!o.vehicle_type.empty()) {
      so.vehicle = survey::vehicle_type(o.vehicle_type);
      so.vehicle_type_given = true;
    }
    so.name = d.manifest.name;
    so.source = "the IMU files of " + d.manifest.name;
    so.tool = "wheelins manifest";
    d = survey::draft_from_files(d, so);
  }
  // The recordings the draft names are its inputs: never replaced by it, --force or not.
  check_output_files({target}, named_files(d.manifest.input_files(), "the recording"), o.force);
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
