// Dataset manifest: which IMU modules a vehicle carries, where they sit, what
// their files hold and what noise a filter should assume for them.
//
// On disk it is YAML in human units (deg, deg/h, deg/sqrt(h), m/s/sqrt(h), ppm,
// hours); load_manifest() converts once into the SI values below, and
// save_manifest() writes human units back. See docs/manifest.md.
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "wheelins/io/diagnostics.hpp"
#include "wheelins/nav/earth.hpp"

namespace wheelins {

enum class ModuleKind { kWheel, kBody };
enum class SampleFormat { kRate, kIncrement };  ///< rad/s & m/s^2, or rad & m/s per sample
enum class FileLayout { kBinary, kText };       ///< float64 LE rows, or whitespace/CSV text

/// Noise figures a filter assumes for one IMU (SI: rad, s, m).
struct ImuNoise {
  double gyro_arw = 0.24 * kDeg / 60.0;   ///< angle random walk [rad/sqrt(s)]
  double acc_vrw = 0.3 / 60.0;            ///< velocity random walk [m/s/sqrt(s)]
  double gyro_bias_std = 50.0 * kDeg / 3600.0;  ///< residual gyro bias std [rad/s]
  double acc_bias_std = 0.01;             ///< residual accelerometer bias std [m/s^2]
  double gyro_sf_std = 3000e-6;           ///< residual gyro scale-factor std [-]
  double acc_sf_std = 3000e-6;            ///< residual accelerometer scale-factor std [-]
  double gyro_bias_tau = 3600.0;          ///< Gauss-Markov correlation times [s]
  double acc_bias_tau = 3600.0;
  double gyro_sf_tau = 3600.0;
  double acc_sf_tau = 3600.0;
};

/// One IMU module (one chip's data file).
struct ModuleSpec {
  std::string name;            ///< unique, e.g. "left-C1"
  ModuleKind kind = ModuleKind::kWheel;
  std::string group;           ///< physical module, e.g. "left-wheel" (its chips share it)
  std::string chip;            ///< e.g. "C1"
  std::filesystem::path file;  ///< absolute, or relative to the manifest's directory
  SampleFormat format = SampleFormat::kRate;
  FileLayout layout = FileLayout::kBinary;
  double rate_hz = 200.0;       ///< nominal sample rate
  double time_offset = 0.0;     ///< added to the file's timestamps [s]
  /// Wheel-IMU: the wheel centre in the v-frame. Body-IMU: the IMU centre in the v-frame. [m]
  Vec3 p_inV = Vec3::Zero();
  /// Wheel-IMU: lever arm from the IMU centre to the wheel centre in the b-frame [m].
  Vec3 lever_arm_inB = Vec3::Zero();
  /// Body-IMU: C_b^v as ZYX Euler [roll, pitch, yaw]. Wheel-IMU: the small rotation of the
  /// sensor axes from the ideal wheel b-frame (the paper's mounting angles). [rad]
  Vec3 mounting_rpy = Vec3::Zero();
  int axle_sign = 1;            ///< Wheel-IMU: +1 if b x-axis points right, -1 if left
  double wheel_radius = 0.0;    ///< Wheel-IMU nominal wheel radius [m]
  /// Gyro full scale [rad/s] (readings at it are saturated); 0 = not stated.
  double gyro_range = 0.0;
  /// Accelerometer full scale [m/s^2]; 0 = not stated. A reading beyond either range (+5 %)
  /// cannot come from the sensor: the run leaves it out as a fault.
  double accel_range = 0.0;
  ImuNoise noise;
};

struct Manifest {
  std::filesystem::path path;       ///< where it was loaded from (relative files resolve here)
  std::string name;
  std::optional<std::filesystem::path> truth_file;     ///< GINS.bin-style truth
  std::optional<std::filesystem::path> odometer_file;  ///< odo.bin
  double static_start = 0.0;        ///< static period for the initial alignment [s]
  double static_end = 0.0;
  earth::Geodetic origin;           ///< the w-frame origin (reference point o at the start)
  double initial_heading = 0.0;     ///< vehicle heading at the start [rad]
  std::optional<double> gravity;    ///< [m/s^2]; default: normal gravity at the origin
  bool earth_rotation = true;       ///< the data contain the earth rotation rate
  double track_width = 0.0;         ///< [m], informational
  std::vector<ModuleSpec> modules;

  /// Absolute path of a file named in the manifest.
  std::filesystem::path resolve(const std::filesystem::path& p) const;
  const ModuleSpec* find(const std::string& module_name) const;
  double gravity_or_default() const;
};

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
/// The YAML text save_manifest writes; relative paths are written for a manifest in `dir`.
std::string manifest_to_yaml(const Manifest& m, const std::filesystem::path& dir,
                             const ManifestAnnotations& notes = {});

/// Manifest text spellings of the enums ("wheel", "rate", "binary", ...).
const char* to_string(ModuleKind k);
const char* to_string(SampleFormat f);
const char* to_string(FileLayout l);

}  // namespace wheelins
