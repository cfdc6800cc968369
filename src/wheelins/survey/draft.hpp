// A manifest drafted from what the data say (survey/dataset.hpp) for recordings that come
// without one (vendor CSV exports through `wheelins import`): every module's kind, axle
// axis and sign, clock offset, side and steering from the survey; the static period on the
// common clock; a Body-IMU's mounting from its up and forward axes; the reference track's
// clock. What the data cannot tell (the absolute wheel radius, the track, the wheelbase,
// the lever arms, the antenna) is written as a typical value of the vehicle type, marked
// TODO, and listed -- unless a calibrated manifest of the same vehicle is given, whose
// vehicle values (what belongs to the vehicle, not to one recording) are carried over.
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "wheelins/io/manifest.hpp"
#include "wheelins/io/manifest_draft.hpp"
#include "wheelins/survey/dataset.hpp"
#include "wheelins/survey/reference_clock.hpp"

namespace wheelins::survey {

/// Typical values of a vehicle type, written (as TODO) where the data cannot tell.
struct VehicleType {
  std::string name;          ///< "car", "robot"
  double wheel_radius = 0.3;
  double track = 1.5;
  double wheelbase = 2.6;
  Vec3 body_position = Vec3(1.3, 0.0, -0.6);
};
/// "car" (a passenger car) or "robot" (a Pioneer-3DX-sized robot); InputError otherwise.
VehicleType vehicle_type(const std::string& name);

struct DraftModule {
  std::string name;
  std::filesystem::path file;     ///< as the manifest is to name it (relative to its directory)
  FileLayout layout = FileLayout::kBinary;
  double rate_hz = 0.0;           ///< measured
  double input_offset = 0.0;      ///< the time offset the survey's data already had [s]
  double gyro_range = 0.0, accel_range = 0.0;  ///< the sensor's full scale (SI), 0 unknown
  std::string source;             ///< where the data came from (for the notes)
};

/// A module position the recording states (a ROS bag's /tf_static): written as it is, and
/// not listed as a TODO.
struct KnownPosition {
  Vec3 p_inV = Vec3::Zero();  ///< [m] in the v-frame (x forward, y right, z down)
  std::string source;         ///< where it was read, for the note ("/tf_static: base_link -> imu0")
};

struct DraftOptions {
  VehicleType vehicle = vehicle_type("car");
  bool vehicle_type_given = false;
  /// A manifest of the same vehicle (calibrated before): its vehicle values are used for
  /// modules of the same name, and its track, wheelbase and antenna.
  std::optional<Manifest> vehicle_from;
  std::optional<std::filesystem::path> truth_file;  ///< as the manifest is to name it
  std::optional<ReferenceClockFit> truth_clock;
  std::optional<earth::Geodetic> origin;            ///< the reference at the start
  /// Positions the recording states, by module name (they win over typical values; a
  /// left and a right wheel among them give the track).
  std::map<std::string, KnownPosition> known_positions;
  std::string name;
  std::string source;  ///< what was imported, for the header
  std::string tool = "wheelins import";  ///< what drafted it, for the header
};

/// The drafted manifest (paths as given), its TODO notes, facts and TODO list.
ManifestDraft draft_from_survey(const DatasetSurvey& survey, const std::vector<DraftModule>& modules,
                                const DraftOptions& options);

/// The draft of a directory of IMU files side by side (`wheelins manifest DIR` of several
/// <name>_imu.bin, and `wheelins import` of a ROS recording): `first` is the layout's draft
/// (io/manifest_draft.hpp: the files, rates, truth, odometer and start); the modules are
/// surveyed and drafted from what their data say (draft_from_survey), the truth, the
/// odometer and a heading read from the truth kept. `options.name`, `source`, `vehicle`
/// and `known_positions` are used; the truth and origin come from `first`. `report` (if
/// given) receives the survey.
ManifestDraft draft_from_files(const ManifestDraft& first, DraftOptions options, DatasetSurvey* report = nullptr);

}  // namespace wheelins::survey
