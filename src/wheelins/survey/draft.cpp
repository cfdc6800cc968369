// The manifest drafted from a survey (draft.hpp).
#include "wheelins/survey/draft.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <algorithm>

#include "wheelins/nav/types.hpp"
#include "wheelins/survey/checks.hpp"
#include "wheelins/survey/format.hpp"
#include "wheelins/survey/level.hpp"

namespace wheelins::survey {
namespace {

/// x rounded to a multiple of q (the precision the data give: the manifest stays readable).
double round_to(double x, double q) {
  // Through text, so that the manifest shows the short number (not 847.8530000000001).
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", std::max(0, static_cast<int>(std::lround(-std::log10(q)))), std::round(x / q) * q);
  return std::strtod(buf, nullptr);
}

/// The vehicle keys of a calibrated manifest's module, onto a drafted one.
void carry_over(const ModuleSpec& from, ModuleSpec& to) {
  to.kind = from.kind;
  to.p_inV = from.p_inV;
  to.lever_arm_inB = from.lever_arm_inB;
  to.mounting_rpy = from.mounting_rpy;
  to.axle_axis = from.axle_axis;
  to.axle_sign = from.axle_sign;
  to.wheel_radius = from.wheel_radius;
  to.odometry_radius = from.odometry_radius;
  to.yaw_scale = from.yaw_scale;
  if (from.gyro_range > 0.0) to.gyro_range = from.gyro_range;
  if (from.accel_range > 0.0) to.accel_range = from.accel_range;
  to.noise = from.noise;
  to.noise_stated = from.noise_stated;
}

}  // namespace

VehicleType vehicle_type(const std::string& name) {
  if (name == "car") return {"car", 0.30, 1.50, 2.60, Vec3(1.3, 0.0, -0.6)};
  if (name == "robot") return {"robot", 0.097, 0.33, 0.38, Vec3(0.1, 0.0, -0.25)};
  throw InputError("unknown vehicle type '" + name + "' (known: car, robot)");
}

ManifestDraft draft_from_survey(const DatasetSurvey& survey, const std::vector<DraftModule>& modules,
                                const DraftOptions& o) {
  ManifestDraft d;
  d.layout = "survey";
  Manifest& m = d.manifest;
  auto& note = d.notes.comments;
  m.name = o.name;
  const VehicleType& vt = o.vehicle;
  const Manifest* veh = o.vehicle_from ? &*o.vehicle_from : nullptr;
  const std::string typical = " (typical " + vt.name + (o.vehicle_type_given ? "" : "; --vehicle-type to change") + ")";
  bool radius_todo = false, lever_todo = false, body_pos_todo = false, side_todo = false;
  std::vector<double> left_y, right_y;  // known wheel positions' y, each side
  bool any_steered = false;
  for (std::size_t i = 0; i < modules.size(); ++i) {
    const DraftModule& in = modules[i];
    const ModuleFinding* f = survey.find(in.name);
    if (!f) throw InputError("module '" + in.name + "' was not surveyed");
    const std::string key = "modules[" + std::to_string(i) + "].";
    ModuleSpec s;
    s.name = in.name;
    s.group = in.name;
    s.kind = f->kind;
    s.file = in.file;
    s.layout = in.layout;
    s.format = SampleFormat::kRate;
    s.rate_hz = in.rate_hz;
    s.gyro_range = in.gyro_range;
    s.accel_range = in.accel_range;
    s.noise_stated = 0;
    s.time_offset = round_to(in.input_offset + (f->clock.found ? f->clock.offset : 0.0), 1e-4);
    if (f->clock_reference)
      note[key + "time_offset_s"] = "the reference clock";
    else if (f->clock.found)
      note[key + "time_offset_s"] = fmt("from the data: +- %.3f s (correlation %.3f, ", f->clock.sigma, f->clock.correlation) +
                                    f->clock_basis + ")";
    else {
      note[key + "time_offset_s"] = "TODO: not found from the data (no overlap with the other modules)";
      d.todo.push_back(in.name + ": time_offset_s (its data did not overlap the others')");
    }
    note[key + "kind"] = f->kind == ModuleKind::kWheel
                             ? fmt("from the data: spins about one axis (95th percentile %.1f rad/s)", f->traits.spin_p95)
                             : fmt("from the data: does not spin (95th percentile %.2f rad/s)", f->traits.spin_p95);
    const ModuleSpec* prior = veh ? veh->find(in.name) : nullptr;
    const auto kp = o.known_positions.find(in.name);
    const KnownPosition* known = kp == o.known_positions.end() ? nullptr : &kp->second;
    if (prior && prior->kind != f->kind)
      throw InputError("module '" + in.name + "': the vehicle manifest '" + veh->path.string() + "' calls it a " +
                       to_string(prior->kind) + " IMU, but its data " +
                       (f->kind == ModuleKind::kWheel ? "spin like a wheel's" : "do not spin"));
    if (f->kind == ModuleKind::kWheel) {
      s.axle_axis = f->axle_axis;
      s.axle_sign = f->axle_sign;
      s.wheel_radius = vt.wheel_radius;
      s.p_inV = Vec3(f->steered ? vt.wheelbase : 0.0, f->side * 0.5 * vt.track, 0.0);
      note[key + "axle_axis"] = "from the data: the spin axis";
      note[key + "axle_sign"] = f->forward_clear
                                    ? fmt("from the data: %.0f %% of its turning one way (a vehicle mostly drives forward)",
                                          50.0 * (1.0 + std::abs(f->traits.spin_direction)))
                                    : "TODO: the data turn both ways; check which way is forward";
      if (!f->forward_clear) d.todo.push_back(in.name + ": axle_sign (its data turn both ways)");
      if (prior) {
        carry_over(*prior, s);
        note[key + "wheel_radius_m"] = "from the vehicle manifest";
        note[key + "position_v_m"] = "from the vehicle manifest";
        note[key + "lever_arm_b_m"] = "from the vehicle manifest";
        if (prior->axle_axis != f->axle_axis || prior->axle_sign != f->axle_sign)
          d.facts.push_back(in.name + ": the vehicle manifest's axle (axis, sign) differs from this recording's data; the data's kept");
        s.axle_axis = f->axle_axis;
        s.axle_sign = f->axle_sign;
      } else {
        radius_todo = true;
        note[key + "wheel_radius_m"] = "TODO: typical " + vt.name + " value; calibrate against a reference (wheelins calibrate --reference) or measure";
        note[key + "lever_arm_b_m"] = "estimated from the data by every run (calibration.yaml)";
        if (known) {
          s.p_inV = known->p_inV;
          note[key + "position_v_m"] = "from " + known->source + " (x forward, y right, z down)";
          if (known->p_inV.y() < 0.0) left_y.push_back(known->p_inV.y());
          if (known->p_inV.y() > 0.0) right_y.push_back(known->p_inV.y());
          if (f->side && (known->p_inV.y() > 0.0) != (f->side > 0))
            d.facts.push_back(in.name + ": " + known->source + " puts it on the " + (f->side > 0 ? "left" : "right") +
                              ", its data on the " + (f->side > 0 ? "right" : "left") + ": check the frames");
        } else {
          lever_todo = true;
          std::string where = f->steered ? "front (steered)" : "rear axle";
          if (f->side) where += std::string(", ") + (f->side > 0 ? "right" : "left");
          else side_todo = true;
          note[key + "position_v_m"] = "from the data: " + where + "; x, y TODO" + typical;
        }
        note[key + "mounting_deg"] = "estimated from the data by every run (calibration.yaml)";
      }
      s.steered = f->steered || (prior && prior->steered);
      any_steered = any_steered || s.steered;
      if (f->steered) {
        note[key + "steered"] = fmt("from the data: its yaw rate leads the vehicle's by %.2f s", f->yaw_lead);
        d.facts.push_back(in.name + fmt(": a steered wheel (its yaw rate leads the vehicle's by %.2f s): "
                                        "steered: true, its steering angle estimated by every run", f->yaw_lead));
      }
    } else {
      s.lever_arm_inB = Vec3::Zero();
      s.p_inV = vt.body_position;
      // C_b^v from the measured axes: rows forward, right, down in sensor axes; the up axis
      // from the drive where it could be fitted, else where the vehicle stood still (which
      // holds the ground's tilt there).
      const bool level = f->axes_found && f->level.found;
      s.mounting_rpy = euler_from_dcm(vehicle_axes(level ? f->level.up : f->traits.up, f->axes_found ? f->forward : Vec3::UnitX()));
      for (int k = 0; k < 3; ++k) s.mounting_rpy[k] = round_to(s.mounting_rpy[k] / kDeg, 0.01) * kDeg;
      note[key + "mounting_deg"] = !f->axes_found ? "roll, pitch from the data; yaw TODO (no clear forward acceleration)"
                                   : level ? fmt("from the data: roll, pitch from the drive (level fit, +- %.1f / %.1f deg), ", f->level.sigma_roll_deg, f->level.sigma_pitch_deg) +
                                                 fmt("forward axis from accelerations (fit %.2f); refined by every run", f->forward_fit)
                                           : fmt("from the data: up-axis at rest, forward axis from accelerations (fit %.2f); refined by every run", f->forward_fit);
      if (level && angle_deg(f->level.up, f->traits.up) > 1.0)
        d.facts.push_back(in.name + fmt(": where the vehicle stood still its up axis was %.1f deg from the drive's (the ground's tilt there, ", angle_deg(f->level.up, f->traits.up)) +
                          fmt("or the fit's error: +- %.1f / %.1f deg); the drive's taken for its roll and pitch", f->level.sigma_roll_deg, f->level.sigma_pitch_deg));
      if (!f->axes_found) d.todo.push_back(in.name + ": mounting_deg yaw (the data showed no clear forward axis)");
      if (prior) {
        carry_over(*prior, s);
        note[key + "mounting_deg"] = "from the vehicle manifest";
        note[key + "position_v_m"] = "from the vehicle manifest";
      } else if (known) {
        s.p_inV = known->p_inV;
        note[key + "position_v_m"] = "from " + known->source + " (x forward, y right, z down); refined by every run relative to the wheels";
      } else {
        body_pos_todo = true;
        note[key + "position_v_m"] = "TODO: measure; refined by every run relative to the wheels" + typical;
      }
    }
    m.modules.push_back(std::move(s));
  }

  // The static period and the start.
  if (survey.static_period) {
    m.static_start = round_to(survey.static_period->start, 0.01);
    m.static_end = round_to(survey.static_period->end, 0.01);
    note["static_period_s"] = "from the data: " + static_period_basis(survey) + ", on the reference clock";
    if (!survey.static_bodies_quiet)
      d.todo.push_back("static_period_s: the wheels rest there but the bodies are never quiet with them; check it");
  } else {
    // Empty, where every module has data: a run refuses it and says why.
    double start = -1e300;
    for (const ModuleFinding& f : survey.modules) start = std::max(start, f.start);
    if (!survey.modules.empty()) m.static_start = m.static_end = round_to(start, 0.01);
    d.todo.push_back("static_period_s: the modules never rest together at the start (a static period is needed to align)");
    note["static_period_s"] = "TODO: no common rest found";
  }
  m.earth_rotation = true;
  m.track_width = veh ? veh->track_width : vt.track;
  m.wheelbase = veh ? veh->wheelbase : vt.wheelbase;
  if (veh && veh->antenna_inV) m.antenna_inV = veh->antenna_inV;
  note["vehicle.track_m"] = veh ? "from the vehicle manifest" : "TODO: measure" + typical;
  note["vehicle.wheelbase_m"] = veh           ? "from the vehicle manifest"
                                : any_steered ? "TODO: measure" + typical
                                              : "a typical value" + typical + "; used with steered wheels only";
  const bool track_known = veh || (!left_y.empty() && !right_y.empty());
  if (!veh && track_known) {
    double l = 0.0, r = 0.0;
    for (double y : left_y) l += y;
    for (double y : right_y) r += y;
    m.track_width = round_to(r / static_cast<double>(right_y.size()) - l / static_cast<double>(left_y.size()), 1e-4);
    note["vehicle.track_m"] = "from the wheels' stated positions (the right's y less the left's)";
  }
  m.heading_known = false;
  if (o.origin) {
    m.origin = *o.origin;
    note["initial.lat_deg"] = "the reference at the start (its antenna)";
  } else {
    m.origin = earth::Geodetic{0.0, 0.0, 0.0};
    note["initial.lat_deg"] = "TODO: the start position (gravity and the earth rate depend on it)";
    d.todo.push_back("initial: the start position (lat_deg, lon_deg, h_m; no reference given)");
  }
  if (o.truth_file) {
    m.truth_file = *o.truth_file;
    if (o.truth_clock && o.truth_clock->found) {
      m.truth_time_offset = round_to(o.truth_clock->offset, 1e-4);
      note["truth_time_offset_s"] = fmt("from the data: +- %.3f s (its speed against the wheels', correlation %.4f)",
                                        o.truth_clock->sigma, o.truth_clock->correlation);
    } else {
      d.todo.push_back("truth_time_offset_s: the reference's clock could not be fitted to the IMUs'");
    }
  }
  // What is still to do.
  if (radius_todo)
    d.todo.insert(d.todo.begin(), "wheel_radius_m of every wheel: typical " + vt.name +
                                      " values written; `wheelins calibrate --reference` fits them to a GNSS track");
  if (lever_todo) d.todo.push_back("wheel position_v_m (x, y): typical values written");
  if (!track_known) d.todo.push_back("vehicle.track_m: a typical value written");
  if (!veh && any_steered) d.todo.push_back("vehicle.wheelbase_m: a typical value written (steered wheels are ahead of the rear axle by it)");
  if (body_pos_todo) d.todo.push_back("body position_v_m: a typical value written (a run refines it relative to the wheels)");
  if (side_todo) d.todo.push_back("which side each wheel is on (y of position_v_m): not told by the data (one wheel, or no turns)");
  if (o.truth_clock)
    for (const auto& n : o.truth_clock->notes) d.facts.push_back("reference clock: " + n);
  d.notes.header = {"drafted by `" + o.tool + "` from " + o.source,
                    "what the data tell is filled in (see the comments); values marked 'TODO' are guesses",
                    "no initial heading: a run navigates in a local frame (heading 0 at the start) unless one is set",
                    "no noise figures: they are identified from the data (noise.yaml of a run)"};
  return d;
}

ManifestDraft draft_from_files(const ManifestDraft& first, DraftOptions o, DatasetSurvey* report) {
  std::vector<std::string> names;
  std::vector<DraftModule> mods;
  for (const ModuleSpec& s : first.manifest.modules) {
    names.push_back(s.name);
    DraftModule d;
    d.name = s.name;
    d.file = s.file;
    d.layout = s.layout;
    d.rate_hz = s.rate_hz;
    mods.push_back(d);
  }
  const DatasetSurvey sv = survey_modules(survey_inputs(first.manifest, names));
  if (first.manifest.truth_file) {
    o.truth_file = *first.manifest.truth_file;
    o.origin = first.manifest.origin;
  }
  ManifestDraft d = draft_from_survey(sv, mods, o);
  d.manifest.path = first.manifest.path;
  d.manifest.odometer_file = first.manifest.odometer_file;
  if (first.manifest.heading_known && first.manifest.truth_file) {
    d.manifest.initial_heading = first.manifest.initial_heading;
    d.manifest.heading_known = true;
    d.notes.comments["initial.heading_deg"] = "from the truth at the start";
  }
  d.layout = first.layout;
  // The layout's facts but its static period (a single gyro's first motion: the survey's
  // common rest of every module replaces it).
  std::vector<std::string> facts;
  for (const auto& f : first.facts)
    if (f.rfind("static period", 0) != 0) facts.push_back(f);
  d.facts.insert(d.facts.begin(), facts.begin(), facts.end());
  d.facts.push_back("what the data say:\n" + survey_report(sv));
  if (report) *report = sv;
  return d;
}

}  // namespace wheelins::survey
