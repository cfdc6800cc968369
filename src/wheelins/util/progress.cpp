// The terminal progress line of progress.hpp.
#include "wheelins/util/progress.hpp"

#include "wheelins/util/interrupt.hpp"

#include <unistd.h>

#include <cstdio>

namespace wheelins {

Progress::Progress(std::string label, std::uint64_t total, bool enabled)
    : label_(std::move(label)),
      total_(total),
      enabled_(enabled && isatty(STDERR_FILENO)),
      start_(std::chrono::steady_clock::now()),
      last_(start_) {}

Progress::~Progress() { finish(); }

void Progress::update(std::uint64_t done) {
  check_interrupt();  // every long loop reports progress: it stops here on Ctrl-C / kill
  if (!enabled_ || finished_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_ < std::chrono::milliseconds(100)) return;
  last_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  if (total_ > 0) {
    const double frac = static_cast<double>(done) / static_cast<double>(total_);
    const double eta = frac > 0 ? elapsed * (1.0 - frac) / frac : 0.0;
    std::fprintf(stderr, "\r%s %5.1f%%  %6.1f s elapsed, ~%.0f s left   ", label_.c_str(),
                 100.0 * frac, elapsed, eta);
  } else {
    std::fprintf(stderr, "\r%s %llu  %6.1f s   ", label_.c_str(),
                 static_cast<unsigned long long>(done), elapsed);
  }
  std::fflush(stderr);
}

void Progress::finish() {
  if (!enabled_ || finished_) return;
  finished_ = true;
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::fprintf(stderr, "\r%s done in %.1f s%30s\n", label_.c_str(), elapsed, "");
}

}  // namespace wheelins
