// Numbers in the simulator's texts (errors.yaml, messages): the shortest %g text that
// reads back to the same double, and vectors of them.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "wheelins/math/rotation.hpp"

namespace wheelins::sim {

inline std::string num(double x) {
  char buf[40];
  const int int_digits = std::abs(x) >= 1.0 && std::abs(x) < 1e17
                             ? static_cast<int>(std::floor(std::log10(std::abs(x)))) + 1
                             : 1;
  for (int p = std::max(1, int_digits); p <= 17; ++p) {
    std::snprintf(buf, sizeof buf, "%.*g", p, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  return buf;
}

inline std::string vec(const Vec3& v, double unit = 1.0) {
  return "[" + num(v.x() / unit) + ", " + num(v.y() / unit) + ", " + num(v.z() / unit) + "]";
}

}  // namespace wheelins::sim
