// Every setting of a run configuration (docs/run-config.md), declared once: its key, its range
// and unit, how the file's number becomes the filters' value, the command-line option that sets
// it too, its default (the RunConfig's own) and what it means. Reading the YAML file (keys,
// types, ranges, the checks of a whole section), the documentation's table of settings, the
// listing of `wheelins run -v`, and the named options of `wheelins run` and `wheelins live` and
// Python's keywords walk this one list: a setting added here is read, checked, documented,
// listed and, with a `cli` text, an option and a keyword.
//
// declare_run_options(v, c) calls one method of the visitor `v` per setting, in the order of
// the file (the top-level keys, output, filter, fusion, noise, standstill, faults):
//   v.number(info, x, range[, scale[, also]])   a number; the field holds the file's value
//                                               converted by `scale`; `also`: a second field
//                                               set to the same value
//   v.rate(info, interval, range)               a rate in Hz; the field holds its interval 1/Hz
//   v.whole(info, n, lo, hi)                    a whole number
//   v.vec3(info, x, range)                      three numbers, each in the range
//   v.flag(info, b)                             true / false
//   v.path(info, p, required, default_text)     a path, relative to the file's folder
//   v.choice(info, e, names)                    one of named values
//   v.custom(info, range_text, show, read)
//                                               its own reading: read(y, node, c, base) with the
//                                               YamlReader, the key's node, the configuration
//                                               and the file's folder; show(c): its value as
//                                               text (the documentation's default is show's
//                                               of the defaults)
//   v.section_check(section, check)             a check of a whole section once it is read
//                                               (check(c) throws InputError)
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "wheelins/run/presets.hpp"
#include "wheelins/run/run_config.hpp"

namespace wheelins {

/// What every declared setting has.
struct OptionInfo {
  const char* key;   ///< dotted from the top of the file: "fusion.position_std_m"
  const char* help;  ///< what it sets (the documentation's table)
  const char* cli;   ///< the command-line option that sets it too ("" if none)
};

/// A number's range and unit, as the errors and the documentation print them.
struct OptionRange {
  double lo, hi;
  const char* unit;  ///< "m", "s (0 = every epoch)", ""
};

/// How the file's number becomes the field's value: times `mul`, then divided by `div` (in that
/// order, so that a value converts as it always has, to the bit).
struct OptionScale {
  double mul = 1.0, div = 1.0;
};
inline constexpr OptionScale kDegrees{kDeg, 1.0};

template <class E>
using OptionChoices = std::vector<std::pair<std::string, E>>;

/// A custom setting's value as text (run_options_listing, the documentation's default).
using OptionShow = std::string (*)(const RunConfig&);
/// A number as the documentation and the listing write it: 10⁻⁴, 10⁶, or printf's %g.
std::string option_number(double x);
/// "a, b, c".
std::string option_list(const std::vector<std::string>& items);

/// The named choices shared by the file and the command line (run_config.cpp's *_from_name).
const OptionChoices<SpeedSharing>& speed_sharing_choices();
const OptionChoices<YawScaleFactorChoice>& yaw_scale_factor_choices();
const OptionChoices<CalibrationMode>& calibration_mode_choices();

/// The declared range of the number setting `key` ("output.interval_s"), for the checks of a
/// value that comes from elsewhere than the file (a command-line option, a RunRequest built in
/// code); std::logic_error for a key that is not a declared number.
OptionRange run_option_range(const std::string& key);

/// The documentation's table of every setting (docs/run-config.md, "Settings"): key, option,
/// range, default, meaning; a test keeps the documentation equal to it.
std::string run_options_markdown();

/// Every setting of `c` as `wheelins run -v` lists it: key, value (and unit), and the default
/// where the value is another.
std::string run_options_listing(const RunConfig& c);

/// A front end's named option over one declared setting, made from the declaration's `cli`
/// text: `wheelins run`'s and `wheelins live`'s options, Python's keywords. The text is the
/// option's names (CLI11's "--out,-o") and, for an option that takes no value, what it sets:
/// "(off)" false, "(= 0)" that value; a flag setting without either sets true.
struct NamedOption {
  std::string names;    ///< "--no-position-constraint", "--out,-o"
  std::string option;   ///< the long name: "--out"
  std::string keyword;  ///< Python's: "out"; "position_constraint" for "--no-position-constraint"
  std::string key;      ///< the setting: "fusion.position_constraint"
  std::string help;     ///< the declaration's, with its range and default
  std::string sets;     ///< an option without a value: what it sets ("false", "0"); empty: a value
  bool path = false;    ///< a path: its value never split at commas
  /// The setting's value for Python's keyword given True or False (an option without a value):
  /// position_constraint=False sets false, fixed_noise=True false, full_rate=False nothing.
  std::optional<std::string> keyword_value(bool given) const;
};

/// Every setting that has a front end's option, in the order of the file.
const std::vector<NamedOption>& run_named_options();
/// The named option with this long name ("--duration") or keyword ("duration"); nullptr if none.
const NamedOption* find_named_option(const std::string& name);

/// The top-level keys.
template <class V>
void declare_selection_options(V& v, RunConfig& c) {
  v.path({"dataset", "the dataset manifest (relative to this file)", "--manifest,-m"}, c.manifest, true,
         "required");
  v.custom({"configuration", "which IMUs: a configuration of the dataset's chips", "--configuration,-c"},
           "single, single-right, dual-wheel, body-wheel, triple, ...", [](const RunConfig& r) { return r.configuration; },
           [](const auto& y, const auto& n, RunConfig& r, const auto&) {
             r.configuration = y.text(n, "configuration");
             bool known = r.configuration == "single-right";
             for (const auto& name : configuration_names()) known = known || name == r.configuration;
             if (!known) y.fail("configuration", "unknown configuration '" + r.configuration + "'", &n);
             r.modules.clear();  // over modules given before (a file's, under --configuration)
           });
  v.custom({"chips", "one chip per IMU of the configuration (left, right, body order)", "--chips"}, "a list",
           [](const RunConfig& r) { return r.chips.empty() ? "the configuration's first chips" : option_list(r.chips); },
           [](const auto& y, const auto& n, RunConfig& r, const auto&) { r.chips = y.text_list(n, "chips"); });
  v.custom({"modules", "the modules by name, instead of a configuration", "--modules"}, "a list",
           [](const RunConfig& r) { return r.modules.empty() ? "none" : option_list(r.modules); },
           [](const auto& y, const auto& n, RunConfig& r, const auto&) { r.modules = y.text_list(n, "modules"); });
  v.custom({"duration_s", "stop after this much navigation", "--duration"}, "(0, 10⁷] s",
           [](const RunConfig& r) { return r.max_duration > 0 ? option_number(r.max_duration) : "all the data"; },
           [](const auto& y, const auto& n, RunConfig& r, const auto&) {
             r.max_duration = y.number_in(n, "duration_s", 0.0, 1e7, "s");
             if (r.max_duration <= 0) y.fail("duration_s", "must be > 0 s (leave it out for all the data)", &n);
           });
  v.flag({"data_checks", "the manifest held against its data before the run", "--no-data-checks (off)"},
         c.data_checks);
  v.choice({"calibration",
            "the installation (axle, lever arms, wheel radii, Body-IMU mounting) estimated from the data "
            "(docs/filter.md section 15), or as the manifest says",
            "--calibration"},
           c.calibration, calibration_mode_choices());
}

/// output: what is written where.
template <class V>
void declare_output_options(V& v, RunConfig& c) {
  v.path({"output.dir", "the results directory (relative to this file)", "--out,-o"}, c.output_dir, false,
         "results/CONFIGURATION[-chips]");
  v.custom({"output.formats", "the trajectory files", "--formats"}, "csv, tum, kml (a list)",
           [](const RunConfig& r) {
             std::vector<std::string> names;
             for (const TrajectoryFormat f : r.formats) names.emplace_back(trajectory_format_name(f));
             return "[" + option_list(names) + "]";
           },
           [](const auto& y, const auto& n, RunConfig& r, const auto&) {
             r.formats.clear();
             for (const auto& f : y.text_list(n, "output.formats")) {
               if (f != "csv" && f != "tum" && f != "kml")
                 y.fail("output.formats", "unknown format '" + f + "' (csv, tum or kml)", &n);
               r.formats.push_back(trajectory_format_from_name(f));
             }
           });
  v.custom({"output.tum_frame",
            "trajectory.tum in ned (x north, y east, z down) or enu (x east, y north, z up: ROS, evo)",
            "--tum-frame"},
           "ned or enu", [](const RunConfig& r) { return std::string(r.tum_frame == TumFrame::kEnu ? "enu" : "ned"); },
           [](const auto& y, const auto& n, RunConfig& r, const auto&) {
             const std::string f = y.text(n, "output.tum_frame");
             if (f != "ned" && f != "enu") y.fail("output.tum_frame", "'" + f + "': expected ned or enu", &n);
             r.tum_frame = tum_frame_from_name(f);
           });
  v.number({"output.interval_s",
            "the navigator's records (the evaluation is computed on these; it interpolates across at "
            "most 5 s)",
            "--output-interval"},
           c.nav.output_interval, {0.0, 5.0, "s (0 = every epoch)"});
  v.number({"output.file_interval_s", "the records written to the trajectory files (and the last one)",
            "--full-rate (= 0)"},
           c.file_interval, {0.0, 5.0, "s (0 = every record)"});
  v.flag({"output.overwrite", "replace earlier results (only the files wheelins wrote)", "--force,-f"}, c.overwrite);
  v.flag({"output.subsystems", "also MODULE.csv for each subsystem", "--subsystems"}, c.write_subsystems);
}

/// filter: each subsystem's EKF.
template <class V>
void declare_filter_options(V& v, RunConfig& c) {
  NavigatorOptions& n = c.nav;
  v.flag({"filter.estimate_axle_accel_scale_factors",
          "a Wheel-IMU's axle accelerometer's scale factor estimated (else held; docs/filter.md 13.4)", ""},
         n.wheel.estimate_axle_accel_scale_factor);
  v.choice({"filter.yaw_scale_factors",
            "auto: from the position constraint alone when it takes in a Body-IMU, else held at 0 | held | "
            "constraint | estimated (docs/filter.md 13.4)",
            "--yaw-scale-factors"},
           n.yaw_scale_factors, yaw_scale_factor_choices());
  v.custom({"filter.estimate_yaw_scale_factors", "the older spelling: true = estimated, false = held (not with "
            "filter.yaw_scale_factors)", ""},
           "true or false", [](const RunConfig&) { return std::string("not given"); },
           [](const auto& y, const auto& node, RunConfig& r, const auto&) {
             if (y.get(y.get(y.root(), "filter"), "yaw_scale_factors").IsDefined())
               y.fail("filter.estimate_yaw_scale_factors",
                      "conflicts with filter.yaw_scale_factors (give only the latter)", &node);
             r.nav.yaw_scale_factors = y.boolean(node, "filter.estimate_yaw_scale_factors")
                                           ? YawScaleFactorChoice::kEstimated
                                           : YawScaleFactorChoice::kHeld;
           });
  v.choice({"filter.mechanization", "the strapdown integration: rotation-exact, or classic two-sample "
            "coning/sculling", ""},
           n.mechanization,
           OptionChoices<MechanizationOptions::Method>{
               {"rotation-exact", MechanizationOptions::Method::kRotationExact},
               {"classic", MechanizationOptions::Method::kClassicTwoSample}});
  v.choice({"filter.earth_rotation", "auto: as the manifest says the data are", ""}, c.earth_rotation,
           OptionChoices<std::string>{{"auto", "auto"}, {"true", "true"}, {"false", "false"}});
  v.number({"filter.covariance_interval_s",
            "covariance time update interval, F integrated in between (docs/filter.md section 12)",
            "--covariance-interval"},
           n.covariance_interval, {0.0, NavigatorOptions::kMaxCovarianceInterval, "s (0 = every epoch)"});
  v.rate({"filter.velocity_update_hz", "the wheel velocity update's rate (the paper's 2 Hz)", ""},
         n.wheel.velocity_update_interval, {0.05, 100.0, "Hz"});
  v.choice({"filter.velocity_average", "whole-turns: the update over the last wheel turn (filter.md 15.1)", ""},
           n.wheel.turn_average, OptionChoices<bool>{{"whole-turns", true}, {"none", false}});
  v.number({"filter.speed_window_s", "gyro-x averaging for the wheel speed", ""}, n.wheel.speed_window,
           {0.001, 2.0, "s"});
  v.vec3({"filter.wheel_velocity_std_m_s", "a Wheel-INS's velocity measurement sigma per axis (paper Table 9)",
          ""},
         n.wheel.velocity_std, {1e-4, 10.0, "m/s"});
  v.vec3({"filter.body_velocity_std_m_s", "a Body-INS's velocity measurement sigma per axis (paper Table 9)",
          ""},
         n.body.velocity_std, {1e-4, 10.0, "m/s"});
  v.number({"filter.velocity_gate", "chi-square test-ratio gate of the velocity updates", ""}, n.wheel.gate,
           {0.0, 1e4, "(test ratio; 0 = off)"}, {}, &n.body.gate);
  v.number({"filter.initial_std.position_m", "initial position sigma", ""}, n.wheel.init.position,
           {1e-4, 1000.0, "m"}, {}, &n.body.init.position);
  v.number({"filter.initial_std.velocity_m_s", "initial velocity sigma", ""}, n.wheel.init.velocity,
           {1e-4, 100.0, "m/s"}, {}, &n.body.init.velocity);
  v.number({"filter.initial_std.roll_pitch_deg", "initial roll and pitch sigma", ""}, n.wheel.init.roll_pitch,
           {1e-3, 90.0, "deg"}, kDegrees, &n.body.init.roll_pitch);
  v.number({"filter.initial_std.heading_deg", "initial heading sigma", ""}, n.wheel.init.heading,
           {1e-3, 180.0, "deg"}, kDegrees, &n.body.init.heading);
}

/// fusion: how the subsystems are tied together.
template <class V>
void declare_fusion_options(V& v, RunConfig& c) {
  FusionOptions& f = c.nav.fusion;
  v.choice({"fusion.speed", "each wheel its own speed (filter.md section 9) | mean of the Wheel-IMUs (the paper's)",
            "--speed"},
           f.speed, speed_sharing_choices());
  v.flag({"fusion.share_level", "the Body-INS's roll and pitch to the Wheel-INSs", ""}, f.share_level);
  v.flag({"fusion.position_constraint", "the position constraint between the subsystems (paper eq. 8)",
          "--no-position-constraint (off)"},
         f.position_constraint);
  v.rate({"fusion.position_update_hz", "the position constraint's rate (the paper's 1 Hz)", ""},
         f.position_update_interval, {0.01, 100.0, "Hz"});
  v.number({"fusion.position_std_m", "the position constraint's sigma (paper Table 9)", ""}, f.position_std,
           {1e-3, 100.0, "m"});
  v.number({"fusion.position_gate", "test-ratio gate of the position constraint", ""}, f.position_gate,
           {0.0, 1e4, "(test ratio; 0 = off)"});
  v.custom({"fusion.weights",
            "k_i of eq. (8): equal (the paper) | covariance (each subsystem's uncertainty, docs/filter.md "
            "section 14) | standalone (each subsystem's drift without the constraint, section 14.1) | a list, "
            "one per module (normalised)",
            "--weights"},
           "a name, or a list with each in (0, 10⁶] (leave a module out rather than weight it 0)", [](const RunConfig& r) {
             if (!r.nav.fusion.weights.empty()) {
               std::vector<std::string> w;
               for (const double x : r.nav.fusion.weights) w.push_back(option_number(x));
               return "[" + option_list(w) + "]";
             }
             const ReferenceWeighting k = r.nav.fusion.weighting;
             return std::string(k == ReferenceWeighting::kCovariance   ? "covariance"
                                : k == ReferenceWeighting::kStandalone ? "standalone"
                                                                       : "equal");
           },
           [](const auto& y, const auto& node, RunConfig& r, const auto&) {
             FusionOptions& o = r.nav.fusion;
             if (node.IsScalar()) {
               if (node.Scalar() != "equal" && node.Scalar() != "covariance" && node.Scalar() != "standalone")
                 y.fail("fusion.weights",
                        "expected equal, covariance or standalone (or a list of one positive weight per "
                        "module), got " + y.describe(node), &node);
               o.weighting = weighting_from_name(node.Scalar());
               o.weights.clear();  // over a list given before (a file's, under --weights)
               return;
             }
             o.weights = y.number_list(node, "fusion.weights");
             if (o.weights.empty())
               y.fail("fusion.weights", "an empty list (leave it out for equal weights)", &node);
             for (std::size_t i = 0; i < o.weights.size(); ++i)
               if (!(o.weights[i] > 0.0) || o.weights[i] > 1e6)
                 y.fail(y.index_path("fusion.weights", i),
                        "must be in (0, 1e6], got " + std::to_string(o.weights[i]) +
                            " (every module of the run needs a positive weight; leave a module out of "
                            "the configuration instead of giving it weight 0)",
                        &node);
           });
  v.number({"fusion.weight_window_epochs", "covariance weights: constraint epochs the variances average over",
            ""},
           f.weight_window, {1.0, 1e6, "constraint epochs"});
  v.number({"fusion.heading_offset_window_s",
            "each IMU's heading offset to the mean heading of all is averaged over this window (e-folding); "
            "it carries the fused heading through an outage (docs/faults.md)",
            ""},
           f.heading_offset_window, {1.0, 3600.0, "s"});
  v.flag({"fusion.centralized", "one joint covariance (paper Section VI-B-2); not on a single module",
          "--centralized"},
         f.centralized);
  v.flag({"fusion.steered_in_reference",
          "a steered wheel's IMU counts in the reference point of eq. (8) and the output as any other "
          "(default: it is tied to them and follows while a wheel that does not steer counts; docs/filter.md "
          "section 16)",
          "--steered-in-reference"},
         f.steered_in_reference);
}

/// noise: the noise model identified from the data (docs/filter.md section 13).
template <class V>
void declare_noise_options(V& v, RunConfig& c) {
  NoiseAdaptationOptions& o = c.nav.noise;
  v.flag({"noise.adapt", "the noise identified from the data (false: the manifest's figures held fixed)",
          "--fixed-noise (off)"},
         o.enabled);
  v.number({"noise.window_updates", "velocity updates the in-motion estimates weigh", ""}, o.window,
           {5.0, 1e5, "velocity updates"});
  v.number({"noise.min_velocity_std_fraction", "measurement noise never below this share of its sigma", ""},
           o.r_floor_fraction, {0.01, 1.0, "(of the given sigma)"});
  v.number({"noise.max_vrw_m_s_sqrt_h", "ceiling of the identified velocity random walk", ""}, o.vrw_max,
           {0.01, 1000.0, "m/s/sqrt(h)"}, OptionScale{1.0, 60.0});
  v.number({"noise.min_speed_m_s", "slower updates do not count (at rest the speed is exact)", ""}, o.min_speed,
           {0.0, 100.0, "m/s"});
  v.number({"noise.settle_s", "time after a (re)start before innovations count", ""}, o.settle,
           {0.0, 3600.0, "s"});
  v.number({"noise.min_gyro_bias_deg_h", "floor of a Wheel-IMU's identified bias instability", ""}, o.bias_floor,
           {0.0, 1e4, "deg/h"}, OptionScale{kDeg, 3600.0});
}

/// standstill: zero-velocity detection (docs/faults.md, "Standing still").
template <class V>
void declare_standstill_options(V& v, RunConfig& c) {
  StandstillOptions& o = c.nav.standstill;
  v.flag({"standstill.enabled", "zero-velocity and zero-rate updates while the vehicle stands",
          "--no-standstill (off)"},
         o.enabled);
  v.number({"standstill.max_rate_deg_s", "every IMU's compensated rate (means over blocks) below ...", ""},
           o.max_rate, {0.001, 100.0, "deg/s"}, kDegrees);
  v.number({"standstill.max_force_spread_m_s2", "... and its specific force within this on every axis ...", ""},
           o.max_force_spread, {0.001, 100.0, "m/s^2"});
  v.number({"standstill.block_s", "... (the blocks; at least two in min_time_s) ...", ""}, o.block,
           {0.001, 10.0, "s"});
  v.number({"standstill.min_time_s", "... for this long: the vehicle stands", ""}, o.min_time,
           {0.01, 3600.0, "s"});
  v.number({"standstill.velocity_std_m_s", "sigma of the zero-velocity update", ""}, o.velocity_std,
           {1e-6, 10.0, "m/s"});
  v.number({"standstill.rate_std_deg_s", "sigma of the zero-rate update (with the gyro noise of the window)", ""},
           o.rate_std, {1e-6, 100.0, "deg/s"}, kDegrees);
  v.section_check("standstill", [](RunConfig& r) { r.nav.standstill.validate(); });
}

/// faults: sensor-fault handling (docs/faults.md).
template <class V>
void declare_fault_options(V& v, RunConfig& c) {
  FaultOptions& o = c.nav.faults;
  v.flag({"faults.enabled", "sensor-fault handling", "--no-fault-handling (off)"}, o.enabled);
  v.number({"faults.stale_after_s", "a module whose data lag the others' by more is out", ""}, o.stale_after,
           {0.001, 60.0, "s"});
  v.number({"faults.max_gap_s", "a longer sample interval is a gap: the module restarts", ""}, o.max_gap,
           {0.001, 60.0, "s"});
  v.number({"faults.realign_s", "data levelling a module that comes back", ""}, o.realign_time,
           {0.01, 60.0, "s"});
  v.number({"faults.probation_s", "tied to the others, not yet in the fused solution", ""}, o.probation,
           {0.01, 3600.0, "s"});
  v.number({"faults.retry_after_s", "an isolated module is restarted after this", ""}, o.retry_after,
           {0.01, 3600.0, "s"});
  v.number({"faults.speed_gate_sigma", "a wheel speed this far from its INS ...", ""}, o.speed_gate,
           {0.1, 1e4, "sigma"});
  v.number({"faults.wheel_mismatch_m_s", "... and from the other wheels' (or 10 %) is not used (slip)", ""},
           o.wheel_mismatch, {1e-3, 100.0, "m/s"});
  v.number({"faults.test_ratio", "velocity test ratio counted as failed ...", ""}, o.test_ratio,
           {0.1, 1e6, ""});
  v.whole({"faults.window", "... in the last this many velocity updates ...", ""}, o.window, 1, 1000);
  v.whole({"faults.max_failed", "... this many failures isolate the module", ""}, o.max_failed, 1, 1000);
  v.number({"faults.heading_gate_deg", "3+ modules: a heading this far off the others' ...", ""}, o.heading_gate,
           {0.01, 180.0, "deg"}, kDegrees);
  v.whole({"faults.heading_epochs", "... for this many constraint epochs isolates it", ""}, o.heading_epochs, 1,
          1000);
  v.number({"faults.saturation_margin", "|gyro| at this share of gyro_range_dps is saturated", ""},
           o.saturation_margin, {0.5, 1.0, "(of the full scale)"});
  v.number({"faults.saturation_hold_s", "a saturated gyro's samples bridged this long after", ""},
           o.saturation_hold, {0.001, 60.0, "s"});
  v.number({"faults.max_outage_s", "no data from any module for longer: an error (with or without the handling)",
            ""},
           o.max_outage, {0.01, 1e6, "s"});
  v.number({"faults.reverse_speed_m_s", "wheel speeds compared in sign from this speed on ...", ""},
           o.reverse_speed, {0.01, 100.0, "m/s"});
  v.number({"faults.reverse_time_s", "... a wheel rolling against the others this long is isolated for the run",
            ""},
           o.reverse_time, {0.1, 3600.0, "s"});
  v.section_check("faults", [](RunConfig& r) { r.nav.faults.validate(); });
}

/// Every setting, in the order of the file.
template <class V>
void declare_run_options(V& v, RunConfig& c) {
  declare_selection_options(v, c);
  declare_output_options(v, c);
  declare_filter_options(v, c);
  declare_fusion_options(v, c);
  declare_noise_options(v, c);
  declare_standstill_options(v, c);
  declare_fault_options(v, c);
}

}  // namespace wheelins
