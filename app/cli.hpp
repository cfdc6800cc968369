// The thin command-line layer: each app/cmd_*.cpp registers one subcommand.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

#include "wheelins/run/run_config.hpp"

namespace wheelins::cli {

/// Runs a parsed subcommand; returns the process exit code.
using Runner = std::function<int()>;
/// Declares a subcommand's options on `sub` and returns what runs it.
using Setup = std::function<Runner(CLI::App& sub)>;

/// "a,b,,c" -> {a, b, c}: a comma-separated list, empty items dropped.
std::vector<std::string> split_list(const std::string& text);

/// `--set KEY=VALUE` (repeatable): any setting of the run configuration (docs/run-config.md),
/// into RunOverrides::settings.
void add_settings_option(CLI::App& sub, std::vector<std::string>& settings);

/// Every run setting that has a named option (run/run_options.hpp: its declaration's `cli`
/// text), each into `named` in the order given: `wheelins run`'s and `wheelins live`'s options.
void add_run_setting_options(CLI::App& sub, std::vector<NamedSetting>& named);

/// Called from a static object in each cmd_*.cpp; `order` sorts the --help listing.
bool register_command(int order, const std::string& name, const std::string& description,
                      Setup setup);

}  // namespace wheelins::cli
