// The evaluation settings of evaluation.hpp.
#include "wheelins/run/evaluation.hpp"

#include <cmath>
#include <cstdio>

namespace wheelins {

Vec3 parse_antenna(const std::string& option, const std::string& text) {
  double v[3];
  char tail;
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &tail) != 3 || !std::isfinite(v[0]) ||
      !std::isfinite(v[1]) || !std::isfinite(v[2]) || std::abs(v[0]) > 20.0 || std::abs(v[1]) > 20.0 || std::abs(v[2]) > 20.0)
    throw InputError(option + " '" + text + "': expected X,Y,Z in metres (forward, right, down; each within 20 m)");
  return Vec3(v[0], v[1], v[2]);
}

eval::RunEvaluationOptions run_evaluation_options(const Manifest& m, const RunEvaluationRequest& r) {
  eval::RunEvaluationOptions eo;
  eo.eval.truth_time_offset = m.truth_time_offset;
  if (m.antenna_inV) eo.eval.antenna = *m.antenna_inV;
  if (!r.antenna.empty()) eo.eval.antenna = parse_antenna("--antenna", r.antenna);
  // A run without an initial heading is in a local frame: its start is aligned onto the
  // truth's (the heading from the reference at the start, as the paper takes it).
  eo.eval.align_start = r.align_start ? *r.align_start : (m.heading_known ? 0.0 : kDefaultAlignStart);
  eo.keep_series = r.keep_series;
  if (!r.solution.empty()) eo.solution = r.solution;
  return eo;
}

}  // namespace wheelins
