// A manifest held against its data (what `wheelins run` does before navigating): what the
// data can check of the manifest is checked, and a disagreement is an error that names the
// module and the setting to change, with the value the data suggest -- a reversed axle, a
// wheel IMU whose spin axis is not the manifest's axle, a forgotten clock offset, a module
// whose data do not cover the run, a wheel on the other side, a Body-IMU turned over or
// round. A steered wheel is named in a warning. The survey behind it is survey/dataset.hpp,
// run on the modules' files read with the manifest's time offsets.
#pragma once

#include <string>
#include <vector>

#include "wheelins/io/manifest.hpp"
#include "wheelins/survey/dataset.hpp"

namespace wheelins::survey {

struct DataCheck {
  enum class Level { kError, kWarning };
  Level level = Level::kError;
  std::string module;   ///< empty: the whole set
  std::string key;      ///< the manifest key to change, e.g. "modules[1].axle_sign"
  std::string message;  ///< one line, naming the module, the key and the value suggested
};

struct DataCheckOptions {
  double axis_tolerance_deg = 30.0;   ///< spin axis vs the manifest's axle
  double min_forward_share = 0.3;     ///< below: the declared axle sign drives backward (error)
  double doubtful_forward_share = 0.7;
  double clock_error = 0.05;          ///< [s] a clock offset the data show beyond this (and 4 sigma) is an error
  double clock_warning = 0.02;        ///< [s] ... beyond this a warning
  double min_clock_correlation = 0.8; ///< clock fits trusted from this correlation
  double min_coverage = 0.8;          ///< share of the run a module's data must cover
  double body_axis_tolerance_deg = 25.0;   ///< a Body-IMU's down axis vs gravity
  double body_forward_tolerance_deg = 45.0;
  /// A Body-IMU's down axis vs the drive's level fit (survey/level.hpp): a warning beyond
  /// this and three of the fit's sigmas.
  double body_level_tolerance_deg = 1.5;
  double min_motion = 10.0;           ///< [s] of motion before a kind is judged
};

/// The checks of `manifest`'s modules `modules` against `survey` (of the same modules, in
/// that order, with the manifest's time offsets applied).
std::vector<DataCheck> check_against_data(const Manifest& manifest, const std::vector<std::string>& modules,
                                          const DatasetSurvey& survey, const DataCheckOptions& options = {});

/// The surveys' input for `modules` of `manifest` (their files, read options and offsets).
std::vector<ModuleInput> survey_inputs(const Manifest& manifest, const std::vector<std::string>& modules);

}  // namespace wheelins::survey
