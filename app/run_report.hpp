// What `wheelins run` and `wheelins odometry` print of a trajectory against the truth, and
// the evaluation options a manifest gives (its truth clock offset, its antenna, and the
// start alignment of a run without an initial heading).
#pragma once

#include <optional>
#include <string>

#include "wheelins/eval/run_evaluation.hpp"
#include "wheelins/io/manifest.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins {

/// [m] of the truth's travel a run without an initial heading is aligned on for scoring.
constexpr double kDefaultAlignStart = 100.0;

/// The manifest's truth_time_offset_s and antenna; the start aligned over `align_start`
/// metres if given, else kDefaultAlignStart when the manifest has no initial heading.
eval::RunEvaluationOptions run_evaluation_options(const Manifest& m, std::optional<double> align_start,
                                                  const std::string& antenna = "");

/// "x,y,z" in metres (the truth's antenna in the vehicle frame); InputError naming `option`.
Vec3 parse_antenna(const std::string& option, const std::string& text);

/// The figures, and the warnings (stderr) on sigmas and coverage; [t_start, t_end] is what
/// was navigated.
void print_evaluation(const eval::EvalResult& e, const std::string& truth_file, double t_start, double t_end,
                      bool distributed_multi);

}  // namespace wheelins
