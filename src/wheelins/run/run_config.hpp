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

/// What a front end (`wheelins run`'s flags, Python's run() and Navigator()) sets over a run
/// configuration, each setting once: an empty or unset field keeps the configuration's value.
/// The numbers' ranges are checked with the request (validate_run_request).
struct RunOverrides {
  std::filesystem::path config;    ///< a run configuration file; empty: the defaults
  std::filesystem::path manifest;  ///< over the configuration's dataset
  std::string configuration;       ///< over the configuration's (and its module list)
  std::vector<std::string> chips, modules;
  std::filesystem::path output_dir;
  std::vector<std::string> formats;
  std::string tum_frame, speed, weights, yaw_scale_factors, calibration;
  std::optional<bool> centralized, position_constraint, fault_handling, standstill, fixed_noise,
      data_checks;
  std::optional<double> duration, output_interval, covariance_interval;
  bool overwrite = false;   ///< --force
  bool full_rate = false;   ///< the trajectory files at every record
  bool subsystems = false;  ///< also each IMU's own trajectory
  /// Any setting of docs/run-config.md as KEY=VALUE (`--set filter.speed_window_s=0.1`), over
  /// the configuration file and under the named fields above; VALUE is YAML (`[1, 2, 1]`).
  std::vector<std::string> settings;
};

/// For settings where a leftover key cannot be meant (a command line, a study's run settings):
/// every warning of the reading is an InputError, "unknown key ignored" said as "unknown key".
WarningSink warnings_are_errors();

/// `settings` (KEY=VALUE each) read over `c` with the file's checks; InputError naming the
/// setting for a malformed one, an unknown key (and the closest known) or a value out of range.
void apply_run_settings(const std::vector<std::string>& settings, RunConfig& c);

/// The configuration file's settings (or the defaults) with `o` over them; InputError for
/// choices that exclude each other (modules with a configuration or chips) and for no dataset.
RunConfig run_config_with(const RunOverrides& o, const WarningSink& warn);

SpeedSharing speed_sharing_from_name(const std::string& name);
/// `auto`, `held`, `constraint` or `estimated` (docs/filter.md 13.4); InputError otherwise.
YawScaleFactorChoice yaw_scale_factors_from_name(const std::string& name);
/// `estimate` or `manifest` (run/calibration.hpp); InputError otherwise.
CalibrationMode calibration_mode_from_name(const std::string& name);
/// `equal` (the paper) or `covariance` (fusion/aids/position_constraint/reference_weights.hpp); InputError otherwise.
ReferenceWeighting weighting_from_name(const std::string& name);

/// Loads the manifest, resolves the modules and fills a RunRequest.
RunRequest make_run_request(const RunConfig& cfg, const WarningSink& warn);

}  // namespace wheelins
