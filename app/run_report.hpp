// What `wheelins run` and `wheelins odometry` print of a trajectory against the truth, and
// the evaluation options a manifest gives (its truth clock offset, its antenna, and the
// start alignment of a run without an initial heading).
#pragma once

#include <optional>
#include <string>

#include "wheelins/eval/run_evaluation.hpp"
#include "wheelins/io/manifest.hpp"
#include "wheelins/run/evaluation.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins {

/// The figures, and the warnings (stderr) on sigmas and coverage; [t_start, t_end] is what
/// was navigated.
void print_evaluation(const eval::EvalResult& e, const std::string& truth_file, double t_start, double t_end,
                      bool distributed_multi);

}  // namespace wheelins
