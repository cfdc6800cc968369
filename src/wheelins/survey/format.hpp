// printf-style formatting of up to three numbers into a string, for the survey's notes and
// messages (any length).
#pragma once

#include <cstdio>
#include <string>

namespace wheelins::survey {

inline std::string fmt(const char* f, double a, double b = 0.0, double c = 0.0) {
  const int n = std::snprintf(nullptr, 0, f, a, b, c);
  if (n <= 0) return {};
  std::string out(static_cast<std::size_t>(n) + 1, '\0');
  std::snprintf(out.data(), out.size(), f, a, b, c);
  out.resize(static_cast<std::size_t>(n));
  return out;
}

}  // namespace wheelins::survey
