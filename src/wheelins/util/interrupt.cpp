// The interrupt flag of interrupt.hpp.
#include "wheelins/util/interrupt.hpp"

#include <atomic>
#include <csignal>

namespace wheelins {
namespace {
volatile std::sig_atomic_t g_interrupt = 0;
}  // namespace

void request_interrupt() noexcept { g_interrupt = 1; }
void clear_interrupt() noexcept { g_interrupt = 0; }
bool interrupt_requested() noexcept { return g_interrupt != 0; }
void check_interrupt() {
  if (g_interrupt) throw Interrupted();
}

}  // namespace wheelins
