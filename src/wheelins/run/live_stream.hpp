// The plain live stream (docs/live.md): text lines `module, t, gx, gy, gz, ax, ay, az` as
// they arrive (standard input, a pipe), put back into time order within a window, navigated
// by a PushSession, and the vehicle's state published as JSON lines or CSV rows.
//
// Bad input never stops the stream nor reaches the filter: a line that cannot be read, a
// value that is not finite, a module that is not navigated, a sample older than the window
// (late), a time that repeats or goes back for its module: each is counted, the first few of
// each kind are reported (the line number, the module, the value), and the stream goes on.
#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "wheelins/io/imu_file.hpp"
#include "wheelins/run/push_session.hpp"

namespace wheelins {

/// One line of the stream. `module` points into the line's text.
struct StreamLine {
  std::string_view module;
  ImuRow row;
};

/// A line's fields: false for a blank line or a comment (`#`); InputError naming the field
/// that is missing, extra or not a number. Fields are separated by commas (spaces around
/// them are allowed) or by white space alone.
bool parse_stream_line(std::string_view line, StreamLine& out);

/// Samples put back into time order: a sample is released once a sample `window` seconds
/// newer has arrived (or at the end), oldest first, ties in module order (as a file run
/// merges its files). A sample older than the last one released is late: refused.
class ReorderWindow {
 public:
  struct Item {
    double key = 0.0;  ///< the time the order is by (the record's t plus its module's offset)
    int module = 0;
    std::uint64_t seq = 0;
    std::uint64_t line = 0;
    ImuRow row;
  };
  /// `window` [s] >= 0 (0: released as they come, any sample older than the newest is late);
  /// `capacity`: room reserved up front (the buffer grows past it only in a burst).
  explicit ReorderWindow(double window, std::size_t capacity = 4096);
  /// False: late (older than the last sample released), not kept.
  bool offer(double key, int module, std::uint64_t line, const ImuRow& row);
  /// The oldest sample that is due (at least `window` older than the newest); false if none.
  bool pop_due(Item& out);
  /// The oldest sample, due or not (the end of the stream); false when empty.
  bool pop_any(Item& out);
  std::size_t size() const { return heap_.size(); }
  double window() const { return window_; }

 private:
  double window_;
  std::vector<Item> heap_;
  std::uint64_t seq_ = 0;
  double newest_ = 0.0, released_ = 0.0;
  bool any_ = false, any_released_ = false;
};

struct LiveStreamOptions {
  double window = 0.05;            ///< [s] the reorder window (ReorderWindow)
  double publish_interval = 0.1;   ///< [s] between published states (0: every record)
  bool csv = false;                ///< CSV rows (a header first) instead of JSON lines
  int reports_per_kind = 5;        ///< bad input: the first this many of each kind reported
  std::string source = "standard input";///< names the stream in messages
  std::string unit = "line";            ///< what the stream's records are called in messages
  /// Where the states go instead of the text output (the ROS node's odometry): called with
  /// the vehicle's state at each publication. Empty: JSON lines or CSV rows to `out`.
  std::function<void(const TrajectoryRecord&)> on_state;
};

/// What the stream saw, for the summary.
struct LiveStreamStats {
  std::uint64_t lines = 0;       ///< lines (or messages) read (comments and blank lines included)
  std::uint64_t samples = 0;     ///< samples passed to the navigation
  std::uint64_t bad_lines = 0;   ///< not readable, not finite, a module not navigated
  std::uint64_t late = 0;        ///< older than the reorder window
  std::uint64_t rejected = 0;    ///< refused by the input checks (time repeats or goes back)
  std::uint64_t published = 0;   ///< states written
  std::uint64_t unreported = 0;  ///< bad input past reports_per_kind, counted only
  /// [s] from a line's arrival to the end of what it caused (its samples navigated, a state
  /// published), for each line after which a state was published.
  std::vector<double> latency;
  std::uint64_t left_out() const { return bad_lines + late + rejected; }
};

/// The stream navigated by `session` (whose request's on_record LiveStream does not use:
/// the states are published from the navigator after each released sample).
class LiveStream {
 public:
  /// `out`: where the states go (flushed after each); `diag`: where reports go.
  LiveStream(PushSession& session, const LiveStreamOptions& options, std::FILE* out, std::FILE* diag);
  /// One line as it arrived (`number` from 1), `arrival` its steady-clock time [s]. False once
  /// the request's duration is reached (read no more).
  bool line(std::string_view text, double arrival);
  /// One sample of module `module` (its index in the request's modules) as it arrived, from
  /// a source that is not text (a ROS message; it was checked to be finite); reports name it
  /// as "SOURCE UNIT NUMBER" (LiveStreamOptions: "ROS topics message 12"). Otherwise as line().
  bool sample(int module, const ImuRow& row, double arrival);
  /// A record of a source that is not text that cannot be navigated (a value not finite, a
  /// wrong frame id): counted as unreadable and reported as line() reports a bad line.
  void refuse(const std::string& what);
  /// The module's index in the request's modules (or its index as a number); -1 if none.
  int module_index(std::string_view name) const;
  const std::vector<std::string>& modules() const { return names_; }
  /// The end of the stream: the window emptied into the navigation (the session is not
  /// finished here).
  void end();
  const LiveStreamStats& stats() const { return stats_; }

 private:
  enum Kind { kBadLine, kLate, kRejected, kKinds };
  void report(Kind kind, const std::string& message);
  bool navigate(const ReorderWindow::Item& item);
  void publish();
  bool offer(int module, const ImuRow& row, double arrival, std::uint64_t number);
  std::string where(std::uint64_t number) const;

  PushSession& session_;
  LiveStreamOptions options_;
  std::FILE* out_;
  std::FILE* diag_;
  ReorderWindow window_;
  std::vector<double> offsets_;   ///< each module's time offset [s]
  std::vector<std::string> names_;
  std::vector<double> values_;    ///< one state's values (trajectory_csv_header order)
  std::vector<std::string> header_;
  std::string text_;              ///< one state's line
  int reported_[kKinds] = {0, 0, 0};
  double next_publish_ = 0.0, grid_start_ = 0.0;
  std::uint64_t grid_steps_ = 0;
  bool published_any_ = false;
  bool said_waiting_ = false, said_warmup_ = false, stopped_ = false;
  LiveStreamStats stats_;
};

/// The latencies' median and 99th percentile [s] (0 when there are none).
void latency_percentiles(std::vector<double> latency, double& median, double& p99);

}  // namespace wheelins
