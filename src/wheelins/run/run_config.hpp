// The run configuration: which dataset, which IMUs, the filter settings and the
// outputs. YAML in human units (docs/run-config.md), converted once here; every
// setting has a default except the dataset.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "wheelins/run/run.hpp"

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

SpeedSharing speed_sharing_from_name(const std::string& name);
/// `auto`, `held`, `constraint` or `estimated` (docs/filter.md 13.4); InputError otherwise.
YawScaleFactorChoice yaw_scale_factors_from_name(const std::string& name);
/// `estimate` or `manifest` (run/calibration.hpp); InputError otherwise.
CalibrationMode calibration_mode_from_name(const std::string& name);
/// `equal` (the paper) or `covariance` (reference_weights.hpp); InputError otherwise.
ReferenceWeighting weighting_from_name(const std::string& name);

/// Loads the manifest, resolves the modules and fills a RunRequest.
RunRequest make_run_request(const RunConfig& cfg, const WarningSink& warn);

}  // namespace wheelins
