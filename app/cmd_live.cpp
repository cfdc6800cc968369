// `wheelins live`: navigate a stream of IMU records as they arrive (standard input or UDP
// datagrams on localhost) and publish the vehicle's state (run/live_stream.hpp; docs/live.md).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "cli.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/run/live_stream.hpp"
#include "wheelins/run/run_config.hpp"
#include "wheelins/util/interrupt.hpp"

namespace {
using namespace wheelins;

struct LiveArgs {
  std::string config_file, format = "json";
  double warmup = 120.0, window = 0.05, publish_interval = 0.1, idle_exit = 0.0;
  std::optional<int> udp_port;  // none: standard input
  std::vector<NamedSetting> named;    ///< the run settings' options (run/run_options.hpp), as given
  std::vector<std::string> settings;  ///< --set KEY=VALUE
};

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// Lines of a file descriptor as they arrive, read with read(2) and a poll of 0.1 s, so that a
/// signal is seen within that time whichever thread the kernel hands it to (the run's writer
/// runs on a thread of its own) and stdio's buffering does not hold lines back. On a datagram
/// socket each datagram holds whole lines (its end ends a line; an empty one is ignored) and
/// there is no end of input: `idle_exit` (> 0) seconds without input end it, for both.
class LineReader {
 public:
  enum Got { kLine, kNothing, kEnd };
  LineReader(int fd, std::string name, bool datagrams, double idle_exit)
      : fd_(fd), name_(std::move(name)), datagrams_(datagrams), idle_exit_(idle_exit), read_time_(now_seconds()) {
    buf_.reserve(1 << 17);
  }
  /// kLine: `line` (valid until the next call) and `arrival`, the steady-clock time of the read
  /// that completed it; kNothing: no whole line within 0.1 s; kEnd: the end of input.
  Got next(std::string_view& line, double& arrival) {
    for (;;) {
      const std::size_t nl = buf_.find('\n', start_);
      if (nl != std::string::npos || (eof_ && start_ < buf_.size())) {
        const std::size_t end = nl == std::string::npos ? buf_.size() : nl;
        line = std::string_view(buf_).substr(start_, end - start_);
        start_ = nl == std::string::npos ? buf_.size() : nl + 1;
        arrival = read_time_;
        return kLine;
      }
      if (eof_) return kEnd;
      buf_.erase(0, start_);
      start_ = 0;
      pollfd p{fd_, POLLIN, 0};
      const int ready = ::poll(&p, 1, 100);
      if (ready <= 0) {
        if (ready < 0 && errno != EINTR) throw InputError(name_ + ": " + std::strerror(errno));
        if (idle_exit_ > 0.0 && now_seconds() - read_time_ > idle_exit_) {
          std::fprintf(stderr, "wheelins live: no input on %s for %g s (--idle-exit): the run ends here\n",
                       name_.c_str(), idle_exit_);
          eof_ = true;
        }
        if (!eof_) return kNothing;
        continue;
      }
      const ssize_t n = ::read(fd_, chunk_.data(), chunk_.size());
      if (n < 0) {
        if (errno == EINTR || errno == EAGAIN) return kNothing;
        throw InputError(name_ + ": " + std::strerror(errno));
      }
      read_time_ = now_seconds();
      if (n == 0 && !datagrams_) eof_ = true;
      buf_.append(chunk_.data(), static_cast<std::size_t>(n));
      if (datagrams_ && n > 0 && buf_.back() != '\n') buf_ += '\n';
    }
  }

 private:
  int fd_;
  std::string name_;
  bool datagrams_;
  double idle_exit_;
  std::string buf_;
  std::vector<char> chunk_ = std::vector<char>(1 << 16);  // the largest UDP datagram whole
  std::size_t start_ = 0;
  double read_time_;
  bool eof_ = false;
};

/// A UDP socket bound to 127.0.0.1:`port` (localhost only: the stream carries no
/// authentication), its receive buffer as large as the system allows (up to 4 MiB) so that a
/// burst of datagrams waits for the navigation instead of being dropped.
class UdpSocket {
 public:
  explicit UdpSocket(int port) {
    if (port < 1 || port > 65535) throw InputError("--udp " + std::to_string(port) + ": a port in 1-65535");
    fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (fd_ < 0) throw InputError(std::string("--udp: socket: ") + std::strerror(errno));
    const int want = 4 << 20;
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &want, sizeof want);  // capped by the system: best effort
    sockaddr_in addr = {};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<std::uint16_t>(port));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
      const int e = errno;
      ::close(fd_);
      throw InputError("--udp " + std::to_string(port) + ": cannot listen on 127.0.0.1:" + std::to_string(port) +
                       ": " + std::strerror(e));
    }
  }
  UdpSocket(const UdpSocket&) = delete;
  UdpSocket& operator=(const UdpSocket&) = delete;
  ~UdpSocket() { ::close(fd_); }
  int fd() const { return fd_; }

 private:
  int fd_ = -1;
};

extern "C" void on_stop(int sig) {
  // The first Ctrl-C / kill ends the stream as the end of input does (the files are written);
  // a second one ends the process at once.
  if (interrupt_requested()) {
    std::signal(sig, SIG_DFL);
    std::raise(sig);
  }
  request_interrupt();
}

// The flag is seen by the reading loop within its poll's 0.1 s.
void catch_stop_signals() {
  struct sigaction sa = {};
  sa.sa_handler = on_stop;
  sigemptyset(&sa.sa_mask);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaction(sig, &sa, nullptr);
}

double cpu_seconds() {
  rusage u = {};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

RunRequest live_request(const LiveArgs& a, const WarningSink& warn) {
  const RunConfig cfg = run_config_with(RunOverrides{a.config_file, a.named, a.settings}, warn);
  RunRequest req = make_run_request(cfg, warn);
  if (cfg.output_dir.empty()) req.output_dir.clear();  // the states go out; files only when asked for
  return req;
}

void print_summary(const LiveStreamStats& st, const RunResult& res, double wall, double cpu) {
  double median = 0.0, p99 = 0.0;
  latency_percentiles(st.latency, median, p99);
  const double worst = st.latency.empty() ? 0.0 : *std::max_element(st.latency.begin(), st.latency.end());
  std::fprintf(stderr,
               "wheelins live: %llu lines, %llu samples navigated over %.1f s, %llu states published; "
               "left out: %llu unreadable or not navigated, %llu late, %llu refused by the input checks\n",
               static_cast<unsigned long long>(st.lines), static_cast<unsigned long long>(st.samples),
               res.stats.t_end - res.stats.t_start, static_cast<unsigned long long>(st.published),
               static_cast<unsigned long long>(st.bad_lines), static_cast<unsigned long long>(st.late),
               static_cast<unsigned long long>(st.rejected));
  std::fprintf(stderr,
               "latency from a line's arrival to the state published after it: median %.3f ms, 99th "
               "percentile %.3f ms, max %.1f ms (%zu states); CPU %.2f s in %.2f s wall (%.1f %% of one "
               "core)\n",
               1e3 * median, 1e3 * p99, 1e3 * worst, st.latency.size(), cpu, wall, wall > 0 ? 100.0 * cpu / wall : 0.0);
  if (!res.files.empty())
    std::fprintf(stderr, "wrote %zu files to %s\n", res.files.size(),
                 res.files.front().parent_path().string().c_str());
}

/// The start-up line (printed once the input is open: a UDP port is bound by then).
void print_start(const RunRequest& request, const std::string& from, bool udp, bool idle_exit) {
  std::string mods;
  for (const auto& m : request.modules) mods += (mods.empty() ? "" : ", ") + m;
  const char* ends = !udp ? "end of input or Ctrl-C ends the run"
                     : idle_exit ? "--idle-exit or Ctrl-C ends the run"
                                 : "Ctrl-C ends the run";
  std::fprintf(stderr, "wheelins live: %s on '%s'; reading `module, t, gx, gy, gz, ax, ay, az` lines from %s (%s)\n",
               mods.c_str(), request.manifest.path.string().c_str(), from.c_str(), ends);
}

int live(const LiveArgs& a) {
  if (a.format != "json" && a.format != "csv")
    throw InputError("--format '" + a.format + "': json (JSON lines) or csv");
  if (!(a.warmup > 0.0 && a.warmup <= 3600.0))
    throw InputError("--calibration-warmup " + io_detail::format_double(a.warmup) + ": must be in (0, 3600] s");
  if (!(a.idle_exit >= 0.0 && a.idle_exit <= 86400.0))
    throw InputError("--idle-exit " + io_detail::format_double(a.idle_exit) + ": must be in [0, 86400] s (0: never)");
  std::optional<UdpSocket> udp;
  if (a.udp_port) udp.emplace(*a.udp_port);
  const std::string source = udp ? "udp://127.0.0.1:" + std::to_string(*a.udp_port) : "standard input";
  const WarningSink warn = [](const std::string& w) { std::fprintf(stderr, "warning: %s\n", w.c_str()); };
  PushSession session(live_request(a, warn), a.warmup, source);
  LiveStreamOptions opt;
  opt.window = a.window;
  opt.publish_interval = a.publish_interval;
  opt.csv = a.format == "csv";
  LiveStream stream(session, opt, stdout, stderr);
  print_start(session.request(), udp ? "UDP datagrams on " + source.substr(6) : source, udp.has_value(),
              a.idle_exit > 0);

  catch_stop_signals();
  const double wall0 = now_seconds(), cpu0 = cpu_seconds();
  LineReader in(udp ? udp->fd() : STDIN_FILENO, source, udp.has_value(), a.idle_exit);
  std::string_view text;
  double arrival = 0.0;
  for (bool more = true; more && !interrupt_requested();) {
    const LineReader::Got got = in.next(text, arrival);
    if (got == LineReader::kEnd) break;
    if (got == LineReader::kLine) more = stream.line(text, arrival);
  }
  const bool stopped = interrupt_requested();
  clear_interrupt();
  if (stopped) std::fprintf(stderr, "wheelins live: stopped by a signal: the run ends here\n");
  stream.end();
  const RunResult res = session.finish();
  print_summary(stream.stats(), res, now_seconds() - wall0, cpu_seconds() - cpu0);
  if (stream.stats().left_out() > 0) {
    std::fprintf(stderr, "wheelins live: %llu input lines were left out (reported above): exit 3\n",
                 static_cast<unsigned long long>(stream.stats().left_out()));
    return 3;
  }
  return 0;
}

const bool registered = cli::register_command(
    25, "live", "Navigate IMU records as they arrive (standard input or UDP) and publish the state",
    [](CLI::App& sub) {
      auto a = std::make_shared<LiveArgs>();
      sub.add_option("config", a->config_file, "Run configuration (YAML; see docs/run-config.md)");
      cli::add_run_setting_options(sub, a->named);  // as `wheelins run` (docs/run-config.md)
      sub.add_option("--format", a->format, "The published states: json (JSON lines; default) or csv");
      sub.add_option("--publish-interval", a->publish_interval,
                     "Seconds of data between published states (default 0.1; 0: after every sample)");
      sub.add_option("--window", a->window,
                     "Reorder window [s]: records up to this much older than the newest are put back in "
                     "order; older ones are dropped (default 0.05)");
      sub.add_option("--calibration-warmup", a->warmup,
                     "Seconds of data the installation is estimated from (default 120); no state is "
                     "published before its end");
      sub.add_option("--udp", a->udp_port,
                     "Read the lines from UDP datagrams on 127.0.0.1:PORT instead of standard input (each "
                     "datagram whole lines)");
      sub.add_option("--idle-exit", a->idle_exit,
                     "End the run when no input arrived for this many seconds (default 0: never)");
      cli::add_settings_option(sub, a->settings);
      sub.footer("Files (the trajectory, calibration.yaml, ...) are written at the end only when --out or the "
                 "configuration's output.dir names a directory.");
      return [a]() { return live(*a); };
    });
}  // namespace
