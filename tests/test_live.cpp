// `wheelins live`'s plain stream (issue 32): lines parsed, put back in order within the
// window, and a simulated dataset piped through standard input giving the file run's
// trajectory to the byte, also with bad input mixed in (which is reported and left out), and
// the same through UDP datagrams on localhost.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "dataset_test_util.hpp"
#include "io_test_util.hpp"
#include "wheelins/io/manifest.hpp"
#include "wheelins/run/live_stream.hpp"
#include "wheelins/run/presets.hpp"

using namespace wheelins;
namespace fs = std::filesystem;

namespace {

sockaddr_in localhost(int port) {
  sockaddr_in a = {};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  return a;
}

/// A UDP port on localhost that nothing holds (bound and let go: the program binds it next).
int free_udp_port() {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in a = localhost(0);
  socklen_t len = sizeof a;
  const bool ok = ::bind(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a) == 0 &&
                  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) == 0;
  ::close(fd);
  return ok ? ntohs(a.sin_port) : -1;
}

/// Whether the program has said that it listens on `port` (it says so once the port is bound;
/// probing by binding the port ourselves could take it from the program).
bool says_it_listens(const fs::path& err, int port) {
  std::ifstream f(err);
  std::stringstream text;
  text << f.rdbuf();
  return text.str().find("UDP datagrams on 127.0.0.1:" + std::to_string(port)) != std::string::npos;
}

ImuRow row_at(double t) {
  ImuRow r;
  r.t = t;
  return r;
}

TEST(LiveStreamLine, ReadsCommaAndSpaceSeparatedLines) {
  StreamLine l;
  ASSERT_TRUE(parse_stream_line("left-C1, 100.005, 0.1, -0.2, 3e-3, 0.5, 0.25, -9.81\r\n", l));
  EXPECT_EQ(l.module, "left-C1");
  EXPECT_DOUBLE_EQ(l.row.t, 100.005);
  EXPECT_DOUBLE_EQ(l.row.gyro.z(), 3e-3);
  EXPECT_DOUBLE_EQ(l.row.accel.z(), -9.81);
  ASSERT_TRUE(parse_stream_line("2 7 1 2 3 4 5 6", l));
  EXPECT_EQ(l.module, "2");
  EXPECT_DOUBLE_EQ(l.row.accel.x(), 4.0);
  EXPECT_FALSE(parse_stream_line("# module, t, gx, gy, gz, ax, ay, az", l));
  EXPECT_FALSE(parse_stream_line("   \n", l));
}

TEST(LiveStreamLine, NamesTheFieldThatIsWrong) {
  StreamLine l;
  auto message = [&](const char* text) {
    try {
      parse_stream_line(text, l);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("m, 1, 2, 3, 4, 5, 6").find("field 8 (az) is missing"), std::string::npos);
  EXPECT_NE(message("m, 1, 2, x3, 4, 5, 6, 7").find("field 4 (gy) 'x3' is not a number"), std::string::npos);
  EXPECT_NE(message("m, 1, 2, 3, nan, 5, 6, 7").find("field 5 (gz) is NaN"), std::string::npos);
  EXPECT_NE(message("m, 1, 2, 3, 4, 5, 6, inf").find("field 8 (az) is infinite"), std::string::npos);
  EXPECT_NE(message("m, 1, 2, 3, 4, 5, 6, 7, 8").find("more than 8 fields"), std::string::npos);
  EXPECT_NE(message("m, , 2, 3, 4, 5, 6, 7").find("field 2 (t) is missing"), std::string::npos);
}

TEST(LiveReorderWindow, ReleasesInTimeOrderOnceTheWindowHasPassed) {
  ReorderWindow w(0.02);
  ReorderWindow::Item it;
  ASSERT_TRUE(w.offer(1.000, 1, 1, row_at(1.000)));
  ASSERT_TRUE(w.offer(1.000, 0, 2, row_at(1.000)));  // a tie: module 0 first, as the file run
  ASSERT_TRUE(w.offer(0.995, 2, 3, row_at(0.995)));  // out of order, inside the window
  EXPECT_FALSE(w.pop_due(it));                       // nothing is 0.02 s older than the newest
  ASSERT_TRUE(w.offer(1.016, 0, 4, row_at(1.016)));
  ASSERT_TRUE(w.pop_due(it));
  EXPECT_EQ(it.line, 3u);
  EXPECT_FALSE(w.pop_due(it));  // 1.000 is not yet 0.02 s older than 1.016
  ASSERT_TRUE(w.offer(1.021, 1, 5, row_at(1.021)));
  ASSERT_TRUE(w.pop_due(it));
  EXPECT_EQ(it.module, 0);
  EXPECT_EQ(it.line, 2u);
  ASSERT_TRUE(w.pop_due(it));
  EXPECT_EQ(it.module, 1);
  EXPECT_FALSE(w.offer(0.999, 2, 6, row_at(0.999)));  // older than what was released: late
  EXPECT_TRUE(w.offer(1.000, 2, 7, row_at(1.000)));   // as old as it: still in order
  std::vector<std::uint64_t> rest;
  while (w.pop_any(it)) rest.push_back(it.line);
  EXPECT_EQ(rest, (std::vector<std::uint64_t>{7, 4, 5}));
  EXPECT_THROW(ReorderWindow(-0.1), InputError);
}

TEST(LiveReorderWindow, ZeroWindowPassesSamplesOnAsTheyCome) {
  ReorderWindow w(0.0);
  ReorderWindow::Item it;
  ASSERT_TRUE(w.offer(2.0, 0, 1, row_at(2.0)));
  ASSERT_TRUE(w.pop_due(it));
  EXPECT_FALSE(w.offer(1.9, 0, 2, row_at(1.9)));
  EXPECT_EQ(w.size(), 0u);
}

struct Cmd {
  int code = -1;
  std::string err;
};

class LiveCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new iotest::ScratchDir();
    dstest::simulate_short(dir_->path() / "data", 60.0);  // 30 s of it standing
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static fs::path manifest() { return dir_->path() / "data" / "manifest.yaml"; }
  /// The configuration's records as `module, t, ...` lines in time order (ties in module
  /// order, as the file run merges them), at full precision.
  static std::vector<std::string> lines(const std::string& configuration) {
    const Manifest m = load_manifest(manifest(), {});
    const std::vector<std::string> modules = configuration_modules(m, configuration, {});
    std::vector<std::tuple<double, std::size_t, std::size_t>> order;
    std::vector<std::vector<double>> data;
    for (std::size_t i = 0; i < modules.size(); ++i) {
      data.push_back(dstest::read_doubles(m.resolve(m.find(modules[i])->file)));
      for (std::size_t k = 0; k + 7 <= data.back().size(); k += 7) order.emplace_back(data.back()[k], i, k);
    }
    std::sort(order.begin(), order.end());
    std::vector<std::string> out;
    char buf[512];
    for (const auto& [t, i, k] : order) {
      const double* v = &data[i][k];
      std::snprintf(buf, sizeof buf, "%s,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", modules[i].c_str(), v[0], v[1],
                    v[2], v[3], v[4], v[5], v[6]);
      out.emplace_back(buf);
    }
    return out;
  }
  static Cmd sh(const std::string& args, const fs::path& err) {
    const std::string cmd = std::string("'") + WHEELINS_BINARY + "' " + args + " 2>'" + err.string() + "'";
    const int status = std::system(cmd.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, iotest::read_text_file(err)};
  }
  /// `wheelins live` on these lines: the run's files in `out`, the states in `out`/states.
  static Cmd live(const std::vector<std::string>& text, const fs::path& out, const std::string& options = "") {
    const fs::path in = out.string() + ".lines";
    {
      std::ofstream f(in);
      for (const auto& l : text) f << l << '\n';
    }
    return sh("live -m '" + manifest().string() + "' -c triple --calibration manifest -o '" + out.string() + "' " +
                  options + " <'" + in.string() + "' >'" + out.string() + ".states'",
              out.string() + ".err");
  }
  static std::string file_run_trajectory() {
    const fs::path out = dir_->path() / "file-run";
    if (!fs::exists(out)) {
      const Cmd c = sh("run -m '" + manifest().string() + "' -c triple --calibration manifest --no-data-checks "
                       "--no-evaluate -q -o '" + out.string() + "' >/dev/null",
                       dir_->path() / "file-run.err");
      EXPECT_EQ(c.code, 0) << c.err;
    }
    return iotest::read_text_file(out / "trajectory.csv");
  }
  static iotest::ScratchDir* dir_;
};
iotest::ScratchDir* LiveCliTest::dir_ = nullptr;

TEST_F(LiveCliTest, ADatasetPipedThroughStandardInputGivesTheFileRunsTrajectory) {
  const fs::path out = dir_->path() / "piped";
  const Cmd c = live(lines("triple"), out);
  ASSERT_EQ(c.code, 0) << c.err;
  EXPECT_EQ(iotest::read_text_file(out / "trajectory.csv"), file_run_trajectory());
  // The states: one JSON object per line every 0.1 s of navigation (30 s), none before the
  // static period's end, every value a number.
  std::istringstream states(iotest::read_text_file(out.string() + ".states"));
  std::string l;
  int n = 0;
  double prev_t = 0.0;
  while (std::getline(states, l)) {
    ++n;
    ASSERT_EQ(l.rfind("{\"t_s\":", 0), 0u) << l;
    const double t = std::stod(l.substr(7));
    if (n > 1) {
      EXPECT_NEAR(t - prev_t, 0.1, 1e-6) << "state " << n;  // every 0.1 s of data
    }
    prev_t = t;
    ASSERT_EQ(l.back(), '}');
    EXPECT_EQ(l.find("null"), std::string::npos) << l;
    EXPECT_NE(l.find("\"north_std_m\":"), std::string::npos);
  }
  EXPECT_GE(n, 295);
  EXPECT_LE(n, 302);
  EXPECT_NE(c.err.find("waiting for the static period"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("left out: 0 unreadable or not navigated, 0 late, 0 refused"), std::string::npos) << c.err;
}

TEST_F(LiveCliTest, BadInputIsReportedAndLeftOutWithoutChangingTheTrajectory) {
  std::vector<std::string> text = lines("triple");
  ASSERT_GT(text.size(), 30000u);
  // Out of order within the window: two neighbours swapped (the window puts them back).
  std::swap(text[20001], text[20002]);
  std::vector<std::string> bad;
  for (std::size_t k = 0; k < text.size(); ++k) {
    bad.push_back(text[k]);
    if (k == 1000) bad.push_back("left, not, a, number");
    if (k == 2000) bad.push_back("nobody,1e5,0,0,0,0,0,-9.8");
    if (k == 25000) bad.push_back(text[24000]);  // 1000 lines (1.7 s) old: late
    if (k == 26000)
      for (int d = 0; d < 20; ++d) bad.push_back(text[k]);  // a burst of duplicate stamps
    if (k == 27000) {
      std::string nan = text[k];
      nan.replace(nan.rfind(','), std::string::npos, ",nan");
      bad.push_back(nan);
    }
  }
  const fs::path out = dir_->path() / "bad";
  const Cmd c = live(bad, out);
  EXPECT_EQ(c.code, 3) << c.err;  // navigated to the end; some input was left out
  EXPECT_EQ(iotest::read_text_file(out / "trajectory.csv"), file_run_trajectory());
  EXPECT_NE(c.err.find("line 1002: field 2 (t) 'not' is not a number"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("line 2003: module 'nobody' is not navigated"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("line 25004: module"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("arrived after the reorder window"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("repeats the previous sample's time"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("(further ones of this kind are counted only)"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("left out: 3 unreadable or not navigated, 1 late, 20 refused"), std::string::npos)
      << c.err;
  const std::string states = iotest::read_text_file(out.string() + ".states");
  EXPECT_EQ(states.find("null"), std::string::npos);
  EXPECT_GT(std::count(states.begin(), states.end(), '\n'), 290);
}

TEST_F(LiveCliTest, PublishesCsvRowsAtTheAskedIntervalAndRefusesBadOptions) {
  const fs::path out = dir_->path() / "csv";
  const Cmd c = live(lines("triple"), out, "--format csv --publish-interval 1 --calibration-warmup 5");
  ASSERT_EQ(c.code, 0) << c.err;
  std::istringstream states(iotest::read_text_file(out.string() + ".states"));
  std::string l;
  ASSERT_TRUE(std::getline(states, l));
  EXPECT_EQ(l.rfind("t_s,north_m,east_m", 0), 0u) << l;
  int n = 0;
  while (std::getline(states, l)) ++n;
  EXPECT_GE(n, 29);
  EXPECT_LE(n, 31);
  EXPECT_EQ(live({}, dir_->path() / "f", "--format xml").code, 2);
  EXPECT_EQ(live({}, dir_->path() / "w", "--window -1").code, 2);
  const Cmd none = live({"# nothing but a comment"}, dir_->path() / "n");
  EXPECT_EQ(none.code, 2);
  EXPECT_NE(none.err.find("the data end before the static period"), std::string::npos) << none.err;
}

TEST_F(LiveCliTest, UdpDatagramsOnLocalhostGiveTheFileRunsTrajectory) {
  const std::vector<std::string> text = lines("triple");
  const fs::path out = dir_->path() / "udp";
  const int port = free_udp_port();
  ASSERT_GT(port, 0);
  const std::string cmd = "exec '" + std::string(WHEELINS_BINARY) + "' live -m '" + manifest().string() +
                          "' -c triple --calibration manifest --udp " + std::to_string(port) +
                          " --idle-exit 2 -o '" + out.string() + "' >'" + out.string() + ".states' 2>'" +
                          out.string() + ".err'";
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  bool listening = false;
  for (int k = 0; k < 600 && !listening; ++k) {
    listening = says_it_listens(out.string() + ".err", port);
    if (!listening) ::usleep(50000);
  }
  if (!listening) ::kill(pid, SIGKILL);
  // 40 lines a datagram, every second one without its last newline (a datagram's end ends a
  // line), paced at about 8,000 lines per second (a slower receiver under the sanitizers keeps
  // up even where the system allows no large receive buffer); then 2 s of silence end the run.
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  const sockaddr_in to = localhost(port);
  std::string datagram;
  std::size_t sent = 0, datagrams = 0;
  for (std::size_t k = 0; listening && k < text.size(); ++k) {
    datagram += text[k];
    datagram += '\n';
    if ((k + 1) % 40 != 0 && k + 1 != text.size()) continue;
    if (++datagrams % 2 == 0) datagram.pop_back();
    if (::sendto(fd, datagram.data(), datagram.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to) ==
        static_cast<ssize_t>(datagram.size()))
      sent += (k % 40) + 1;
    datagram.clear();
    ::usleep(5000);
  }
  ::close(fd);
  int status = 0;
  ::waitpid(pid, &status, 0);
  const std::string err = iotest::read_text_file(out.string() + ".err");
  ASSERT_TRUE(listening) << "the program did not listen on port " << port << ": " << err;
  ASSERT_EQ(sent, text.size());
  ASSERT_TRUE(WIFEXITED(status)) << err;
  ASSERT_EQ(WEXITSTATUS(status), 0) << err;
  EXPECT_EQ(iotest::read_text_file(out / "trajectory.csv"), file_run_trajectory());
  EXPECT_NE(err.find("UDP datagrams on 127.0.0.1:" + std::to_string(port)), std::string::npos) << err;
  EXPECT_NE(err.find("no input on udp://127.0.0.1:" + std::to_string(port) + " for 2 s (--idle-exit)"),
            std::string::npos) << err;
  EXPECT_NE(err.find("wheelins live: " + std::to_string(text.size()) + " lines"), std::string::npos) << err;
  EXPECT_NE(err.find("left out: 0 unreadable or not navigated, 0 late, 0 refused"), std::string::npos) << err;

  // A port out of range, a port already held (by this test), a negative idle time: refused.
  const fs::path bad = dir_->path() / "udp-bad";
  for (const std::string& opt : {std::string("--udp 70000"), std::string("--idle-exit -1")}) {
    const Cmd c = live({}, bad, opt);
    EXPECT_EQ(c.code, 2) << opt << ": " << c.err;
    EXPECT_NE(c.err.find(opt.substr(0, opt.find(' '))), std::string::npos) << c.err;
  }
  const int holder = ::socket(AF_INET, SOCK_DGRAM, 0);
  const sockaddr_in held = localhost(port);
  ASSERT_EQ(::bind(holder, reinterpret_cast<const sockaddr*>(&held), sizeof held), 0);
  const Cmd c = live({}, bad, "--udp " + std::to_string(port));
  ::close(holder);
  EXPECT_EQ(c.code, 2) << c.err;
  EXPECT_NE(c.err.find("cannot listen on 127.0.0.1:" + std::to_string(port)), std::string::npos) << c.err;
}

TEST_F(LiveCliTest, ASignalEndsTheRunAsTheEndOfInputDoesAndTheFilesAreWritten) {
  // The input stays open (a logger still running) until the program is told to stop.
  const std::vector<std::string> text = lines("triple");
  const fs::path out = dir_->path() / "signal", in = dir_->path() / "signal.lines";
  {
    std::ofstream f(in);
    for (std::size_t k = 0; k < text.size() * 3 / 4; ++k) f << text[k] << '\n';
  }
  const std::string states = out.string() + ".states";
  // Through a named pipe, so that the shell waits for the program alone (not the feeder).
  const std::string fifo = out.string() + ".fifo";
  const std::string script =
      "mkfifo '" + fifo + "' || exit 9; (cat '" + in.string() + "'; sleep 20) >'" + fifo + "' 2>/dev/null & feeder=$!; '" +
      WHEELINS_BINARY + "' live -m '" + manifest().string() + "' -c triple --calibration manifest -o '" +
      out.string() + "' <'" + fifo + "' >'" + states + "' 2>'" + out.string() + ".err' & pid=$!; n=0; while [ ! -s '" +
      states + "' ] && [ $n -lt 600 ]; do sleep 0.1; n=$((n+1)); done; sleep 0.5; kill -INT $pid; wait $pid; "
      "rc=$?; kill $feeder 2>/dev/null; exit $rc";
  const int status = std::system(script.c_str());
  const std::string err = iotest::read_text_file(out.string() + ".err");
  ASSERT_TRUE(WIFEXITED(status)) << err;
  EXPECT_EQ(WEXITSTATUS(status), 0) << err;
  EXPECT_NE(err.find("stopped by a signal: the run ends here"), std::string::npos) << err;
  EXPECT_NE(err.find("left out: 0 unreadable"), std::string::npos) << err;
  EXPECT_TRUE(fs::exists(out / "trajectory.csv")) << err;
  EXPECT_GT(iotest::read_text_file(out / "trajectory.csv").size(), 1000u);
}

}  // namespace
