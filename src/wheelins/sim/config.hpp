// Simulator settings: vehicle presets, error profiles, effect switches, and their
// YAML form (scenario.yaml holds every setting; feeding it back with --config
// reproduces the dataset byte for byte).
//
// Every number of the profiles is documented in docs/simulator.md.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "wheelins/nav/earth.hpp"
#include "wheelins/sim/faults.hpp"

namespace YAML {
class Node;
}

namespace wheelins::sim {

/// The effects, each with its own switch. Datasheet: sensor errors and the rolling radius;
/// field adds the physical effects below `radius`; the last ones are in no profile (switched
/// on by an option, `--only` or the `effects` key).
inline const std::vector<std::string>& all_effects() {
  static const std::vector<std::string> e = {
      "gyro_bias", "gyro_gm", "arw", "accel_bias", "accel_gm", "vrw", "scale_factor",
      "misalignment", "quantization", "saturation", "radius",
      // field only
      "temperature", "vibration", "slip", "skid", "time_offset", "calibration",
      // in no profile
      "wheel_noise"};
  return e;
}
/// How many of all_effects() the field profile has (the rest are options).
constexpr std::size_t kFieldEffects = 17;
/// The effects a profile ("ideal", "datasheet", "field") switches on.
std::set<std::string> profile_effects(const std::string& profile);

/// Error-model parameters in SI units (docs/simulator.md lists them in datasheet units).
struct ErrorParams {
  // gyroscope, per axis and chip
  double gyro_bias = 200.0 * kDeg / 3600.0;     ///< turn-on bias sigma [rad/s]
  double gyro_gm_sigma = 20.0 * kDeg / 3600.0;  ///< in-run Gauss-Markov sigma [rad/s]
  double gyro_gm_tau = 3600.0;                  ///< [s]
  double gyro_arw = 0.24 * kDeg / 60.0;         ///< [rad/sqrt(s)]
  double gyro_sf = 1000e-6;                     ///< scale-factor sigma [-]
  double gyro_misalign = 0.05 * kDeg;           ///< off-diagonal axis misalignment sigma [rad]
  double gyro_lsb = (1.0 / 16.4) * kDeg;        ///< quantization step [rad/s]
  double gyro_range = 2000.0 * kDeg;            ///< saturation [rad/s]
  double gyro_tempco = 3.0 * kDeg / 3600.0;     ///< bias temperature coefficient sigma [rad/s/K]
  // accelerometer
  double accel_bias = 0.01;                     ///< turn-on bias sigma [m/s^2]
  double accel_gm_sigma = 0.002;                ///< [m/s^2]
  double accel_gm_tau = 3600.0;                 ///< [s]
  double accel_vrw = 0.3 / 60.0;                ///< [m/s/sqrt(s)]
  double accel_sf = 1000e-6;
  double accel_misalign = 0.05 * kDeg;
  double accel_lsb = 16.0 * 9.80665 / 32768.0;  ///< [m/s^2]
  double accel_range = 16.0 * 9.80665;          ///< [m/s^2]
  double accel_tempco = 0.2e-3 * 9.80665;       ///< bias temperature coefficient sigma [m/s^2/K]
  // temperature: each module warms by rise (x (1 + N(0, 0.2))) with time constant tau
  double temp_rise = 10.0;   ///< [K]
  double temp_tau = 300.0;   ///< [s]
  // wheel
  double radius_rel = 0.002;  ///< effective rolling radius sigma, relative [-]
  double slip_coeff = 0.04;   ///< longitudinal slip per longitudinal acceleration [s^2/m]
  double skid_coeff = 0.06;   ///< lateral skid velocity per lateral acceleration [s]
  /// The vehicle's slip angle per lateral acceleration [rad/(m/s^2)], a tyre's law (0: none,
  /// every profile; with the `skid` effect, added to skid_coeff's).
  double skid_angle = 0.0;
  // vibration (per-axis RMS in the v-frame: x, y, z); band [Hz]
  Vec3 vib_body_accel{0.2, 0.2, 0.4};         ///< [m/s^2]
  Vec3 vib_body_rate{0.8 * kDeg, 0.8 * kDeg, 0.4 * kDeg};   ///< [rad/s]
  Vec3 vib_wheel_accel{0.9, 0.7, 1.6};
  Vec3 vib_wheel_rate{1.5 * kDeg, 2.0 * kDeg, 1.0 * kDeg};
  double vib_body_band[2] = {5.0, 40.0};
  double vib_wheel_band[2] = {8.0, 60.0};
  // clocks
  double time_offset = 0.003;  ///< per-module clock offset sigma [s]
  // white accelerometer noise of the Wheel-IMUs from rolling vibration (effect wheel_noise)
  double wheel_accel_noise = 1.0 / 60.0;  ///< density in motion at the cruise speed [m/s/sqrt(s)]
  double wheel_accel_noise_rest = 0.0;    ///< fraction of it at rest [-]
  // calibration residuals of the manifest geometry
  double cal_lever_arm = 0.003;      ///< [m]
  double cal_mounting = 0.3 * kDeg;  ///< [rad]
  double cal_position = 0.01;        ///< [m]
  double cal_radius_rel = 0.003;     ///< [-]
};

/// The error parameters of a profile ("ideal", "datasheet", "field"): the defaults above,
/// with the field profile's gyro scale factor raised to 3000 ppm. InputError for another name.
ErrorParams profile_errors(const std::string& profile);

/// One physical module (a group of four chips).
struct ModuleGeometry {
  std::string group;            ///< "left-wheel", "right-wheel", "body", "front-left-wheel", ...
  bool wheel = true;
  /// A steered wheel (preset car-steered): it turns about the vehicle's z through its centre
  /// by the Ackermann angle of the path's curvature (docs/simulator.md); p_inV.x is its distance
  /// ahead of o, the mid rear axle.
  bool steered = false;
  Vec3 p_inV = Vec3::Zero();    ///< wheel centre (wheel) / IMU centre (body) [m]
  Vec3 lever_arm_inB = Vec3::Zero();  ///< wheel: IMU centre -> wheel centre, b-frame [m]
  Vec3 mounting_rpy = Vec3::Zero();   ///< wheel: C_s^b; body: C_b^v (ZYX Euler) [rad]
};

struct VehicleConfig {
  std::string preset = "robot";
  double wheel_radius = 0.097;  ///< nominal [m]
  double track = 0.33;          ///< [m]
  /// Rear to front axle [m]; 0: not stated (robot, car). The steered wheels' x and the arc of
  /// a start with the wheels turned (SimConfig::start_steering_deg) follow it.
  double wheelbase = 0.0;
  ModuleGeometry left, right, body;
  /// The steered front wheels (car-steered: front-left-wheel, front-right-wheel), else empty.
  std::vector<ModuleGeometry> front;
  /// Wheel centres at (0, -/+ track/2, 0) (front wheels: (wheelbase, -/+ track/2, 0)) unless
  /// overridden. Presets: robot, car, car-steered (the car with two steered front Wheel-IMUs).
  static VehicleConfig preset_named(const std::string& name);
  /// Every module in group order: left, right, body, then the front wheels.
  std::vector<const ModuleGeometry*> modules() const;
  std::vector<ModuleGeometry*> mutable_modules();
  /// The car's scenario defaults (speed, size, smoothing) apply: presets car and car-steered.
  bool car() const { return preset == "car" || preset == "car-steered"; }
};

struct SimConfig {
  std::string scenario = "default";  ///< "default" or a .kml/.csv path
  std::optional<std::filesystem::path> speed_file;
  std::string profile = "field";
  std::set<std::string> effects = profile_effects("field");
  std::uint64_t seed = 1;
  std::optional<double> duration;  ///< [s] from the start; default: the whole scenario
  double rate_hz = 200.0;
  int chips = 4;
  /// Also write the error-free streams (ideal/, manifest-ideal.yaml). An output choice,
  /// not a setting of the data: not in scenario.yaml.
  bool write_ideal = true;
  double gps_week = 2200;
  bool earth_rotation = true;
  VehicleConfig vehicle = VehicleConfig::preset_named("robot");
  ErrorParams errors = profile_errors("field");
  // scenario shape
  double static_duration = 30.0;
  int laps = 5;
  std::optional<double> speed;         ///< cruise speed; default 1.4 m/s (robot), 6 m/s (car)
  std::optional<double> loop_scale;    ///< default scenario size; default 1 (robot), 4 (car)
  bool stops = true;
  double stop_s = 15.0;                 ///< each stop of the default scenario [s] (~7 s less at rest)
  std::optional<double> path_sigma;     ///< default: 2.0 m (default scenario), 0.7 m (files)
  std::optional<double> speed_sigma;    ///< default: 1.2 s / 0.5 s
  double terrain_slope_deg = 0.0;       ///< 0: flat
  /// A start with the wheels turned: the vehicle starts at rest on an arc of curvature
  /// tan(D) / wheelbase (positive D: a right turn), so the Ackermann angle of the front axle's
  /// centre is D [deg]; 0: the scenario as without it (default scenario only).
  double start_steering_deg = 0.0;
  std::optional<double> start_time;     ///< default 100000.0 (ignored with a speed file)
  std::optional<earth::Geodetic> origin;
  /// Sensor-fault events (sim/faults.hpp), in the order given; times in seconds since the
  /// start of the data. The YAML key `faults` replaces the list; `--fault` appends to it.
  std::vector<FaultEvent> faults;
  /// Module group -> the group whose random draws it takes: the module's own (true radius,
  /// clock offset, temperature rise, vibration, calibration residuals) and its chips' error
  /// parameters (biases, scale factors, misalignments, temperature coefficients), chip by
  /// chip: the same wheel and chips in another place, for a comparison paired on them (key
  /// `draws_from`; e.g. front-left-wheel: left-wheel). The white noise and the bias
  /// processes stay the chips' own.
  std::map<std::string, std::string> draws_from;

  bool on(const std::string& effect) const { return effects.count(effect) > 0; }
  /// Sets a profile: its parameters (field: gyro scale factor 3000 ppm) and its effects.
  void set_profile(const std::string& name);
  /// Removes / restricts effects (names checked: InputError for unknown ones).
  void disable(const std::vector<std::string>& names);
  void only(const std::vector<std::string>& names);
  /// Where a dotted key of a YAML map came from, appended to messages about it (e.g. a
  /// study's " (sweep.seed, line 7)"); none: the messages name `where` and the key.
  using KeyOrigin = std::function<std::string(const std::string& key)>;
  /// Applies the keys present in a YAML map (the scenario.yaml format), `where` names it;
  /// a value of the wrong type is an InputError naming `where`, the key and the value.
  void apply_yaml(const YAML::Node& node, const std::string& where, const KeyOrigin& key_origin = {});
  /// Applies "a.b.c=value" (value parsed as YAML).
  void apply_setting(const std::string& assignment);
  /// Every number in its range (docs/simulator.md); InputError naming the setting and its
  /// command-line option. The Simulation constructor calls it.
  void validate() const;
  /// draws_from names modules of the vehicle of the same kind (wheel or body), none its own
  /// and none a copy itself.
  void check_draws_from() const;
  /// The complete settings as YAML text (the scenario.yaml format).
  std::string to_yaml() const;
};

}  // namespace wheelins::sim
