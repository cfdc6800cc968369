// Helpers for the study tests (test_study.cpp, test_study_run.cpp): files, the command-line
// tool run through a shell, and a small study.
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace wheelins::studytest {

inline std::string slurp(const std::filesystem::path& f) {
  std::ifstream in(f, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline void put(const std::filesystem::path& f, const std::string& text) {
  std::filesystem::create_directories(f.parent_path());
  std::ofstream(f, std::ios::binary) << text;
}

struct Cmd {
  int code;
  std::string out, err;
};

/// Runs a shell command line in `dir`, capturing its output.
inline Cmd shell(const std::string& line, const std::filesystem::path& dir) {
  const std::filesystem::path out = dir / ".cmd-out", err = dir / ".cmd-err";
  const std::string cmd =
      "cd '" + dir.string() + "' && " + line + " >'" + out.string() + "' 2>'" + err.string() + "'";
  const int status = std::system(cmd.c_str());
  Cmd c{WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return c;
}
inline std::string bin() { return std::string("'") + WHEELINS_BINARY + "'"; }
inline std::string script(const char* name) {
  return std::string("'") + WHEELINS_SOURCE_DIR + "/scripts/" + name + "'";
}

/// A small study: 2 seeds x 3 configurations on 60 s of simulated car data (one chip per
/// module): 200 m, so the drift rate has two segments; the whole study takes about a second.
inline const char* const kSmall =
    "name: small\n"
    "simulate:\n"
    "  preset: car\n"
    "  chips: 1\n"
    "  static_s: 10\n"
    "  duration_s: 60\n"
    "seeds: [1, 2]\n"
    "configurations: [single, body-wheel, triple]\n";

}  // namespace wheelins::studytest
