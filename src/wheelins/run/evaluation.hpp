// How a run is evaluated against its manifest's truth as it goes (eval/run_evaluation.hpp),
// one setting for every front end (`wheelins run`, `wheelins odometry`, Python's run(), a
// study's job): the truth's time offset and the antenna from the manifest (or given), and a
// run without an initial heading (a local frame) aligned onto the truth's start.
#pragma once

#include <optional>
#include <string>

#include "wheelins/eval/run_evaluation.hpp"
#include "wheelins/io/manifest.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins {

/// [m] of the truth's travel a run without an initial heading is aligned on for scoring.
constexpr double kDefaultAlignStart = 100.0;

struct RunEvaluationRequest {
  /// [m] of travel the start is aligned over; default: 0 when the manifest gives the initial
  /// heading, else kDefaultAlignStart.
  std::optional<double> align_start;
  /// The truth's antenna in the vehicle frame, "x,y,z" [m], over the manifest's.
  std::string antenna;
  bool keep_series = false;  ///< the per-epoch errors kept (EvalResult::series)
  std::string solution;      ///< names the evaluated trajectory in messages; empty: the default
};

/// The evaluation options of `r` on the manifest `m` (InputError for a malformed antenna).
eval::RunEvaluationOptions run_evaluation_options(const Manifest& m, const RunEvaluationRequest& r);

/// "x,y,z" in metres (the truth's antenna in the vehicle frame); InputError naming `option`.
Vec3 parse_antenna(const std::string& option, const std::string& text);

}  // namespace wheelins
