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
#include <filesystem>
#include <memory>
#include <mutex>
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
#if WHEELINS_HAVE_ROS_LIVE
#include <dlfcn.h>

#include <cctype>
#include <cmath>
#include <map>

#include "ros/ros1_node.hpp"
#include "wheelins/run/live_odometry.hpp"
#endif

namespace {
using namespace wheelins;

struct LiveArgs {
  std::string config_file, format = "json";
  double warmup = 120.0, window = 0.05, publish_interval = 0.1, idle_exit = 0.0;
  std::optional<int> udp_port;  // none: standard input
  bool ros = false;             // ROS 1 topics (docs/live.md)
  double ros_wait = 10.0;       // [s] for the master
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

void print_summary(const LiveStreamStats& st, const RunResult& res, double wall, double cpu, const char* unit) {
  double median = 0.0, p99 = 0.0;
  latency_percentiles(st.latency, median, p99);
  const double worst = st.latency.empty() ? 0.0 : *std::max_element(st.latency.begin(), st.latency.end());
  std::fprintf(stderr,
               "wheelins live: %llu %s, %llu samples navigated over %.1f s, %llu states published; "
               "left out: %llu unreadable or not navigated, %llu late, %llu refused by the input checks\n",
               static_cast<unsigned long long>(st.lines), unit, static_cast<unsigned long long>(st.samples),
               res.stats.t_end - res.stats.t_start, static_cast<unsigned long long>(st.published),
               static_cast<unsigned long long>(st.bad_lines), static_cast<unsigned long long>(st.late),
               static_cast<unsigned long long>(st.rejected));
  std::fprintf(stderr,
               "latency from a record's arrival to the state published after it: median %.3f ms, 99th "
               "percentile %.3f ms, max %.1f ms (%zu states); CPU %.2f s in %.2f s wall (%.1f %% of one "
               "core)\n",
               1e3 * median, 1e3 * p99, 1e3 * worst, st.latency.size(), cpu, wall, wall > 0 ? 100.0 * cpu / wall : 0.0);
  if (!res.files.empty())
    std::fprintf(stderr, "wrote %zu files to %s\n", res.files.size(),
                 res.files.front().parent_path().string().c_str());
}

/// 3 when input was left out (said so), else 0.
int left_out_exit(const LiveStreamStats& st, const char* what) {
  if (st.left_out() == 0) return 0;
  std::fprintf(stderr, "wheelins live: %llu input %s were left out (reported above): exit 3\n",
               static_cast<unsigned long long>(st.left_out()), what);
  return 3;
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
  print_summary(stream.stats(), res, now_seconds() - wall0, cpu_seconds() - cpu0, "lines");
  return left_out_exit(stream.stats(), "lines");
}


#if WHEELINS_HAVE_ROS_LIVE
// ----------------------------------------------------------------------------- ROS 1 node

/// The node's settings: its private parameters (a YAML file loaded by the launch file).
/// `settings.KEY` parameters are run settings, under the command line's (as --set KEY=VALUE
/// before the command line's --set and named options); `config` a run configuration file when
/// the command line names none; `topics.MODULE` a module's topic (default NAME/imu, a ROS
/// name, in the node's namespace); `frame_ids.MODULE` the frame id its messages must carry;
/// the others go over the command line's --window, --publish-interval, --calibration-warmup
/// and --idle-exit.
struct RosParams {
  ros1::NodeSetup setup;
  std::map<std::string, std::string> topics, frame_ids;
  double stale_after = 1.0;  ///< [s] without a message before a topic's diagnostic is an error
};

constexpr double kDiagnosticsPeriod = 1.0;  ///< [s] of wall time between the node's diagnostics

double param_number(const std::string& node, const std::string& key, const std::string& text, double lo, double hi) {
  double v = 0.0;
  std::size_t used = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !(v >= lo && v <= hi))
    throw InputError("ROS parameter " + node + "/" + key + " '" + text + "': a number in [" + io_detail::format_double(lo) +
                     ", " + io_detail::format_double(hi) + "]");
  return v;
}

bool param_bool(const std::string& node, const std::string& key, const std::string& text) {
  if (text == "true" || text == "1") return true;
  if (text == "false" || text == "0") return false;
  throw InputError("ROS parameter " + node + "/" + key + " '" + text + "': true or false");
}

RosParams read_ros_params(const ros1::Node& node, LiveArgs& a) {
  RosParams p;
  std::vector<std::string> settings;
  const std::string n = node.name();
  for (const auto& [key, value] : node.private_parameters()) {
    const std::size_t dot = key.find('.');
    const std::string top = key.substr(0, dot);
    const std::string sub = dot == std::string::npos ? "" : key.substr(dot + 1);
    if (top == "settings" && !sub.empty()) settings.push_back(sub + "=" + value);
    else if (top == "topics" && !sub.empty()) p.topics[sub] = value;
    else if (top == "frame_ids" && !sub.empty()) p.frame_ids[sub] = value;
    else if (key == "config") a.config_file = a.config_file.empty() ? value : a.config_file;
    else if (key == "odom_topic") p.setup.odom_topic = value;
    else if (key == "odom_frame") p.setup.odom_frame = value;
    else if (key == "base_frame") p.setup.base_frame = value;
    else if (key == "publish_tf") p.setup.publish_tf = param_bool(n, key, value);
    else if (key == "publish_rate") a.publish_interval = 1.0 / param_number(n, key, value, 0.01, 1000.0);
    else if (key == "window") a.window = param_number(n, key, value, 0.0, 60.0);
    else if (key == "calibration_warmup") a.warmup = param_number(n, key, value, 1e-3, 3600.0);
    else if (key == "stale_after") p.stale_after = param_number(n, key, value, 0.01, 3600.0);
    else if (key == "idle_exit") a.idle_exit = param_number(n, key, value, 0.0, 86400.0);
    else
      throw InputError("ROS parameter " + n + "/" + key +
                       ": unknown (known: config, settings/KEY, topics/MODULE, frame_ids/MODULE, odom_topic, "
                       "odom_frame, base_frame, publish_tf, publish_rate, window, calibration_warmup, stale_after, "
                       "idle_exit; docs/live.md)");
  }
  a.settings.insert(a.settings.begin(), settings.begin(), settings.end());
  return p;
}

/// A module's name as a ROS graph name: characters other than letters, digits and _ become _
/// (and a name that does not start with a letter gets an "m" before it).
std::string ros_name(const std::string& name) {
  std::string n = name;
  for (char& c : n)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') c = '_';
  if (n.empty() || !std::isalpha(static_cast<unsigned char>(n.front()))) n = "m" + n;
  return n;
}

ros1::Odometry odometry_message(const OdometryState& s) {
  ros1::Odometry o;
  o.t = s.t;
  for (int k = 0; k < 3; ++k) {
    o.position[k] = s.position[k];
    o.linear[k] = s.linear[k];
    o.angular[k] = s.angular[k];
  }
  o.orientation[0] = s.orientation.x();
  o.orientation[1] = s.orientation.y();
  o.orientation[2] = s.orientation.z();
  o.orientation[3] = s.orientation.w();
  o.pose_covariance = s.pose_covariance;
  o.twist_covariance = s.twist_covariance;
  return o;
}

/// What the node knows of each topic, for its diagnostics.
struct TopicState {
  std::string topic, frame_id;
  std::uint64_t received = 0, refused = 0;
  double last_arrival = 0.0, last_stamp = 0.0;
};

std::vector<ros1::Diagnostic> diagnostics(const PushSession& session, const LiveStream& stream,
                                          const std::vector<TopicState>& topics, const std::vector<std::string>& wrong,
                                          double now, double stale_after) {
  std::vector<ros1::Diagnostic> out;
  const Navigator& nav = session.navigator();
  const bool navigating = !session.in_warmup() && nav.navigating();
  for (std::size_t i = 0; i < topics.size(); ++i) {
    const TopicState& t = topics[i];
    ros1::Diagnostic d;
    d.name = "wheelins: " + stream.modules()[i];
    d.hardware_id = t.topic;
    const double silent = now - t.last_arrival;
    std::string health = "not navigating yet";
    if (navigating && static_cast<int>(i) < nav.faults().size()) health = to_string(nav.faults().health(static_cast<int>(i)));
    if (t.received == 0) {
      d.level = ros1::Diagnostic::kError;
      d.message = "no message on " + t.topic + " yet";
    } else if (silent > stale_after) {
      d.level = ros1::Diagnostic::kError;
      d.message = "no message on " + t.topic + " for " + io_detail::format_double(std::round(silent * 10) / 10) +
                  " s: left out of the navigation";
    } else if (navigating && !nav.faults().counts(static_cast<int>(i))) {
      d.level = ros1::Diagnostic::kWarn;
      d.message = "left out by the fault handling: " + health;
    } else {
      d.message = "ok";
    }
    if (i < wrong.size() && !wrong[i].empty()) {
      d.level = ros1::Diagnostic::kError;
      d.message = "a publisher on " + t.topic + " of type " + wrong[i] + ": the node takes sensor_msgs/Imu";
    }
    d.values = {{"messages", std::to_string(t.received)},
                {"refused", std::to_string(t.refused)},
                {"last stamp [s]", io_detail::format_double(t.last_stamp)},
                {"health", health}};
    out.push_back(std::move(d));
  }
  const LiveStreamStats& st = stream.stats();
  ros1::Diagnostic all;
  all.name = "wheelins: navigation";
  all.level = st.left_out() > 0 ? ros1::Diagnostic::kWarn : ros1::Diagnostic::kOk;
  all.message = session.in_warmup() ? "calibration warm-up" : navigating ? "navigating" : "waiting for the static period";
  all.values = {{"samples navigated", std::to_string(st.samples)},
                {"states published", std::to_string(st.published)},
                {"left out: unreadable", std::to_string(st.bad_lines)},
                {"left out: late", std::to_string(st.late)},
                {"left out: refused by the input checks", std::to_string(st.rejected)}};
  out.push_back(std::move(all));
  return out;
}

/// A message's values, or why it cannot be navigated.
std::string refusal(const ros1::ImuMessage& m, const TopicState& t, const std::map<std::string, std::string>& frame_ids,
                    const std::string& module) {
  static const char* const names[6] = {"angular_velocity.x", "angular_velocity.y", "angular_velocity.z",
                                       "linear_acceleration.x", "linear_acceleration.y", "linear_acceleration.z"};
  const std::string at = t.topic + " seq " + std::to_string(m.seq) + ": ";
  if (!(m.t > 0.0) || !std::isfinite(m.t)) return at + "header.stamp " + io_detail::format_double(m.t) + " is not a time";
  for (int k = 0; k < 6; ++k) {
    const double v = k < 3 ? m.gyro[k] : m.accel[k - 3];
    if (!std::isfinite(v)) return at + names[k] + " is " + (std::isnan(v) ? "NaN" : "infinite");
  }
  const auto want = frame_ids.find(module);
  if (want != frame_ids.end() && m.frame_id != want->second)
    return at + "frame_id '" + m.frame_id + "' is not '" + want->second + "' (frame_ids/" + module + ")";
  if (want == frame_ids.end() && !t.frame_id.empty() && m.frame_id != t.frame_id)
    return at + "frame_id '" + m.frame_id + "' is not the topic's first one, '" + t.frame_id + "'";
  return {};
}

/// The ROS 1 node from its plugin next to the program (cmake/ros_live.cmake), connected to the
/// master. The plugin stays loaded to the end of the process (roscpp's statics).
std::unique_ptr<ros1::Node> connect_ros(const std::vector<std::string>& ros_args, double wait) {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  const std::filesystem::path plugin = exe.parent_path() / ros1::kPluginFile;
  void* lib = ::dlopen(plugin.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (lib == nullptr)
    throw InputError("live --ros: cannot load the ROS 1 node '" + plugin.string() + "': " + ::dlerror() +
                     " (Debian's ROS 1 packages: scripts/setup.sh)");
  const auto connect = reinterpret_cast<ros1::ConnectFunction>(::dlsym(lib, ros1::kConnectSymbol));
  if (connect == nullptr) throw InputError("live --ros: '" + plugin.string() + "' is not the ROS 1 node of this build");
  std::string error;
  ros1::Node* node = connect("wheelins", ros_args, wait, error);
  if (node == nullptr) throw InputError("live --ros: " + error);
  return std::unique_ptr<ros1::Node>(node);
}

/// Each navigated module's topic (`topics/NAME` or NAME/imu), added to the node's setup.
std::vector<TopicState> topic_states(const LiveStream& stream, RosParams& p) {
  std::vector<TopicState> topics;
  for (const auto& name : stream.modules()) {
    const auto t = p.topics.find(name);
    topics.push_back(TopicState{t == p.topics.end() ? ros_name(name) + "/imu" : t->second, {}, 0, 0, now_seconds(), 0.0});
    p.setup.topics.push_back(topics.back().topic);
  }
  for (const auto& [module, topic] : p.topics)
    if (stream.module_index(module) < 0) throw InputError("ROS parameter topics/" + module + ": not a navigated module");
  return topics;
}

/// A message of the topic `t`: refused (reported as a bad line) or given to the stream. False
/// once the stream takes no more.
bool take_message(const ros1::ImuMessage& m, TopicState& t, const RosParams& p, LiveStream& stream) {
  ++t.received;
  t.last_arrival = m.arrival;
  const std::string why = refusal(m, t, p.frame_ids, stream.modules()[static_cast<std::size_t>(m.module)]);
  if (!why.empty()) {
    ++t.refused;
    stream.refuse(why);
    return true;
  }
  if (t.frame_id.empty()) t.frame_id = m.frame_id;
  t.last_stamp = m.t;
  ImuRow row;
  row.t = m.t;
  row.gyro = Vec3(m.gyro[0], m.gyro[1], m.gyro[2]);
  row.accel = Vec3(m.accel[0], m.accel[1], m.accel[2]);
  return stream.sample(m.module, row, m.arrival);
}

int live_ros(LiveArgs a, const std::vector<std::string>& ros_args) {
  const std::unique_ptr<ros1::Node> connected = connect_ros(ros_args, a.ros_wait);
  ros1::Node& node = *connected;
  RosParams p = read_ros_params(node, a);
  const WarningSink warn = [](const std::string& w) { std::fprintf(stderr, "warning: %s\n", w.c_str()); };
  PushSession session(live_request(a, warn), a.warmup, "ROS topics");
  for (const auto& name : session.request().modules)
    if (imu_read_options(*session.request().manifest.find(name)).format != SampleFormat::kRate)
      throw InputError(session.request().manifest.path.string() + ": module '" + name +
                       "': format is increment, and a sensor_msgs/Imu message carries rates (format: rate)");
  OdometryFrame frame;
  LiveStreamOptions opt;
  opt.window = a.window;
  opt.publish_interval = a.publish_interval;
  opt.source = "ROS topics";
  opt.unit = "message";
  opt.on_state = [&](const TrajectoryRecord& r) { node.publish(odometry_message(frame(r))); };
  LiveStream stream(session, opt, stdout, stderr);
  std::vector<TopicState> topics = topic_states(stream, p);
  // The messages are navigated on roscpp's receive thread (Node::start); this thread publishes
  // the diagnostics and ends the run: `mutex` guards the stream, the session and the topics.
  std::mutex mutex;
  bool more = true;
  double last_input = 0.0;
  // Whichever way this function is left: no message after the variables the callback uses.
  struct Unsubscribe {
    ros1::Node& node;
    ~Unsubscribe() { node.stop(); }
  } const unsubscribe{node};
  node.start(p.setup, [&](const ros1::ImuMessage& m) {
    const std::lock_guard<std::mutex> lock(mutex);
    if (!more) return;
    last_input = m.arrival;
    more = take_message(m, topics[static_cast<std::size_t>(m.module)], p, stream);
  });
  std::string mods;
  for (std::size_t i = 0; i < topics.size(); ++i) mods += (i ? ", " : "") + stream.modules()[i] + " <- " + topics[i].topic;
  std::fprintf(stderr, "wheelins live: ROS node %s: %s; publishing %s (%s -> %s)%s, /diagnostics\n", node.name().c_str(),
               mods.c_str(), p.setup.odom_topic.c_str(), p.setup.odom_frame.c_str(), p.setup.base_frame.c_str(),
               p.setup.publish_tf ? ", /tf" : "");
  catch_stop_signals();
  const double wall0 = now_seconds(), cpu0 = cpu_seconds();
  double next_diag = wall0;
  std::vector<std::string> wrong;
  while (!interrupt_requested() && node.spin(0.05)) {
    const double now = now_seconds();
    if (now >= next_diag) wrong = node.wrong_types();  // asks the master: not under the lock
    const std::lock_guard<std::mutex> lock(mutex);
    if (!more) break;
    if (now >= next_diag) {
      node.publish(diagnostics(session, stream, topics, wrong, now, p.stale_after), 0.0);
      next_diag = now + kDiagnosticsPeriod;
    }
    // From the first message on: a node waits for its topics as long as it takes.
    if (a.idle_exit > 0.0 && last_input > 0.0 && now - last_input > a.idle_exit) {
      std::fprintf(stderr, "wheelins live: no message for %g s (idle_exit): the run ends here\n", a.idle_exit);
      break;
    }
  }
  node.stop();  // later messages are not navigated
  const std::lock_guard<std::mutex> lock(mutex);
  const bool stopped = interrupt_requested();
  clear_interrupt();
  if (stopped) std::fprintf(stderr, "wheelins live: stopped by a signal: the run ends here\n");
  stream.end();
  const RunResult res = session.finish();
  node.publish(diagnostics(session, stream, topics, wrong, now_seconds(), p.stale_after), 0.0);
  print_summary(stream.stats(), res, now_seconds() - wall0, cpu_seconds() - cpu0, "messages");
  return left_out_exit(stream.stats(), "messages");
}
#endif

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
#if WHEELINS_HAVE_ROS_LIVE
      sub.add_flag("--ros", a->ros,
                   "A ROS 1 node: sensor_msgs/Imu topics in, nav_msgs/Odometry, /tf and /diagnostics out; its "
                   "private parameters and ROS arguments (__name:=, remappings) as docs/live.md says");
      sub.add_option("--ros-wait", a->ros_wait, "Seconds to wait for the ROS master (default 10)");
#endif
      sub.allow_extras();  // ROS arguments (NAME:=VALUE), refused without --ros
      cli::add_settings_option(sub, a->settings);
      sub.footer("Files (the trajectory, calibration.yaml, ...) are written at the end only when --out or the "
                 "configuration's output.dir names a directory.");
      return [a, &sub]() {
        std::vector<std::string> extras = sub.remaining();
        if (a->config_file.find(":=") != std::string::npos) {  // a ROS argument in the configuration's place
          extras.insert(extras.begin(), a->config_file);
          a->config_file.clear();
        }
        for (const auto& e : extras)
          if (!a->ros || e.find(":=") == std::string::npos)
            throw InputError("live: unexpected argument '" + e + "'" +
                             (a->ros ? " (ROS arguments are NAME:=VALUE)" : ""));
#if WHEELINS_HAVE_ROS_LIVE
        if (a->ros) {
          if (a->udp_port) throw InputError("live: --ros and --udp are two sources: give one");
          return live_ros(*a, extras);
        }
#endif
        return live(*a);
      };
    });
}  // namespace
