// The thin command-line layer: each app/cmd_*.cpp registers one subcommand.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace wheelins::cli {

/// Runs a parsed subcommand; returns the process exit code.
using Runner = std::function<int()>;
/// Declares a subcommand's options on `sub` and returns what runs it.
using Setup = std::function<Runner(CLI::App& sub)>;

/// "a,b,,c" -> {a, b, c}: a comma-separated list, empty items dropped.
std::vector<std::string> split_list(const std::string& text);

/// Called from a static object in each cmd_*.cpp; `order` sorts the --help listing.
bool register_command(int order, const std::string& name, const std::string& description,
                      Setup setup);

}  // namespace wheelins::cli
