// A manifest against its data (checks.hpp).
#include "wheelins/survey/checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "wheelins/io/text_util.hpp"
#include "wheelins/survey/format.hpp"
#include "wheelins/survey/level.hpp"

namespace wheelins::survey {
namespace {

using io_detail::format_double;

std::string axis_name(const Vec3& u) {
  int k = 0;
  u.cwiseAbs().maxCoeff(&k);
  if (std::abs(u[k]) > 0.97) return std::string(u[k] > 0 ? "+" : "-") + "xyz"[k];
  return fmt("[%.2f, %.2f, %.2f]", u.x(), u.y(), u.z());
}

}  // namespace

std::vector<ModuleInput> survey_inputs(const Manifest& m, const std::vector<std::string>& modules) {
  std::vector<ModuleInput> in;
  for (const auto& name : modules) {
    const ModuleSpec* s = m.find(name);
    if (!s) throw InputError(io_detail::quote(m.path) + ": no module named '" + name + "'");
    ModuleInput x;
    x.name = name;
    x.file = m.resolve(s->file);
    x.read = imu_read_options(*s);
    x.read.pass_nonfinite = true;  // left out like a sample beyond the range (series.hpp)
    if (s->gyro_range > 0.0) x.gyro_limit = 1.05 * s->gyro_range;
    if (s->accel_range > 0.0) x.accel_limit = 1.05 * s->accel_range;
    in.push_back(std::move(x));
  }
  return in;
}

std::vector<DataCheck> check_against_data(const Manifest& man, const std::vector<std::string>& modules,
                                          const DatasetSurvey& survey, const DataCheckOptions& o) {
  std::vector<DataCheck> out;
  auto error = [&](const std::string& mod, const std::string& key, const std::string& msg) {
    out.push_back({DataCheck::Level::kError, mod, key, msg});
  };
  auto warning = [&](const std::string& mod, const std::string& key, const std::string& msg) {
    out.push_back({DataCheck::Level::kWarning, mod, key, msg});
  };
  // Does the vehicle move? (A kind is judged only on a moving vehicle.)
  double wheel_motion = 0.0;
  for (const auto& f : survey.modules)
    if (f.kind == ModuleKind::kWheel) wheel_motion = std::max(wheel_motion, f.traits.motion_time);
  // The clocks are judged against a module whose data, as the manifest times them, cover
  // its static period (a body first): the manifest's own times are in that clock. A static
  // period is often written from a round time before the first record (a simulated one from
  // the start, its first record 1 / rate later): data that leave a little of it out at either
  // end (a fifth of it, at most 1 s) still cover it.
  const double slack = std::min(1.0, 0.2 * std::max(0.0, man.static_end - man.static_start));
  auto covers_static = [&](const ModuleFinding& f) {
    return f.input_start <= man.static_start + slack && f.input_end >= man.static_end - slack;
  };
  const ModuleFinding* ref = nullptr;
  for (int pass = 0; pass < 3 && !ref; ++pass)
    for (const auto& f : survey.modules)
      if ((pass == 2 || (f.kind == ModuleKind::kBody) == (pass == 0)) && (pass == 2 || !f.clock_weak) && f.clock.found && covers_static(f)) {
        ref = &f;
        break;
      }
  const double ref_offset = ref ? ref->clock.offset : 0.0;
  const double ref_sigma = ref ? ref->clock.sigma : 0.0;
  // The run's span as the manifest times it: from the static period to the latest end of the
  // modules on the run's clock, those whose data cover the static period (all of them if none
  // does): a module whose clock is off must not stretch the run and have the others blamed.
  double run_end = -1e300;
  for (const auto& f : survey.modules)
    if (covers_static(f)) run_end = std::max(run_end, f.input_end);
  if (run_end == -1e300)
    for (const auto& f : survey.modules) run_end = std::max(run_end, f.input_end);
  const double run_start = man.static_start;

  for (std::size_t i = 0; i < modules.size(); ++i) {
    const ModuleSpec* spec = man.find(modules[i]);
    const ModuleFinding* f = survey.find(modules[i]);
    if (!spec || !f) continue;
    std::size_t index = 0;
    while (index < man.modules.size() && man.modules[index].name != spec->name) ++index;
    const std::string key = "modules[" + std::to_string(index) + "].";
    const std::string who = "module '" + spec->name + "'";
    const bool moving = f->kind == ModuleKind::kWheel || wheel_motion >= o.min_motion ||
                        f->traits.motion_time >= 3.0 * o.min_motion;

    // Kind.
    if (spec->kind == ModuleKind::kWheel && f->kind == ModuleKind::kBody && moving) {
      error(spec->name, key + "kind",
            who + " is declared a wheel IMU, but its data do not spin (95th percentile rate " +
                fmt("%.2f rad/s", f->traits.spin_p95) + (wheel_motion >= o.min_motion ? " while the wheels turn" : "") +
                "): is it on the body? set " + key + "kind: body");
      continue;
    }
    if (spec->kind == ModuleKind::kBody && f->kind == ModuleKind::kWheel) {
      error(spec->name, key + "kind",
            who + " is declared a body IMU, but its data spin like a wheel's (about its " +
                std::string(1, "xyz"[f->axle_axis]) + fmt(" axis, 95th percentile %.1f rad/s): set ", f->traits.spin_p95) +
                key + "kind: wheel");
      continue;
    }

    // Clock and coverage.
    bool clock_reported = false;
    const bool weak_pair = f->clock_weak || (ref && ref->clock_weak);  // a body tied to the wheels only coarsely
    if (f->clock.found && f != ref && !weak_pair && f->clock.correlation >= o.min_clock_correlation) {
      const double off = f->clock.offset - ref_offset, sig = std::hypot(f->clock.sigma, ref_sigma);
      const std::string suggestion = format_double(std::round((spec->time_offset + off) * 1e4) / 1e4);
      if (std::abs(off) > o.clock_error && std::abs(off) > 4.0 * sig) {
        error(spec->name, key + "time_offset_s",
              who + fmt(": its clock is %+.4f s (+- %.4f s) off ", off, sig) +
                  (ref ? "'" + ref->module + "'s, whose data hold the static period (" : "the others' (") +
                  (f->clock_reference && ref ? ref->clock_basis : f->clock_basis) +
                  fmt(", correlation %.3f): set ", f->clock_reference && ref ? ref->clock.correlation : f->clock.correlation) + key +
                  "time_offset_s: " + suggestion);
        clock_reported = true;
      }
      else if (std::abs(off) > o.clock_warning && std::abs(off) > 3.0 * sig)
        warning(spec->name, key + "time_offset_s",
                who + fmt(": its clock looks %+.4f s (+- %.4f s) off the others' (", off, sig) + f->clock_basis +
                    "): time_offset_s " + suggestion + " would match them");
    }
    if (!clock_reported) {
      const double span = run_end - run_start;
      const double from = std::max(f->input_start, run_start), to = std::min(f->input_end, run_end);
      const double covered = span > 0.0 ? std::max(0.0, to - from) / span : 1.0;
      if (span > 0.0 && covered < o.min_coverage)
        error(spec->name, key + "time_offset_s",
              who + fmt(": its data cover %.1f s .. %.1f s, ", f->input_start, f->input_end) +
                  fmt("%.0f %% of the run (%.1f s .. %.1f s): ", 100.0 * covered, run_start, run_end) +
                  "a clock offset (time_offset_s)? Leave it out, or set its clock");
    }

    if (spec->kind == ModuleKind::kWheel && f->kind == ModuleKind::kWheel) {
      // Spin axis against the manifest's axle.
      const Mat3 C_StoB = wheel_sensor_to_body(*spec);
      const Vec3 axle_inS = C_StoB.transpose() * Vec3::UnitX();  // b x in sensor axes
      const Vec3 spin_inS = Vec3::Unit(f->traits.spin_axis);
      const double ang = std::acos(std::min(1.0, std::abs(axle_inS.dot(spin_inS)))) / kDeg;
      if (ang > o.axis_tolerance_deg) {
        error(spec->name, key + "axle_axis",
              who + ": its data spin about the sensor's " + std::string(1, "xyz"[f->traits.spin_axis]) +
                  fmt(" axis (%.1f %% of the rotation), but the manifest puts the axle along the sensor's ",
                      100.0 * f->traits.spin_share) +
                  axis_name(axle_inS) + " axis: set " + key + "axle_axis: " + std::string(1, "xyz"[f->traits.spin_axis]) +
                  (spec->mounting_rpy.norm() > 10.0 * kDeg ? " and mounting_deg near [0, 0, 0]" : ""));
        continue;
      }
      // Which way is forward: the share of the turning the manifest calls forward.
      const double along = axle_inS.dot(spin_inS) >= 0.0 ? 1.0 : -1.0;
      const double d = f->traits.spin_direction;  // +1: all positive about the spin axis
      const double forward_share = 0.5 * (1.0 + (-spec->axle_sign * along) * d);
      if (f->traits.motion_time >= o.min_motion) {
        if (forward_share < o.min_forward_share)
          error(spec->name, key + "axle_sign",
                who + fmt(": with axle_sign %+.0f it rolls backward for %.0f %% of its turning; a vehicle drives forward "
                          "most of its way: set ", spec->axle_sign, 100.0 * (1.0 - forward_share)) +
                    key + "axle_sign: " + std::to_string(-spec->axle_sign) +
                    " (if it really drove backward, run with --no-data-checks)");
        else if (forward_share < o.doubtful_forward_share)
          warning(spec->name, key + "axle_sign",
                  who + fmt(": it turns both ways (%.0f %% of its turning forward with axle_sign %+.0f): "
                            "check which way is forward", 100.0 * forward_share, spec->axle_sign));
      }
      // Side.
      if (f->side != 0 && std::abs(spec->p_inV.y()) > 1e-3 && (spec->p_inV.y() > 0) != (f->side > 0))
        error(spec->name, key + "position_v_m",
              who + ": its data put it on the vehicle's " + (f->side > 0 ? "right" : "left") +
                  " (it turns faster than the other side's wheels in " + (f->side > 0 ? "left" : "right") +
                  fmt(" turns; evidence %.2f), but its position_v_m y is %+.3f m: swap the sides", f->side_evidence,
                      spec->p_inV.y()));
      if (f->steered && !spec->steered)
        warning(spec->name, key + "steered",
                who + fmt(": its yaw rate leads the vehicle's by %.2f s and departs from it by %.0f %% like a steered "
                          "wheel's, but the manifest takes it as unsteered (its heading would follow the steering): "
                          "set steered: true (and its position_v_m x to its distance ahead of the rear axle)",
                          f->yaw_lead, 100.0 * f->yaw_departure));
    }

    if (spec->kind == ModuleKind::kBody && f->kind == ModuleKind::kBody && f->traits.rest_found) {
      const Mat3 C_BtoV = dcm_from_euler(spec->mounting_rpy);
      const Vec3 down_inS = C_BtoV.transpose() * Vec3::UnitZ();
      const double tilt = angle_deg(down_inS, -f->traits.up);
      if (tilt > o.body_axis_tolerance_deg) {
        error(spec->name, key + "mounting_deg",
              who + ": at rest its sensor's " + axis_name(f->traits.up) + " axis points up, but the manifest's mounting_deg " +
                  fmt("puts the vehicle's down axis %.0f deg away from gravity (along the sensor's ", tilt) +
                  axis_name(down_inS) + "): correct the roll and pitch of " + key + "mounting_deg");
        continue;
      }
      if (f->axes_found) {
        const Vec3 fwd_inS = C_BtoV.transpose() * Vec3::UnitX();
        const double off = angle_deg(fwd_inS, f->forward);
        if (off > o.body_forward_tolerance_deg) {
          // The angles to set, as the import drafts them (the up axis from the drive if fitted).
          const Vec3 up = f->level.found ? f->level.up : f->traits.up;
          const Vec3 rpy = euler_from_dcm(vehicle_axes(up, f->forward)) / kDeg;
          error(spec->name, key + "mounting_deg",
                who + ": the vehicle's forward axis is along its sensor's " + axis_name(f->forward) +
                    fmt(" axis (from its accelerations, fit %.2f), ", f->forward_fit) + fmt("%.0f deg from the manifest's (", off) +
                    axis_name(fwd_inS) + "): set " + key + fmt("mounting_deg to about [%.0f, %.0f, %.0f]", rpy.x(), rpy.y(), rpy.z()));
          continue;
        }
      }
      if (f->axes_found && f->level.found) {
        const double off = angle_deg(down_inS, -f->level.up);
        const double sigma = std::hypot(f->level.sigma_roll_deg, f->level.sigma_pitch_deg);
        if (off > std::max(o.body_level_tolerance_deg, 3.0 * sigma)) {
          const Vec3 rpy = euler_from_dcm(vehicle_axes(f->level.up, C_BtoV.transpose() * Vec3::UnitX())) / kDeg;
          warning(spec->name, key + "mounting_deg",
                  who + fmt(": over the drive the vehicle's down axis is %.1f deg from the manifest's mounting_deg (level fit, +- %.1f deg; ", off, sigma) +
                      "a mounting taken where the vehicle stood on a slope holds the slope): set " + key +
                      fmt("mounting_deg to about [%.1f, %.1f, %.1f]", rpy.x(), rpy.y(), rpy.z()));
        }
      }
    }
  }
  return out;
}

}  // namespace wheelins::survey
