// A first manifest for a directory of recordings in one of the layouts the
// Wheel-INS datasets use (the engine behind `wheelins manifest DIR`):
//
//   single-IMU:  DIR/<name>_imu.bin (7 columns) + DIR/GINS.bin [+ DIR/odo.bin]
//   multi-IMU:   DIR/{body-imu,left-wheel-imu,right-wheel-imu}/tri_C1_imu.bin ... tri_C4_imu.bin
//                + DIR/ground_truth/GINS-body.bin (rows of 11 or 5 float64) [+ DIR/odo.bin]
//
// What the data tell is filled in: the files, each module's rate (median interval
// of the first records), the start time, the static period at the start (from the
// truth velocity, the odometer, or the wheel gyro), and the origin and heading from
// the truth record at the start. Geometry the data cannot tell (positions, lever
// arms, wheel radius, mounting angles, axle directions, track) gets a typical value
// and a "# TODO: measure" comment, and is listed in `todo`.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "wheelins/io/manifest.hpp"

namespace wheelins {

struct ManifestDraft {
  Manifest manifest;          ///< paths relative to the manifest file's directory
  ManifestAnnotations notes;  ///< the TODO comments (pass to save_manifest)
  std::string layout;         ///< "single-IMU" or "multi-IMU"
  std::vector<std::string> facts;  ///< what was read from the data, one line each
  std::vector<std::string> todo;   ///< what the user must still fill in, one line each
};

/// The time at which a Wheel-IMU file's gyro first shows the wheel rolling (0.5 rad/s),
/// scanning at most 900 s after t_from; nullopt if it does not within that.
std::optional<double> motion_from_wheel(const std::filesystem::path& file, double t_from);

/// Inspects `dir` and drafts a manifest meant to be written to `manifest_file`.
/// Throws InputError naming the directory when it matches neither layout, and the
/// file and record for unreadable data.
ManifestDraft draft_manifest(const std::filesystem::path& dir,
                             const std::filesystem::path& manifest_file);

}  // namespace wheelins
