// Helpers for the tests on whole datasets: IMU files read and written as raw rows, an IMU
// file turned into a vendor's CSV table, a manifest's text edited by module, numbers read
// out of messages, and the command-line tool run with its output captured.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "io_test_util.hpp"
#include "wheelins/nav/types.hpp"
#include "wheelins/sim/simulator.hpp"

namespace wheelins::dstest {

/// A short simulated dataset in `dir` (the datasheet profile, one chip per module, no ideal
/// streams): `duration` seconds of the default scenario, the first 30 of them standing.
inline void simulate_short(const std::filesystem::path& dir, double duration) {
  sim::SimConfig cfg;
  cfg.set_profile("datasheet");
  cfg.chips = 1;
  cfg.duration = duration;
  cfg.write_ideal = false;
  sim::Simulation(cfg).write(dir, false, false);
}

/// A file of float64 values (an IMU file, GINS.bin) as read.
inline std::vector<double> read_doubles(const std::filesystem::path& file) {
  const std::string b = iotest::read_text_file(file);
  std::vector<double> v(b.size() / sizeof(double));
  std::memcpy(v.data(), b.data(), v.size() * sizeof(double));
  return v;
}

/// An IMU file as a vendor's CSV table: `t,gx,gy,gz,ax,ay,az`, the gyro in deg/s (a units
/// line says so), the axes turned by R (v' = R v), `shift` added to the times.
inline void write_table(const std::filesystem::path& bin, const std::filesystem::path& csv, const Mat3& R,
                        double shift) {
  const std::vector<double> v = read_doubles(bin);
  std::string text = "# units: s, deg/s, m/s^2\nt,gx,gy,gz,ax,ay,az\n";
  text.reserve(v.size() / 7 * 140);
  char line[400];
  for (std::size_t k = 0; k + 7 <= v.size(); k += 7) {
    const Vec3 g = R * Vec3(v[k + 1], v[k + 2], v[k + 3]) / kDeg, a = R * Vec3(v[k + 4], v[k + 5], v[k + 6]);
    std::snprintf(line, sizeof line, "%.6f,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", v[k] + shift, g.x(), g.y(), g.z(),
                  a.x(), a.y(), a.z());
    text += line;
  }
  iotest::write_text(csv, text);
}

/// The number after `key` in `text` (NaN if there is none).
inline double number_after(const std::string& text, const std::string& key) {
  const std::size_t at = text.find(key);
  if (at == std::string::npos) return std::nan("");
  const char* p = text.c_str() + at + key.size();
  char* end = nullptr;
  const double v = std::strtod(p, &end);
  return end == p ? std::nan("") : v;
}

/// Replaces the first `from` after module `name`'s entry in a manifest's text by `to`.
inline void edit_module_text(const std::filesystem::path& manifest_file, const std::string& name,
                             const std::string& from, const std::string& to) {
  std::string text = iotest::read_text_file(manifest_file);
  const std::size_t entry = text.find("name: \"" + name + "\"");
  ASSERT_NE(entry, std::string::npos) << name;
  const std::size_t at = text.find(from, entry);
  ASSERT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
  iotest::write_text(manifest_file, text);
}

/// What a run of the command-line tool gave: its exit code, stdout and stderr.
struct CmdResult {
  int code = -1;
  std::string out, err;
};

/// Runs `wheelins ARGS` (ARGS quoted by the caller); its output goes through files in `scratch`.
inline CmdResult wheelins_cli(const std::string& args, const std::filesystem::path& scratch) {
  const std::filesystem::path out = scratch / "stdout.txt", err = scratch / "stderr.txt";
  const std::string cmd =
      std::string("'") + WHEELINS_BINARY + "' " + args + " >'" + out.string() + "' 2>'" + err.string() + "'";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, iotest::read_text_file(out), iotest::read_text_file(err)};
}

/// `path` in single quotes for a shell command.
inline std::string q(const std::filesystem::path& path) { return "'" + path.string() + "'"; }

}  // namespace wheelins::dstest
