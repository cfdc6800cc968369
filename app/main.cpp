// wheelins: multi-IMU wheeled-vehicle dead reckoning (Wheel-INS2).
#include <algorithm>
#include <csignal>
#include <iostream>
#include <map>
#include <vector>

#include "cli.hpp"
#include "wheelins/nav/types.hpp"
#include "wheelins/run/run_options.hpp"
#include "wheelins/util/interrupt.hpp"

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
void add_settings_option(CLI::App& sub, std::vector<std::string>& settings) {
  sub.add_option("--set", settings,
                 "KEY=VALUE: any setting of the run configuration (docs/run-config.md, e.g. "
                 "fusion.position_std_m=0.3; VALUE is YAML), over the file; repeat it for more")
      ->allow_extra_args(false);
}

void add_run_setting_options(CLI::App& sub, std::vector<NamedSetting>& named) {
  for (const NamedOption& o : run_named_options()) {
    if (o.sets.empty())
      sub.add_option_function<std::string>(
          o.names, [&named, &o](const std::string& v) { named.push_back(cli_setting(o, v)); }, o.help);
    else
      sub.add_flag_callback(o.names, [&named, &o] { named.push_back(cli_setting(o)); }, o.help);
  }
}

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t k = text.find(',', start);
    std::string item = text.substr(start, k == std::string::npos ? std::string::npos : k - start);
    if (!item.empty()) out.push_back(std::move(item));
    if (k == std::string::npos) break;
    start = k + 1;
  }
  return out;
}

/// The first option of the command line (of `app` and the subcommands parsed) given an
/// empty value, e.g. `-o ''` or `--job $K` with K unset: its name, or "" if none. An empty
/// value is an error, never taken as "not given" (which would pick a default directory or
/// every job).
std::string option_with_empty_value(const CLI::App& app) {
  for (const CLI::Option* opt : app.get_options()) {
    if (opt->get_type_size() == 0 || opt->count() == 0) continue;  // a flag, or not given
    for (const std::string& v : opt->results())
      if (v.empty()) return opt->get_name();
  }
  for (const CLI::App* sub : app.get_subcommands())
    if (const std::string name = option_with_empty_value(*sub); !name.empty()) return name;
  return "";
}

}  // namespace wheelins::cli

namespace {
extern "C" void on_signal(int sig) {
  // First signal: ask the work to stop at its next block (outputs are removed, nothing
  // half-written stays); a second one ends the process at once.
  if (wheelins::interrupt_requested()) {
    std::signal(sig, SIG_DFL);
    std::raise(sig);
  }
  wheelins::request_interrupt();
}
}  // namespace

int main(int argc, char** argv) {
  using namespace wheelins::cli;
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) std::signal(sig, on_signal);
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

  // An unknown command is an error, also with --help (which CLI11 would answer with the
  // main help and exit 0).
  if (argc > 1 && argv[1][0] != '-') {
    bool known = false;
    for (const auto& e : entries) known = known || e.name == argv[1];
    if (!known) {
      std::string list;
      for (const auto& e : entries) list += (list.empty() ? "" : ", ") + e.name;
      std::cerr << "error: unknown command '" << argv[1] << "' (commands: " << list
                << "; wheelins --help lists them)\n";
      return 2;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  if (const std::string name = option_with_empty_value(app); !name.empty()) {
    std::cerr << "error: " << name << ": an empty value (an unset variable?); give a value or leave the option out\n";
    return 2;
  }
  for (auto& [sub, run] : runners) {
    if (!sub->parsed()) continue;
    try {
      return run();
    } catch (const wheelins::Interrupted& e) {
      std::cerr << "error: " << e.what() << "\n";
      return 130;
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
