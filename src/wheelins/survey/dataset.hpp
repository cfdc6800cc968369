// What a set of IMU recordings says about the vehicle and its modules when nothing is
// believed but the physics (the engine behind `wheelins import`'s drafted manifest and
// `wheelins run`'s checks of a manifest against its data):
//
//  * kind: a module whose rotation is carried by one sensor axis, fast (a 95th percentile
//    over 2 rad/s in motion), is a Wheel-IMU; any other a Body-IMU (survey/traits.hpp);
//  * axle axis: that sensor axis; axle sign: which way of turning about it is forward --
//    a vehicle drives forward most of its way, and rolling forward turns a wheel
//    negatively about an axis pointing to the vehicle's right (x forward, y right, z down);
//  * clocks: the offset of each module's clock to the reference module's (the first Body-
//    IMU, else the first Wheel-IMU), from the wheels' spin rates against each other and
//    from the yaw rate about the vertical against the best-matching wheel (survey/clock.hpp);
//  * side: a wheel on the right turns faster in a left turn than one on the left, by
//    track * yaw rate (every pair of wheels votes);
//  * steering: a steered wheel's yaw rate is the vehicle's plus the steering rate: it leads
//    the vehicle's (the driver steers before the vehicle turns) and departs from it far more
//    than an unsteered wheel's does (needs a Body-IMU for the vehicle's yaw rate);
//  * a body's axes: its specific force follows the wheels' acceleration along the vehicle's
//    forward axis and speed times yaw rate along its left axis (the centripetal acceleration);
//    its roll and pitch on the vehicle from the drive: the vertical specific force does not
//    follow the horizontal (survey/level.hpp; the up-axis at rest holds the ground's tilt);
//  * the static period: the first interval in which every module rests, on the common
//    clock: every wheel's spin rate at its bias, and every body's rate and specific force
//    as quiet as they get (an idling engine's shaking can keep a body from ever being
//    that quiet while the wheels rest: then the wheels' rest, said so).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "wheelins/io/imu_file.hpp"
#include "wheelins/nav/vehicle.hpp"
#include "wheelins/survey/clock.hpp"
#include "wheelins/survey/level.hpp"
#include "wheelins/survey/traits.hpp"

namespace wheelins::survey {

struct ModuleInput {
  std::string name;
  std::filesystem::path file;
  ImuReadOptions read;  ///< the time offset in it is applied before anything is compared
  double gyro_limit = 0.0, accel_limit = 0.0;  ///< the sensor's range (+5 %); 0: the defaults
};

struct SurveyOptions {
  SeriesOptions series;
  TraitOptions traits;
  ClockOptions clock;
  LevelFitOptions level;
  double min_static = 2.0;       ///< [s] shortest static period drafted
  double static_margin = 0.3;    ///< [s] taken off both ends of the common rest
  /// Wheels known to steer (a manifest's steered: true): their yaw rate leads the vehicle's,
  /// so no body's clock is tied through it.
  std::vector<std::string> steered;
  double steering_ratio = 0.5;   ///< yaw departure (rms, over the vehicle's rms yaw rate) of a steered wheel
  double steering_lead = 0.2;    ///< [s] a steered wheel's yaw rate leads the vehicle's by more
  double min_turning = 0.03;     ///< [rad/s] rms yaw rate of the vehicle below which steering is not judged
  double min_forward = 0.5;      ///< |spin direction| below this: the way forward is not clear
  double min_clock_correlation = 0.5;  ///< a clock fit below this correlation is not taken
};

struct ModuleFinding {
  std::string module;
  ModuleTraits traits;
  ModuleKind kind = ModuleKind::kBody;
  int axle_axis = 0;     ///< wheels: the spin axis
  int axle_sign = 1;     ///< wheels: +1 the axle axis points right (forward rolling is negative)
  bool forward_clear = false;  ///< wheels: the way forward is clear (|spin_direction| >= min_forward)
  /// Offset of this module's clock to the reference module's [s]: add it to the module's
  /// times (already including the input's time offset, i.e. the new time_offset_s is the
  /// input's + this).
  ClockFit clock;
  bool clock_reference = false;
  /// A body whose clock is tied to the wheels' only by the size of an acceleration (no
  /// turns): good enough for the survey's own comparisons, too coarse to judge a manifest's
  /// offsets by (survey/checks.cpp leaves such a body's clock against the wheels' out).
  bool clock_weak = false;
  std::string clock_basis;  ///< what the clock was fitted on ("spin rate vs IMU4", ...)
  int side = 0;             ///< wheels: +1 right, -1 left, 0 not determined
  double side_evidence = 0.0;
  bool steered = false;     ///< wheels: departs from the vehicle's yaw like a steered wheel
  double yaw_departure = 0.0;  ///< rms(yaw - vehicle yaw) / rms(vehicle yaw); NaN if unknown
  double yaw_lead = 0.0;       ///< [s] how much the wheel's yaw rate leads the vehicle's; NaN if unknown
  double start = 0.0, end = 0.0;  ///< data span on the common clock [s]
  double input_start = 0.0, input_end = 0.0;  ///< data span with the input's time offset only [s]
  /// Bodies: the vehicle's forward and left axes in sensor axes, from the specific force
  /// against the wheels' acceleration (forward) and speed times yaw rate (left, centripetal
  /// in a turn); `axes_found` when both fits correlate.
  bool axes_found = false;
  Vec3 forward = Vec3::UnitX(), left = Vec3::UnitY();
  double forward_fit = 0.0, left_fit = 0.0;  ///< correlation of each fit
  /// Bodies with their axes found: the vehicle's up axis from the drive (survey/level.hpp),
  /// free of the ground's tilt where the vehicle stood (which `traits.up` holds).
  LevelFit level;
};

struct DatasetSurvey {
  std::vector<ModuleFinding> modules;
  std::optional<Interval> static_period;  ///< on the common clock
  /// The bodies are quiet in the static period too (false: only the wheels rest there).
  bool static_bodies_quiet = true;
  std::vector<std::string> notes;         ///< what was found and why, one line each
  const ModuleFinding* find(const std::string& name) const;
};

/// What the static period was found on, in words.
std::string static_period_basis(const DatasetSurvey& survey);

/// A readable table: per module its kind, axle axis and the way forward, side, steering and
/// clock offset, and the static period.
std::string survey_report(const DatasetSurvey& survey);

/// Reads the modules' files (bounded, survey/series.hpp) and surveys them.
DatasetSurvey survey_modules(const std::vector<ModuleInput>& modules, const SurveyOptions& options = {});

/// The same on series already read (their times including the inputs' offsets).
DatasetSurvey survey_series(const std::vector<Series>& series, const SurveyOptions& options = {});

}  // namespace wheelins::survey
