// Interruption (Ctrl-C, kill): a signal handler only raises a flag; long loops call
// check_interrupt() at their block boundaries, which throws Interrupted, so the
// destructors remove every unfinished output (nothing half-written is left behind).
#pragma once

#include <stdexcept>

namespace wheelins {

struct Interrupted : std::runtime_error {
  Interrupted() : std::runtime_error("interrupted; nothing was written") {}
};

/// Raises the flag; async-signal-safe (for a signal handler).
void request_interrupt() noexcept;
/// Clears it (tests).
void clear_interrupt() noexcept;
bool interrupt_requested() noexcept;
/// Throws Interrupted when the flag is raised.
void check_interrupt();

}  // namespace wheelins
