// `wheelins manifest DIR`: drafts a manifest for a directory of Wheel-INS-style
// recordings and lists the geometry the user must still measure.
#include <filesystem>
#include <iostream>
#include <string>

#include "cli.hpp"
#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/manifest_draft.hpp"

namespace {

struct Options {
  std::string dir;
  std::string out;
  bool force = false;
};

int run(const Options& o) {
  using namespace wheelins;
  namespace fs = std::filesystem;
  const fs::path out = o.out.empty() ? fs::path(o.dir) / "manifest.yaml" : fs::path(o.out);
  check_output_target(out, o.force);
  const ManifestDraft d = draft_manifest(o.dir, out);
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
      sub.add_flag("--force", o->force, "overwrite an existing manifest");
      return [o]() { return run(*o); };
    });

}  // namespace
