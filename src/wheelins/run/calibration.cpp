// The calibration pass of a run (calibration.hpp).
#include "wheelins/run/calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "wheelins/io/imu_file.hpp"
#include "wheelins/run/input_checks.hpp"
#include "wheelins/util/progress.hpp"

namespace wheelins {
namespace fs = std::filesystem;

struct ModuleCalibrators::Impl {
  // Per module, in the order of `modules`: one of the two.
  std::vector<std::unique_ptr<WheelImuCalibrator>> wheel;
  std::vector<std::unique_ptr<BodyImuCalibrator>> body;
  InstallationCalibrationOptions opt;
};

ModuleCalibrators::ModuleCalibrators(const Manifest& m, const std::vector<std::string>& modules,
                                     const InstallationCalibrationOptions& opt,
                                     const std::vector<double>& expected_end)
    : impl_(std::make_unique<Impl>()) {
  impl_->opt = opt;
  for (std::size_t k = 0; k < modules.size(); ++k) {
    const ModuleSpec* spec = m.find(modules[k]);
    if (!spec) throw InputError("'" + m.path.string() + "': no module '" + modules[k] + "'");
    const double end = k < expected_end.size() ? expected_end[k] : 0.0;
    if (spec->kind == ModuleKind::kWheel) {
      impl_->wheel.push_back(std::make_unique<WheelImuCalibrator>(*spec, m.static_start, m.static_end, opt, end));
      impl_->body.push_back(nullptr);
    } else {
      impl_->wheel.push_back(nullptr);
      impl_->body.push_back(std::make_unique<BodyImuCalibrator>(*spec, m.static_start, m.static_end, opt, end));
    }
  }
}

ModuleCalibrators::~ModuleCalibrators() = default;
ModuleCalibrators::ModuleCalibrators(ModuleCalibrators&&) noexcept = default;
ModuleCalibrators& ModuleCalibrators::operator=(ModuleCalibrators&&) noexcept = default;

void ModuleCalibrators::add(int index, const ImuSample& s) {
  const auto k = static_cast<std::size_t>(index);
  if (impl_->wheel[k])
    impl_->wheel[k]->add(s);
  else
    impl_->body[k]->add(s);
}

InstallationCalibration ModuleCalibrators::result() const {
  InstallationCalibration out;
  std::vector<const WheelImuCalibrator*> views;
  std::vector<const BodyImuCalibrator*> bodies;
  for (std::size_t k = 0; k < impl_->wheel.size(); ++k) {
    if (impl_->wheel[k]) {
      out.wheels.push_back(impl_->wheel[k]->result());
      views.push_back(impl_->wheel[k].get());
    } else {
      out.bodies.push_back(impl_->body[k]->result());
      bodies.push_back(impl_->body[k].get());
    }
  }
  // The relative radius (the two sides' speed difference against the yaw rate) and a Body-IMU's
  // yaw and position (against the wheels' axle accelerometers) hold for wheels that do not
  // steer: a steered wheel's speed and axle turn with the steering.
  std::vector<const WheelImuCalibrator*> fixed;
  std::vector<WheelImuCalibration> fixed_results;
  std::vector<std::size_t> fixed_index;
  for (std::size_t i = 0; i < views.size(); ++i)
    if (!views[i]->module().steered) {
      fixed.push_back(views[i]);
      fixed_results.push_back(out.wheels[i]);
      fixed_index.push_back(i);
    }
  estimate_relative_radius(fixed, impl_->opt, fixed_results);
  for (std::size_t j = 0; j < fixed.size(); ++j) out.wheels[fixed_index[j]] = fixed_results[j];
  for (std::size_t b = 0; b < bodies.size(); ++b)
    estimate_body_yaw(*bodies[b], fixed, fixed_results, impl_->opt, out.bodies[b]);
  return out;
}

CalibrationWarmup::CalibrationWarmup(const Manifest& m, const std::vector<std::string>& modules,
                                     const InstallationCalibrationOptions& opt, double warmup_s)
    : t_end_(m.static_end + warmup_s),
      cals_(m, modules, opt, std::vector<double>(modules.size(), m.static_end + warmup_s)) {
  // Room for the warm-up's samples at the modules' rates, so that keeping them does not
  // reallocate on the way; at most 2^20 of them (a hint: what is kept grows with the data
  // read, and the manifest's times alone never size memory).
  double per_s = 0.0;
  for (const auto& name : modules)
    if (const ModuleSpec* spec = m.find(name)) per_s += spec->rate_hz > 0.0 ? spec->rate_hz : 0.0;
  const double span = std::max(0.0, t_end_ - std::min(m.static_start, m.static_end));
  if (std::isfinite(span)) kept_.reserve(static_cast<std::size_t>(std::min(per_s * span * 1.02, 1048576.0)) + 16);
}

bool CalibrationWarmup::add(int index, const ImuSample& s, std::uint64_t record) {
  if (s.t > t_end_) return false;
  cals_.add(index, s);
  kept_.push_back({index, s, record});
  return true;
}

InstallationCalibration calibrate_installation(
    const Manifest& m, const std::vector<std::string>& modules,
    const InstallationCalibrationOptions& opt, bool isolate_faults, bool progress, double t_end) {
  // A binary file's sample count from its size (7 doubles a record); 0 for text files.
  auto binary_samples = [&](const ModuleSpec& spec) -> std::uint64_t {
    if (spec.layout != FileLayout::kBinary) return 0;
    std::error_code ec;
    const auto size = fs::file_size(m.resolve(spec.file), ec);
    return ec ? 0 : size / (7 * sizeof(double));
  };
  std::uint64_t total = 0;
  std::vector<const ModuleSpec*> specs;
  std::vector<double> expected_end;
  for (const auto& name : modules) {
    const ModuleSpec* spec = m.find(name);
    if (!spec) throw InputError("'" + m.path.string() + "': no module '" + name + "'");
    specs.push_back(spec);
    const std::uint64_t n = binary_samples(*spec);
    total += n;
    // The rate series reserved for the file's span (binary files: from the sample count).
    double end = t_end;
    if (!std::isfinite(end)) end = n > 0 && spec->rate_hz > 0.0 ? m.static_start + static_cast<double>(n) / spec->rate_hz : 0.0;
    expected_end.push_back(end);
  }
  ModuleCalibrators cals(m, modules, opt, expected_end);
  Progress bar("calibrating", total, progress);
  std::uint64_t done = 0;
  for (std::size_t k = 0; k < specs.size(); ++k) {
    const ModuleSpec* spec = specs[k];
    // The samples the navigator will see: the same reader and input checks, with their
    // warnings left to the navigation pass (which reads the same file again).
    ImuReadOptions ro = imu_read_options(*spec, {});
    ro.pass_nonfinite = isolate_faults;  // as the run reads them
    auto reader = std::make_unique<ImuFileReader>(m.resolve(spec->file), ro);
    CheckedStream stream(std::move(reader), *spec, m, isolate_faults, WarningSink{});
    ImuSample s;
    while (stream.next(s) && s.t <= t_end) {
      cals.add(static_cast<int>(k), s);
      if ((++done & 0xFFFF) == 0) bar.update(done);
    }
  }
  bar.finish();
  return cals.result();
}

Manifest apply_calibration(Manifest m, const InstallationCalibration& cal) {
  for (auto& spec : m.modules) {
    for (const auto& c : cal.wheels)
      if (spec.name == c.module) {
        spec.mounting_rpy = c.mounting_rpy;
        spec.lever_arm_inB = c.lever_arm_inB();
        spec.wheel_radius = c.wheel_radius.value;
      }
    for (const auto& c : cal.bodies)
      if (spec.name == c.module) {
        spec.mounting_rpy = c.mounting_rpy;
        spec.p_inV.x() += c.position_x.value;
        spec.p_inV.y() += c.position_y.value;
      }
  }
  return m;
}

namespace {

/// A YAML number every YAML 1.1 reader takes as a float ("1.2e-05" would be a string to
/// some: an exponent needs a decimal point).
std::string num(double v, int digits = 6) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  std::string t = b;
  const auto e = t.find('e');
  if (e != std::string::npos && t.find('.') == std::string::npos) t.insert(e, ".0");
  return t;
}

std::string list3(double a, double b, double c, int digits = 6) {
  return "[" + num(a, digits) + ", " + num(b, digits) + ", " + num(c, digits) + "]";
}

const char* yn(bool b) { return b ? "true" : "false"; }

CalibrationOutcome outcome_of(const CalibratedValue& v, double prior) {
  if (v.observed) return CalibrationOutcome::kEstimated;
  return v.value == prior ? CalibrationOutcome::kKept : CalibrationOutcome::kWeak;
}

const char* const kAngles[3] = {"roll", "pitch", "yaw"};
const char* const kAxes[3] = {"x", "y", "z"};

/// The decisions of one module's key, in component order.
std::vector<const CalibrationDecision*> decisions_of(const std::vector<CalibrationDecision>& all, const std::string& module,
                                                     const std::string& key) {
  std::vector<const CalibrationDecision*> out;
  for (const auto& d : all)
    if (d.module == module && d.key == key) out.push_back(&d);
  return out;
}

const char* const* component_names(const std::string& key) {
  return key == "mounting_deg" ? kAngles : kAxes;
}

/// "[estimated]" when every part agrees, else "[pitch: estimated, yaw: weak]".
std::string tags(const std::vector<const CalibrationDecision*>& ds) {
  bool same = true;
  for (const auto* d : ds) same = same && d->outcome == ds.front()->outcome;
  if (same) return std::string("[") + to_string(ds.front()->outcome) + "]";
  std::string t;
  for (const auto* d : ds)
    t += (t.empty() ? "" : ", ") + std::string(d->component >= 0 ? component_names(d->key)[d->component] : "value") +
         ": " + to_string(d->outcome);
  return "[" + t + "]";
}

/// The decisions of a key as a YAML flow list (a scalar: one string).
std::string outcome_yaml(const std::vector<const CalibrationDecision*>& ds) {
  if (ds.size() == 1 && ds.front()->component < 0) return std::string("\"") + to_string(ds.front()->outcome) + "\"";
  std::string t;
  for (const auto* d : ds) t += (t.empty() ? "" : ", ") + std::string("\"") + to_string(d->outcome) + "\"";
  return "[" + t + "]";
}

}  // namespace

const char* to_string(CalibrationOutcome o) {
  switch (o) {
    case CalibrationOutcome::kEstimated: return "estimated";
    case CalibrationOutcome::kWeak: return "weak";
    case CalibrationOutcome::kKept: return "kept";
    case CalibrationOutcome::kNotEstimable: return "not estimable";
  }
  return "?";
}

std::vector<CalibrationDecision> calibration_decisions(const InstallationCalibration& cal) {
  std::vector<CalibrationDecision> out;
  auto add = [&](const std::string& module, const char* key, int comp, CalibrationOutcome o, bool no_effect = false,
                 bool relative = false) { out.push_back({module, key, comp, o, no_effect, relative}); };
  for (const auto& c : cal.wheels) {
    add(c.module, "mounting_deg", 0, CalibrationOutcome::kNotEstimable, true);
    add(c.module, "mounting_deg", 1, outcome_of(c.axle_tilt_y, 0.0));
    add(c.module, "mounting_deg", 2, outcome_of(c.axle_tilt_z, 0.0));
    add(c.module, "lever_arm_b_m", 0, CalibrationOutcome::kNotEstimable, true);
    for (int k = 1; k < 3; ++k) add(c.module, "lever_arm_b_m", k, outcome_of(c.lever_arm[k], c.manifest_lever_arm[k]));
    add(c.module, "wheel_radius_m", -1, outcome_of(c.wheel_radius, c.manifest_wheel_radius), false, true);
  }
  for (const auto& c : cal.bodies) {
    add(c.module, "mounting_deg", 0, outcome_of(c.tilt_x, 0.0));
    add(c.module, "mounting_deg", 1, outcome_of(c.tilt_y, 0.0));
    add(c.module, "mounting_deg", 2, outcome_of(c.yaw, 0.0));
    add(c.module, "position_v_m", 0, outcome_of(c.position_x, 0.0));
    add(c.module, "position_v_m", 1, outcome_of(c.position_y, 0.0));
    add(c.module, "position_v_m", 2, CalibrationOutcome::kNotEstimable);
  }
  return out;
}

ManifestAnnotations calibration_notes(const Manifest& m, const InstallationCalibration& cal, ManifestAnnotations notes,
                                      const std::vector<std::string>& reference_measured) {
  const std::vector<CalibrationDecision> all = calibration_decisions(cal);
  for (std::size_t i = 0; i < m.modules.size(); ++i) {
    const std::string& name = m.modules[i].name;
    for (const char* key : {"mounting_deg", "lever_arm_b_m", "wheel_radius_m", "position_v_m"}) {
      const auto ds = decisions_of(all, name, key);
      if (ds.empty()) continue;
      const std::string path = "modules[" + std::to_string(i) + "]." + key;
      const auto it = notes.comments.find(path);
      const bool was_todo = it != notes.comments.end() && it->second.find("TODO") != std::string::npos;
      std::string text;
      if (ds.front()->relative) {
        const bool measured = std::find(reference_measured.begin(), reference_measured.end(), name) != reference_measured.end();
        if (measured) {
          text = "measured against the reference (calibration.yaml)";
        } else {
          text = std::string("relative to the other side: ") + to_string(ds.front()->outcome) + " (calibration.yaml)";
          if (was_todo)
            text = "TODO: the absolute radius is still a guess (" + text +
                   "); `wheelins calibrate --reference` measures it, or measure it";
        }
      } else {
        // Parts grouped by outcome: "pitch, yaw estimated; roll not estimable".
        std::string guess;
        for (CalibrationOutcome o : {CalibrationOutcome::kEstimated, CalibrationOutcome::kWeak, CalibrationOutcome::kKept,
                                     CalibrationOutcome::kNotEstimable}) {
          std::string parts;
          for (const auto* d : ds)
            if (d->outcome == o) parts += (parts.empty() ? "" : ", ") + std::string(component_names(key)[d->component]);
          if (!parts.empty()) text += (text.empty() ? "" : "; ") + parts + " " + to_string(o);
        }
        for (const auto* d : ds)
          if (d->outcome != CalibrationOutcome::kEstimated && !d->without_effect)
            guess += (guess.empty() ? "" : ", ") + std::string(component_names(key)[d->component]);
        text = "calibrated: " + text + " (calibration.yaml)";
        if (was_todo && !guess.empty()) text = "TODO: still a guess: " + guess + "; " + text;
      }
      notes.comments[path] = text;
    }
  }
  return notes;
}

std::string calibration_yaml(const InstallationCalibration& cal, const Manifest& m) {
  std::string y =
      "# wheelins installation calibration (docs/filter.md section 15): per module the\n"
      "# estimates from the data, their 1 sigma, the manifest's values, and whether the data\n"
      "# determined them (observed: true when the data shrink the prior's 1 sigma below half),\n"
      "# and per part the outcome -- the same words as the console table and the refined\n"
      "# manifest's notes: estimated (the data determine it; the estimate is used), weak (the\n"
      "# data moved it without determining it; the estimate, drawn towards the manifest's value\n"
      "# by its prior, is used), kept (no information: the manifest's value), not estimable\n"
      "# (not estimated by design: the manifest's value, re-expressed in the calibrated axes).\n"
      "# The estimate column is what the run navigated with and `wheelins calibrate` writes.\n"
      "# The estimates are in the manifest's keys and units: paste them into the module.\n"
      "# A Wheel-IMU's mounting_deg roll (about the axle) and lever_arm_b_m x (along it) are\n"
      "# unobservable and without effect; they are kept. Its wheel_radius_m is relative to the\n"
      "# Wheel-IMUs on the other side (the absolute radius is not observable).\n";
  y += "manifest: \"" + m.path.string() + "\"\n";
  y += "modules:\n";
  const double d = 180.0 / kPi;
  const std::vector<CalibrationDecision> all = calibration_decisions(cal);
  auto outcome = [&](const std::string& module, const char* key) {
    return "      outcome: " + outcome_yaml(decisions_of(all, module, key)) + "\n";
  };
  for (const auto& c : cal.wheels) {
    y += "  " + c.module + ":\n";
    y += "    turns: " + std::to_string(c.turns) + "  # whole wheel turns used\n";
    y += "    mounting_deg:\n";
    y += "      estimate: " + list3(c.mounting_rpy.x() * d, c.mounting_rpy.y() * d, c.mounting_rpy.z() * d) + "\n";
    y += "      std: " + list3(0.0, c.axle_tilt_y.std * d, c.axle_tilt_z.std * d, 3) + "  # roll: not estimated\n";
    y += "      manifest: " + list3(c.manifest_mounting_rpy.x() * d, c.manifest_mounting_rpy.y() * d, c.manifest_mounting_rpy.z() * d) + "\n";
    y += std::string("      observed: [false, ") + yn(c.axle_tilt_y.observed) + ", " + yn(c.axle_tilt_z.observed) + "]\n";
    y += outcome(c.module, "mounting_deg");
    y += "    lever_arm_b_m:\n";
    const Vec3 l = c.lever_arm_inB();
    y += "      estimate: " + list3(l.x(), l.y(), l.z()) + "\n";
    y += "      std: " + list3(c.lever_arm[0].std, c.lever_arm[1].std, c.lever_arm[2].std, 3) + "\n";
    y += "      manifest: " + list3(c.manifest_lever_arm.x(), c.manifest_lever_arm.y(), c.manifest_lever_arm.z()) + "\n";
    y += std::string("      observed: [false, ") + yn(c.lever_arm[1].observed) + ", " + yn(c.lever_arm[2].observed) + "]\n";
    y += outcome(c.module, "lever_arm_b_m");
    y += "    accel_residual_rms_m_s2: " + num(c.accel_residual_rms, 4) + "  # per-turn residual of the lever-arm fit\n";
    y += "    wheel_radius_m:  # relative to the other side's wheel; the two sides' mean is the manifest's\n";
    y += "      estimate: " + num(c.wheel_radius.value, 9) + "\n";
    y += "      std: " + num(c.wheel_radius.std, 3) + "  # of the ratio to the other side, not of the absolute radius\n";
    y += "      manifest: " + num(c.manifest_wheel_radius, 9) + "\n";
    y += std::string("      observed: ") + yn(c.wheel_radius.observed) + "\n";
    y += outcome(c.module, "wheel_radius_m");
  }
  for (const auto& c : cal.bodies) {
    y += "  " + c.module + ":\n";
    y += "    turning_s: " + num(c.turning_time, 4) + "  # time turning, which shows the vehicle's z-axis\n";
    y += "    mounting_deg:\n";
    y += "      estimate: " + list3(c.mounting_rpy.x() * d, c.mounting_rpy.y() * d, c.mounting_rpy.z() * d) + "\n";
    y += "      std: " + list3(c.tilt_x.std * d, c.tilt_y.std * d, c.yaw.std * d, 3) + "  # of the v-frame about v x, y and z\n";
    y += "      manifest: " + list3(c.manifest_mounting_rpy.x() * d, c.manifest_mounting_rpy.y() * d, c.manifest_mounting_rpy.z() * d) + "\n";
    y += std::string("      observed: [") + yn(c.tilt_x.observed) + ", " + yn(c.tilt_y.observed) + ", " + yn(c.yaw.observed) + "]\n";
    y += outcome(c.module, "mounting_deg");
    y += "    yaw_fit:  # the yaw from the lateral specific force against the Wheel-IMUs' axle accelerometers\n";
    y += "      bins: " + std::to_string(c.yaw_bins) + "\n";
    y += "      excitation_m_s2: " + num(c.yaw_excitation, 4) + "  # RMS forward specific force about its 60 s means\n";
    y += "      residual_rms_m_s2: " + num(c.yaw_residual_rms, 4) + "\n";
    const Vec3 p = c.manifest_position;
    y += "    position_v_m:  # x, y fitted with the yaw, relative to the Wheel-IMUs' manifest positions\n";
    y += "      estimate: " + list3(p.x() + c.position_x.value, p.y() + c.position_y.value, p.z()) + "\n";
    y += "      std: " + list3(c.position_x.std, c.position_y.std, 0.0, 3) + "  # z: not estimated\n";
    y += "      manifest: " + list3(p.x(), p.y(), p.z()) + "\n";
    y += std::string("      observed: [") + yn(c.position_x.observed) + ", " + yn(c.position_y.observed) + ", false]\n";
    y += outcome(c.module, "position_v_m");
  }
  return y;
}

std::string calibration_report(const InstallationCalibration& cal) {
  std::string t = "installation calibration (estimate +- 1 sigma, manifest):\n";
  if (cal.empty()) return t + "  no module in the run\n";
  const std::vector<CalibrationDecision> all = calibration_decisions(cal);
  auto said = [&](const std::string& module, const char* key) { return "  " + tags(decisions_of(all, module, key)); };
  const double d = 180.0 / kPi;
  char line[400];
  for (const auto& c : cal.wheels) {
    std::snprintf(line, sizeof line,
                  "  %-10s %5d turns  mounting pitch %.3f +- %.3f (%.3f), yaw %.3f +- %.3f (%.3f) deg",
                  c.module.c_str(), c.turns, c.mounting_rpy.y() * d, c.axle_tilt_y.std * d,
                  c.manifest_mounting_rpy.y() * d, c.mounting_rpy.z() * d, c.axle_tilt_z.std * d,
                  c.manifest_mounting_rpy.z() * d);
    t += line + said(c.module, "mounting_deg") + "\n";
    const Vec3 l = c.lever_arm_inB();
    std::snprintf(line, sizeof line, "  %-10s %5s        lever arm y %.2f +- %.2f (%.2f), z %.2f +- %.2f (%.2f) mm", "",
                  "", l.y() * 1e3, c.lever_arm[1].std * 1e3, c.manifest_lever_arm.y() * 1e3, l.z() * 1e3,
                  c.lever_arm[2].std * 1e3, c.manifest_lever_arm.z() * 1e3);
    t += line + said(c.module, "lever_arm_b_m") + "\n";
    std::snprintf(line, sizeof line, "  %-10s %5s        wheel radius %.5f +- %.5f (%.5f) m, relative to the other side", "",
                  "", c.wheel_radius.value, c.wheel_radius.std, c.manifest_wheel_radius);
    t += line + said(c.module, "wheel_radius_m") +
         (c.wheel_radius.observed ? "\n" : " (needs a Wheel-IMU on the other side)\n");
  }
  for (const auto& c : cal.bodies) {
    std::snprintf(line, sizeof line,
                  "  %-10s body        mounting roll %.3f (%.3f), pitch %.3f (%.3f), yaw %.3f +- %.3f (%.3f) deg, "
                  "z-axis +- %.3f, %.3f deg",
                  c.module.c_str(), c.mounting_rpy.x() * d, c.manifest_mounting_rpy.x() * d, c.mounting_rpy.y() * d,
                  c.manifest_mounting_rpy.y() * d, c.mounting_rpy.z() * d, c.yaw.std * d,
                  c.manifest_mounting_rpy.z() * d, c.tilt_x.std * d, c.tilt_y.std * d);
    t += line + said(c.module, "mounting_deg") +
         (c.yaw.observed ? "\n" : " (the yaw needs a Wheel-IMU in the run and acceleration)\n");
    std::snprintf(line, sizeof line,
                  "  %-10s %5s        position x %+.1f +- %.1f, y %+.1f +- %.1f mm from the manifest's "
                  "(relative to the wheels)",
                  "", "", c.position_x.value * 1e3, c.position_x.std * 1e3, c.position_y.value * 1e3,
                  c.position_y.std * 1e3);
    t += line + said(c.module, "position_v_m") + "\n";
  }
  t += "  (estimated: the data determine it; weak: the data moved it without determining it, the estimate drawn\n"
       "   towards the manifest's value is used; kept: no information, the manifest's value; not estimable: not\n"
       "   estimated by design, the manifest's value)\n";
  return t;
}

}  // namespace wheelins
