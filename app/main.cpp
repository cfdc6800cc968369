// wheelins: multi-IMU wheeled-vehicle dead reckoning (Wheel-INS2).
#include <algorithm>
#include <iostream>
#include <map>
#include <vector>

#include "cli.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins::cli {
namespace {
struct Entry {
  int order;
  std::string name;
  std::string description;
  Setup setup;
};
std::vector<Entry>& registry() {
  static std::vector<Entry> entries;
  return entries;
}
}  // namespace

bool register_command(int order, const std::string& name, const std::string& description,
                      Setup setup) {
  registry().push_back({order, name, description, std::move(setup)});
  return true;
}
}  // namespace wheelins::cli

int main(int argc, char** argv) {
  using namespace wheelins::cli;
  CLI::App app{"wheelins: dead reckoning for wheeled vehicles from wheel-mounted and body IMUs"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "wheelins 0.1.0");

  auto entries = registry();
  std::sort(entries.begin(), entries.end(),
            [](const auto& a, const auto& b) { return a.order < b.order; });
  std::map<CLI::App*, Runner> runners;
  for (auto& e : entries) {
    CLI::App* sub = app.add_subcommand(e.name, e.description);
    runners[sub] = e.setup(*sub);
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  for (auto& [sub, run] : runners) {
    if (!sub->parsed()) continue;
    try {
      return run();
    } catch (const wheelins::InputError& e) {
      std::cerr << "error: " << e.what() << "\n";
      return 2;
    } catch (const std::exception& e) {
      std::cerr << "error: " << e.what() << "\n";
      return 1;
    }
  }
  return 0;
}
