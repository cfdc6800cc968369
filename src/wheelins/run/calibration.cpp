// The calibration pass of a run (calibration.hpp).
#include "wheelins/run/calibration.hpp"

#include <cmath>
#include <cstdio>
#include <memory>

#include "wheelins/io/imu_file.hpp"
#include "wheelins/run/input_checks.hpp"
#include "wheelins/util/progress.hpp"

namespace wheelins {
namespace fs = std::filesystem;

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
  for (const auto& name : modules) {
    const ModuleSpec* spec = m.find(name);
    if (!spec) throw InputError("'" + m.path.string() + "': no module '" + name + "'");
    specs.push_back(spec);
    total += binary_samples(*spec);
  }
  InstallationCalibration out;
  std::vector<std::unique_ptr<WheelImuCalibrator>> wheels;
  Progress bar("calibrating", total, progress);
  std::uint64_t done = 0;
  for (const ModuleSpec* spec : specs) {
    // The samples the navigator will see: the same reader and input checks, with their
    // warnings left to the navigation pass (which reads the same file again).
    auto reader = std::make_unique<ImuFileReader>(m.resolve(spec->file), imu_read_options(*spec, {}));
    CheckedStream stream(std::move(reader), *spec, m, isolate_faults, WarningSink{});
    auto feed = [&](auto& cal) {
      ImuSample s;
      while (stream.next(s) && s.t <= t_end) {
        cal.add(s);
        if ((++done & 0xFFFF) == 0) bar.update(done);
      }
    };
    if (spec->kind == ModuleKind::kWheel) {
      // The rate series reserved for the file's span (binary files: from the sample count).
      double expected_end = t_end;
      const std::uint64_t n = binary_samples(*spec);
      if (!std::isfinite(expected_end) && n > 0 && spec->rate_hz > 0.0)
        expected_end = m.static_start + static_cast<double>(n) / spec->rate_hz;
      auto cal = std::make_unique<WheelImuCalibrator>(*spec, m.static_start, m.static_end, opt, expected_end);
      feed(*cal);
      out.wheels.push_back(cal->result());
      wheels.push_back(std::move(cal));
    } else {
      BodyImuCalibrator cal(*spec, m.static_start, m.static_end, opt);
      feed(cal);
      out.bodies.push_back(cal.result());
    }
  }
  bar.finish();
  std::vector<const WheelImuCalibrator*> views;
  for (const auto& c : wheels) views.push_back(c.get());
  estimate_relative_radius(views, opt, out.wheels);
  return out;
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
      if (spec.name == c.module) spec.mounting_rpy = c.mounting_rpy;
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

}  // namespace

std::string calibration_yaml(const InstallationCalibration& cal, const Manifest& m) {
  std::string y =
      "# wheelins installation calibration (docs/filter.md section 15): per module the\n"
      "# estimates from the data, their 1 sigma, the manifest's values, and whether the data\n"
      "# determined them (observed: false = the manifest value kept, its prior sigma given).\n"
      "# The estimates are in the manifest's keys and units: paste them into the module.\n"
      "# A Wheel-IMU's mounting_deg roll (about the axle) and lever_arm_b_m x (along it) are\n"
      "# unobservable and without effect; they are kept. Its wheel_radius_m is relative to the\n"
      "# Wheel-IMUs on the other side (the absolute radius is not observable).\n";
  y += "manifest: \"" + m.path.string() + "\"\n";
  y += "modules:\n";
  const double d = 180.0 / kPi;
  for (const auto& c : cal.wheels) {
    y += "  " + c.module + ":\n";
    y += "    turns: " + std::to_string(c.turns) + "  # whole wheel turns used\n";
    y += "    mounting_deg:\n";
    y += "      estimate: " + list3(c.mounting_rpy.x() * d, c.mounting_rpy.y() * d, c.mounting_rpy.z() * d) + "\n";
    y += "      std: " + list3(0.0, c.axle_tilt_y.std * d, c.axle_tilt_z.std * d, 3) + "  # roll: not estimated\n";
    y += "      manifest: " + list3(c.manifest_mounting_rpy.x() * d, c.manifest_mounting_rpy.y() * d, c.manifest_mounting_rpy.z() * d) + "\n";
    y += std::string("      observed: [false, ") + yn(c.axle_tilt_y.observed) + ", " + yn(c.axle_tilt_z.observed) + "]\n";
    y += "    lever_arm_b_m:\n";
    const Vec3 l = c.lever_arm_inB();
    y += "      estimate: " + list3(l.x(), l.y(), l.z()) + "\n";
    y += "      std: " + list3(c.lever_arm[0].std, c.lever_arm[1].std, c.lever_arm[2].std, 3) + "\n";
    y += "      manifest: " + list3(c.manifest_lever_arm.x(), c.manifest_lever_arm.y(), c.manifest_lever_arm.z()) + "\n";
    y += std::string("      observed: [false, ") + yn(c.lever_arm[1].observed) + ", " + yn(c.lever_arm[2].observed) + "]\n";
    y += "    accel_residual_rms_m_s2: " + num(c.accel_residual_rms, 4) + "  # per-turn residual of the lever-arm fit\n";
    y += "    wheel_radius_m:  # relative to the other side's wheel; the two sides' mean is the manifest's\n";
    y += "      estimate: " + num(c.wheel_radius.value, 9) + "\n";
    y += "      std: " + num(c.wheel_radius.std, 3) + "  # of the ratio to the other side, not of the absolute radius\n";
    y += "      manifest: " + num(c.manifest_wheel_radius, 9) + "\n";
    y += std::string("      observed: ") + yn(c.wheel_radius.observed) + "\n";
  }
  for (const auto& c : cal.bodies) {
    y += "  " + c.module + ":\n";
    y += "    turning_s: " + num(c.turning_time, 4) + "  # time turning, which shows the vehicle's z-axis\n";
    y += "    mounting_deg:\n";
    y += "      estimate: " + list3(c.mounting_rpy.x() * d, c.mounting_rpy.y() * d, c.mounting_rpy.z() * d) + "\n";
    y += "      std: " + list3(c.tilt_x.std * d, c.tilt_y.std * d, 0.0, 3) + "  # of the v-frame about v x and y; yaw: not estimated\n";
    y += "      manifest: " + list3(c.manifest_mounting_rpy.x() * d, c.manifest_mounting_rpy.y() * d, c.manifest_mounting_rpy.z() * d) + "\n";
    y += std::string("      observed: [") + yn(c.tilt_x.observed) + ", " + yn(c.tilt_y.observed) + ", false]\n";
  }
  return y;
}

std::string calibration_report(const InstallationCalibration& cal) {
  std::string t = "installation calibration (estimate +- 1 sigma, manifest):\n";
  if (cal.empty()) return t + "  no module in the run\n";
  const double d = 180.0 / kPi;
  char line[400];
  for (const auto& c : cal.wheels) {
    std::snprintf(line, sizeof line,
                  "  %-10s %5d turns  mounting pitch %.3f +- %.3f (%.3f), yaw %.3f +- %.3f (%.3f) deg%s\n",
                  c.module.c_str(), c.turns, c.mounting_rpy.y() * d, c.axle_tilt_y.std * d,
                  c.manifest_mounting_rpy.y() * d, c.mounting_rpy.z() * d, c.axle_tilt_z.std * d,
                  c.manifest_mounting_rpy.z() * d,
                  c.axle_tilt_y.observed && c.axle_tilt_z.observed ? "" : "  (not observed: manifest kept)");
    t += line;
    const Vec3 l = c.lever_arm_inB();
    std::snprintf(line, sizeof line,
                  "  %-10s %5s        lever arm y %.2f +- %.2f (%.2f), z %.2f +- %.2f (%.2f) mm%s\n", "", "",
                  l.y() * 1e3, c.lever_arm[1].std * 1e3, c.manifest_lever_arm.y() * 1e3, l.z() * 1e3,
                  c.lever_arm[2].std * 1e3, c.manifest_lever_arm.z() * 1e3,
                  c.lever_arm[1].observed && c.lever_arm[2].observed ? "" : "  (not observed: manifest kept)");
    t += line;
    std::snprintf(line, sizeof line, "  %-10s %5s        wheel radius %.5f +- %.5f (%.5f) m%s\n", "", "",
                  c.wheel_radius.value, c.wheel_radius.std, c.manifest_wheel_radius,
                  c.wheel_radius.observed ? "  (relative to the other side)"
                                          : "  (not observed: manifest kept; needs a Wheel-IMU on the "
                                            "other side)");
    t += line;
  }
  for (const auto& c : cal.bodies) {
    std::snprintf(line, sizeof line,
                  "  %-10s body        mounting roll %.3f (%.3f), pitch %.3f (%.3f) deg, z-axis +- %.3f, %.3f deg; "
                  "yaw %.3f deg (manifest, not estimated)%s\n",
                  c.module.c_str(), c.mounting_rpy.x() * d, c.manifest_mounting_rpy.x() * d,
                  c.mounting_rpy.y() * d, c.manifest_mounting_rpy.y() * d, c.tilt_x.std * d, c.tilt_y.std * d,
                  c.mounting_rpy.z() * d, c.tilt_x.observed && c.tilt_y.observed ? "" : "  (not observed: manifest kept)");
    t += line;
  }
  return t;
}

}  // namespace wheelins
