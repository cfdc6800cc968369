// Dataset manifest: which IMU modules a vehicle carries, where they sit, what
// their files hold and what noise a filter should assume for them.
//
// On disk it is YAML in human units (deg, deg/h, deg/sqrt(h), m/s/sqrt(h), ppm,
// hours); load_manifest() converts once into the SI values below, and
// save_manifest() writes human units back. See docs/manifest.md.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "wheelins/io/diagnostics.hpp"
#include "wheelins/nav/earth.hpp"
#include "wheelins/nav/vehicle.hpp"

namespace wheelins {

enum class SampleFormat { kRate, kIncrement };  ///< rad/s & m/s^2, or rad & m/s per sample
enum class FileLayout { kBinary, kText };       ///< float64 LE rows, or whitespace/CSV text

/// What a manifest accepts for a module's geometry and sensor ranges (docs/manifest.md):
/// declared once, read by the manifest loader and by the simulator's settings check, so
/// `simulate` never writes a dataset that `run` refuses.
struct ManifestLimits {
  static constexpr double kPositionM = 20.0;        ///< |position_v_m| per axis [m]
  static constexpr double kWheelLeverArmM = 1.0;    ///< a wheel's |lever_arm_b_m| per axis [m]
  static constexpr double kBodyLeverArmM = 20.0;    ///< a body's |lever_arm_b_m| per axis [m]
  static constexpr double kGyroRangeMinDps = 10.0;  ///< gyro_range_dps [deg/s]
  static constexpr double kGyroRangeMaxDps = 1e5;
  static constexpr double kAccelRangeMin = 5.0;     ///< accel_range_m_s2 [m/s^2]
  static constexpr double kAccelRangeMax = 1e5;
  static constexpr double kYawScalePpm = 50000.0;   ///< |yaw_scale_ppm| (5 %)
};

/// One IMU module (one chip's data file): the module as the estimator knows it (name, kind,
/// rate, geometry, noise: ImuModule, nav/vehicle.hpp) and where and how its data are stored.
/// Which of ImuNoise's figures a manifest states, one bit per key of its `noise:` map in the
/// order of docs/manifest.md (gyro_arw, acc_vrw, gyro_bias, acc_bias, gyro_sf, acc_sf, the four
/// correlation times).
constexpr std::uint16_t kAllNoiseStated = 0x3FF;
enum NoiseKeyBit : std::uint16_t { kNoiseArw = 1, kNoiseVrw = 2, kNoiseGyroBias = 4, kNoiseAccBias = 8,
                                   kNoiseGyroSf = 16, kNoiseAccSf = 32 };

/// The velocity random walk a module is given when its manifest does not state one: a wheel
/// vibrates as it rolls (the noise identification starts from this and the data correct it,
/// docs/filter.md section 13; a figure too small makes the velocity updates push the sensor
/// errors away, one too large only slows the filter a little) [m/s/sqrt(s)].
constexpr double kDefaultWheelVrw = 3.0 / 60.0;
constexpr double kDefaultBodyVrw = 1.0 / 60.0;

struct ModuleSpec : ImuModule {
  /// The noise figures the manifest states (the others are defaults); save_manifest writes
  /// only these.
  std::uint16_t noise_stated = kAllNoiseStated;
  std::string group;           ///< physical module, e.g. "left-wheel" (its chips share it)
  std::string chip;            ///< e.g. "C1"
  std::filesystem::path file;  ///< absolute, or relative to the manifest's directory
  SampleFormat format = SampleFormat::kRate;
  FileLayout layout = FileLayout::kBinary;
  double time_offset = 0.0;     ///< added to the file's timestamps [s]
  /// Wheel: the radius that turns this IMU's raw axle rate into speed (a plain odometer,
  /// `wheelins odometry`), from a reference; 0: wheel_radius [m]. The filter's wheel_radius
  /// differs from it by the axle gyro's scale factor, which the filter estimates.
  double odometry_radius = 0.0;
};

/// Names a module cannot have: a run writes NAME.csv per module beside these files of its own.
inline constexpr const char* kReservedModuleNames[] = {"trajectory", "faults", "weights"};

struct Manifest {
  std::filesystem::path path;       ///< where it was loaded from (relative files resolve here)
  std::string name;
  std::optional<std::filesystem::path> truth_file;     ///< GINS.bin-style truth
  std::optional<std::filesystem::path> odometer_file;  ///< odo.bin
  double static_start = 0.0;        ///< static period for the initial alignment [s]
  double static_end = 0.0;
  earth::Geodetic origin;           ///< the w-frame origin (reference point o at the start)
  double initial_heading = 0.0;     ///< vehicle heading at the start [rad]
  /// False when `initial.heading_deg` is absent: the run starts in a local (odometry)
  /// frame with heading 0 and says so.
  bool heading_known = true;
  double truth_time_offset = 0.0;   ///< added to the truth file's times [s]
  std::optional<double> gravity;    ///< [m/s^2]; default: normal gravity at the origin
  bool earth_rotation = true;       ///< the data contain the earth rotation rate
  double track_width = 0.0;         ///< [m], informational
  double wheelbase = 0.0;           ///< [m], rear to front axle; 0 = unknown
  /// The reference's antenna (the point the truth positions are of) in the v-frame [m];
  /// none: the truth is of the reference point o itself.
  std::optional<Vec3> antenna_inV;
  std::vector<ModuleSpec> modules;

  /// Absolute path of a file named in the manifest.
  std::filesystem::path resolve(const std::filesystem::path& p) const;
  const ModuleSpec* find(const std::string& module_name) const;
  /// Every data file the manifest names (the modules' recordings, truth, odometer): inputs
  /// that no output of a command reading them may replace.
  std::vector<std::filesystem::path> input_files() const;
  double gravity_or_default() const;
  /// What the navigator is told (vehicle_setup()): a Manifest converts implicitly, so a
  /// Navigator is made straight from one.
  operator VehicleSetup() const;
};

/// The manifest without its files: every module's geometry and noise, the origin, the static
/// period, the initial heading and gravity (the default if not stated); the module files,
/// resolved, as the data sources named in messages.
VehicleSetup vehicle_setup(const Manifest& m);

/// Reads and validates a manifest; throws InputError naming the file and the key.
/// Warnings (unknown keys, with the closest known key) are printed on stderr.
Manifest load_manifest(const std::filesystem::path& file);
/// The same, with warnings sent to `warn` (nothing is printed; `warn` may be empty).
Manifest load_manifest(const std::filesystem::path& file, const WarningSink& warn);
/// Writes a manifest in human units (written to a temporary name, then moved into place).
/// Relative data-file paths are rewritten so that they still name the same files
/// when `file` is in another directory than `m.path`.
void save_manifest(const Manifest& m, const std::filesystem::path& file);

/// Extra comments for the YAML text: lines at the top, and end-of-line comments keyed
/// by key path ("initial.heading_deg", "modules[1].wheel_radius_m", "modules[1]").
struct ManifestAnnotations {
  std::vector<std::string> header;
  std::map<std::string, std::string> comments;
};
void save_manifest(const Manifest& m, const std::filesystem::path& file,
                   const ManifestAnnotations& notes);
/// The notes of a manifest file as save_manifest writes them: the header comment lines
/// (but the format line every manifest opens with) and each key's trailing comment, by key
/// path ("vehicle.track_m", "modules[1].wheel_radius_m"). Comments of keys written in
/// flow style or on lines of their own are not kept. Throws InputError if unreadable.
ManifestAnnotations read_manifest_notes(const std::filesystem::path& file);

/// The YAML text save_manifest writes; relative paths are written for a manifest in `dir`.
std::string manifest_to_yaml(const Manifest& m, const std::filesystem::path& dir,
                             const ManifestAnnotations& notes = {});

/// Manifest text spellings of the enums ("wheel", "rate", "binary", ...).
const char* to_string(ModuleKind k);
const char* to_string(SampleFormat f);
const char* to_string(FileLayout l);

}  // namespace wheelins
