// The installation calibration pass of a run (docs/filter.md section 15): every selected
// module's file read once through the input checks into a WheelImuCalibrator, the
// manifest refined with the estimates, and the estimates as text (calibration.yaml and a
// table).
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "wheelins/calib/installation_calibration.hpp"
#include "wheelins/io/diagnostics.hpp"
#include "wheelins/io/manifest.hpp"

namespace wheelins {

/// How a run treats the installation geometry of its Wheel-IMUs.
enum class CalibrationMode {
  kEstimate,  ///< estimated from the data before navigating (the default)
  kManifest,  ///< the manifest's values as they are
};

/// The estimates of a run's modules.
struct InstallationCalibration {
  std::vector<WheelImuCalibration> wheels;  ///< in the order of the run's modules
  std::vector<BodyImuCalibration> bodies;
  bool empty() const { return wheels.empty() && bodies.empty(); }
};

/// The estimators of a run's modules (a WheelImuCalibrator per Wheel-IMU, a
/// BodyImuCalibrator per Body-IMU), fed sample by sample.
class ModuleCalibrators {
 public:
  /// `expected_end`: per module, the time of its last sample if known (0: unknown; the
  /// relative-radius series is reserved up to it). Throws InputError for an unknown name.
  ModuleCalibrators(const Manifest& m, const std::vector<std::string>& modules,
                    const InstallationCalibrationOptions& opt, const std::vector<double>& expected_end = {});
  ~ModuleCalibrators();
  ModuleCalibrators(ModuleCalibrators&&) noexcept;
  ModuleCalibrators& operator=(ModuleCalibrators&&) noexcept;
  /// One sample of module `index` (its position in `modules`; sensor axes, as checked input).
  void add(int index, const ImuSample& s);
  /// The estimates from the samples so far, the relative radius included.
  InstallationCalibration result() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The calibration of a stream that is seen once (the Python Navigator): the samples up to
/// `static_end + warmup_s` are kept and fed to the estimators; at the first sample after that
/// (or at the end of the data) the caller takes result() and navigates the kept samples with
/// it, then the rest as they come. The estimates are calibrate_installation()'s with
/// t_end = static_end + warmup_s, from the same samples.
class CalibrationWarmup {
 public:
  CalibrationWarmup(const Manifest& m, const std::vector<std::string>& modules,
                    const InstallationCalibrationOptions& opt, double warmup_s);
  /// The last time the estimators take [s].
  double end() const { return t_end_; }
  /// Keeps sample `s` of module `index` (`record`: its index in its source, for messages);
  /// false (nothing kept) when it is past end().
  bool add(int index, const ImuSample& s, std::uint64_t record = 0);
  InstallationCalibration result() const { return cals_.result(); }
  struct Kept {
    int index;
    ImuSample sample;
    std::uint64_t record;
  };
  /// The kept samples in the order given.
  const std::vector<Kept>& kept() const { return kept_; }
  /// Frees the kept samples.
  void release() { std::vector<Kept>().swap(kept_); }

 private:
  double t_end_;
  ModuleCalibrators cals_;
  std::vector<Kept> kept_;
};

/// Reads the modules among `modules` and returns their estimates (Wheel-IMUs: axle, lever
/// arm, relative radius; Body-IMUs: mounting); samples after `t_end` are not used.
InstallationCalibration calibrate_installation(
    const Manifest& m, const std::vector<std::string>& modules,
    const InstallationCalibrationOptions& opt, bool isolate_faults, bool progress,
    double t_end = std::numeric_limits<double>::infinity());

/// What a calibration did with one value of the manifest. One list of these is what the
/// console table, calibration.yaml and the refined manifest's notes all say.
enum class CalibrationOutcome {
  kEstimated,     ///< the data determine it (1 sigma below half the prior's): the estimate is used
  kWeak,          ///< the data moved it without determining it: the estimate, drawn towards the manifest's value, is used
  kKept,          ///< no information in the data: the manifest's value is kept
  kNotEstimable,  ///< not estimated by design (a Wheel-IMU's roll and lever arm x, a body's height): the manifest's, re-expressed in the calibrated axes
};
/// "estimated", "weak", "kept", "not estimable".
const char* to_string(CalibrationOutcome o);

struct CalibrationDecision {
  std::string module;
  std::string key;      ///< the manifest key: mounting_deg, lever_arm_b_m, wheel_radius_m, position_v_m
  int component = -1;   ///< 0..2 of a vector key, -1 a scalar
  CalibrationOutcome outcome = CalibrationOutcome::kKept;
  /// The value only matters to navigation through others (a Wheel-IMU's roll about the axle
  /// and lever arm along it): never a TODO.
  bool without_effect = false;
  bool relative = false;  ///< a wheel radius relative to the other side's (the absolute one is not observable)
};

/// Every calibrated value of `cal`, module by module, key by key, component by component.
std::vector<CalibrationDecision> calibration_decisions(const InstallationCalibration& cal);

/// The manifest with each calibrated module's mounting, lever arm and radius replaced by
/// what calibration_decisions() says is used: the estimate where estimated or weak (a weak
/// one is drawn towards the manifest's value by its prior), the manifest's where kept.
Manifest apply_calibration(Manifest m, const InstallationCalibration& cal);

/// The notes of the refined manifest: `input` (the input manifest's, read_manifest_notes())
/// with every calibrated key's note saying, from calibration_decisions(), what was
/// estimated, what was kept and what is still a guess: a key the input marked TODO stays
/// TODO while any part of it that matters was not estimated; a wheel radius (relative only)
/// stays TODO unless measured (`reference_measured`: the wheels whose absolute radius a
/// reference measured).
ManifestAnnotations calibration_notes(const Manifest& m, const InstallationCalibration& cal, ManifestAnnotations input,
                                      const std::vector<std::string>& reference_measured = {});

/// calibration.yaml: per module the estimates, their 1 sigma, the manifest values and
/// whether the data determined them, in the manifest's keys and units.
std::string calibration_yaml(const InstallationCalibration& cal, const Manifest& m);

/// A readable table of the same.
std::string calibration_report(const InstallationCalibration& cal);

}  // namespace wheelins
