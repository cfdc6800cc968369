// How library code reports things that are not errors (gaps in a data file, an
// unknown manifest key): through a sink the caller hands in. Library code never
// prints on its own; the CLI passes stderr_sink().
#pragma once

#include <functional>
#include <string>

namespace wheelins {

/// Receives one human-readable warning (no trailing newline, no "warning:" prefix).
using WarningSink = std::function<void(const std::string& message)>;

/// A sink that prints "warning: <message>" on stderr (what the CLI uses).
WarningSink stderr_sink();

}  // namespace wheelins
