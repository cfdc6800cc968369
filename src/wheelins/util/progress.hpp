// Progress on a terminal: a single updating line on stderr when stderr is a TTY,
// silent otherwise (logs and CI stay clean).
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

namespace wheelins {

class Progress {
 public:
  /// `total` is the amount of work (samples, bytes, runs); 0 if unknown.
  Progress(std::string label, std::uint64_t total, bool enabled = true);
  ~Progress();
  /// Reports that `done` units are complete; redraws at most ~10 times a second. Throws
  /// Interrupted when an interrupt was requested (util/interrupt.hpp).
  void update(std::uint64_t done);
  void finish();

 private:
  std::string label_;
  std::uint64_t total_;
  bool enabled_;
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace wheelins
