// The run configuration: which dataset, which IMUs, the filter settings and the
// outputs. YAML in human units (docs/run-config.md), converted once here; every
// setting has a default except the dataset.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "wheelins/run/run.hpp"

namespace YAML {
class Node;
}

namespace wheelins {

struct RunConfig {
  std::filesystem::path manifest;          ///< dataset manifest
  std::string configuration = "single";    ///< see configuration_names()
  std::vector<std::string> chips;          ///< one per IMU of the configuration
  std::vector<std::string> modules;        ///< explicit modules (overrides configuration)
  std::filesystem::path output_dir;        ///< default: results/<configuration>[-chips]
  std::vector<TrajectoryFormat> formats{TrajectoryFormat::kCsv, TrajectoryFormat::kTum,
                                        TrajectoryFormat::kKml};
  TumFrame tum_frame = TumFrame::kNed;     ///< output.tum_frame: ned | enu
  bool overwrite = false;
  /// Sized by default: the vehicle files at 10 Hz (output.file_interval_s; --full-rate: every
  /// record) and no per-subsystem files (output.subsystems; --subsystems). A 15-minute run
  /// so writes about 7 MB instead of 490 MB; the evaluation sees every record either way.
  double file_interval = 0.1;
  bool write_subsystems = false;
  double max_duration = 0.0;
  std::string earth_rotation = "auto";     ///< auto (from the manifest) | true | false
  /// The Wheel-IMUs' installation: estimated from the data (default) or the manifest's.
  CalibrationMode calibration = CalibrationMode::kEstimate;
  /// The manifest held against its data before the run (survey/checks.hpp).
  bool data_checks = true;
  NavigatorOptions nav;
};

/// Reads a run configuration; relative paths resolve against the file's directory.
RunConfig load_run_config(const std::filesystem::path& file, const WarningSink& warn);
/// The same from settings already parsed (a study's run settings): relative paths resolve
/// against `base`; messages name `where` instead of a file.
RunConfig load_run_config(const YAML::Node& settings, const std::filesystem::path& base,
                          const std::string& where, const WarningSink& warn);

/// A front end's named option as given (`--duration 60`, Python's duration=60.0): the setting
/// it sets (run_options.hpp: NamedOption) and the value, as text.
struct NamedSetting {
  std::string name;                 ///< as the user gave it ("--duration", "duration"): messages name it
  std::string key;                  ///< the setting ("duration_s")
  std::vector<std::string> values;  ///< the value; a list when `list`
  bool list = false;
};

/// What a front end (`wheelins run`'s and `wheelins live`'s options, Python's run() and
/// Navigator()) sets over a run configuration: the file, the `--set` settings over it, the named
/// options over both.
struct RunOverrides {
  std::filesystem::path config;     ///< a run configuration file; empty: the defaults
  std::vector<NamedSetting> named;  ///< in the order given
  /// Any setting of docs/run-config.md as KEY=VALUE (`--set filter.speed_window_s=0.1`), over
  /// the configuration file and under the named options; VALUE is YAML (`[1, 2, 1]`).
  std::vector<std::string> settings;
};

/// The command line's `option` ("--chips", or any of its names) given `value` (ignored for an
/// option without a value): a value with commas is a list, except a path's. InputError for an
/// option that sets no run setting.
NamedSetting cli_setting(const std::string& option, const std::string& value = "");
/// The same for the option itself (run_options.hpp: run_named_options).
struct NamedOption;
NamedSetting cli_setting(const NamedOption& option, const std::string& value = "");

/// For settings where a leftover key cannot be meant (a command line, a study's run settings):
/// every warning of the reading is an InputError, "unknown key ignored" said as "unknown key".
WarningSink warnings_are_errors();

/// `settings` (KEY=VALUE each) read over `c` with the file's checks; InputError naming the
/// setting for a malformed one, an unknown key (and the closest known) or a value out of range.
void apply_run_settings(const std::vector<std::string>& settings, RunConfig& c);

/// The configuration file's settings (or the defaults) with `o` over them, every named option
/// checked before a file is read; InputError naming the option or setting for a value out of
/// range or unknown, for choices that exclude each other (modules with a configuration or
/// chips) and for no dataset.
RunConfig run_config_with(const RunOverrides& o, const WarningSink& warn);

SpeedSharing speed_sharing_from_name(const std::string& name);
/// `estimate` or `manifest` (run/calibration.hpp); InputError otherwise.
CalibrationMode calibration_mode_from_name(const std::string& name);
/// `equal` (the paper) or `covariance` (fusion/aids/position_constraint/reference_weights.hpp); InputError otherwise.
ReferenceWeighting weighting_from_name(const std::string& name);

/// Loads the manifest, resolves the modules and fills a RunRequest.
RunRequest make_run_request(const RunConfig& cfg, const WarningSink& warn);

}  // namespace wheelins
