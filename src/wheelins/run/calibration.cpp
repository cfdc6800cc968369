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

std::vector<WheelImuCalibration> calibrate_installation(
    const Manifest& m, const std::vector<std::string>& modules,
    const InstallationCalibrationOptions& opt, bool isolate_faults, bool progress, double t_end) {
  std::uint64_t total = 0;
  std::vector<const ModuleSpec*> wheels;
  for (const auto& name : modules) {
    const ModuleSpec* spec = m.find(name);
    if (!spec) throw InputError("'" + m.path.string() + "': no module '" + name + "'");
    if (spec->kind != ModuleKind::kWheel) continue;
    wheels.push_back(spec);
    std::error_code ec;
    if (spec->layout == FileLayout::kBinary)
      total += fs::file_size(m.resolve(spec->file), ec) / (7 * sizeof(double));
  }
  std::vector<WheelImuCalibration> out;
  Progress bar("calibrating", total, progress);
  std::uint64_t done = 0;
  for (const ModuleSpec* spec : wheels) {
    // The samples the navigator will see: the same reader and input checks, with their
    // warnings left to the navigation pass (which reads the same file again).
    auto reader = std::make_unique<ImuFileReader>(m.resolve(spec->file), imu_read_options(*spec, {}));
    CheckedStream stream(std::move(reader), *spec, m, isolate_faults, WarningSink{});
    WheelImuCalibrator cal(*spec, m.static_start, m.static_end, opt);
    ImuSample s;
    while (stream.next(s) && s.t <= t_end) {
      cal.add(s);
      if ((++done & 0xFFFF) == 0) bar.update(done);
    }
    out.push_back(cal.result());
  }
  bar.finish();
  return out;
}

Manifest apply_calibration(Manifest m, const std::vector<WheelImuCalibration>& cal) {
  for (const auto& c : cal)
    for (auto& spec : m.modules)
      if (spec.name == c.module) {
        spec.mounting_rpy = c.mounting_rpy;
        spec.lever_arm_inB = c.lever_arm_inB();
      }
  return m;
}

namespace {

std::string num(double v, int digits = 6) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}

std::string list3(double a, double b, double c, int digits = 6) {
  return "[" + num(a, digits) + ", " + num(b, digits) + ", " + num(c, digits) + "]";
}

const char* yn(bool b) { return b ? "true" : "false"; }

}  // namespace

std::string calibration_yaml(const std::vector<WheelImuCalibration>& cal, const Manifest& m) {
  std::string y =
      "# wheelins installation calibration (docs/filter.md section 15): per Wheel-IMU the\n"
      "# estimates from the data, their 1 sigma, the manifest's values, and whether the data\n"
      "# determined them (observed: false = the manifest value kept, its prior sigma given).\n"
      "# The estimates are in the manifest's keys and units: paste them into the module.\n"
      "# mounting_deg roll (about the axle) and lever_arm_b_m x (along it) are unobservable\n"
      "# and without effect on a Wheel-IMU; they are kept.\n";
  y += "manifest: \"" + m.path.string() + "\"\n";
  y += "modules:\n";
  const double d = 180.0 / kPi;
  for (const auto& c : cal) {
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
  }
  return y;
}

std::string calibration_report(const std::vector<WheelImuCalibration>& cal) {
  std::string t = "installation calibration (Wheel-IMUs; estimate +- 1 sigma, manifest):\n";
  if (cal.empty()) return t + "  no Wheel-IMU in the run\n";
  const double d = 180.0 / kPi;
  char line[400];
  for (const auto& c : cal) {
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
  }
  return t;
}

}  // namespace wheelins
