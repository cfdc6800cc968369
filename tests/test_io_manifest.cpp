#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include "io_test_util.hpp"
#include "wheelins/io/manifest.hpp"

using namespace wheelins;
using namespace wheelins::iotest;

namespace {

Manifest sample_manifest() {
  Manifest m;
  m.name = "triple \"ins\" test";
  m.truth_file = "ground_truth/GINS-body.bin";
  m.odometer_file = "/abs/odo.bin";
  m.static_start = 132030.005;
  m.static_end = 132067.5;
  m.origin = {30.528 * kDeg, 114.356 * kDeg, 23.7};
  m.initial_heading = -93.25 * kDeg;
  m.gravity = 9.7936;
  m.earth_rotation = false;
  m.track_width = 0.33;
  for (int i = 0; i < 3; ++i) {
    ModuleSpec s;
    s.name = "m" + std::to_string(i);
    s.kind = i == 2 ? ModuleKind::kBody : ModuleKind::kWheel;
    s.group = i == 2 ? "body" : (i == 0 ? "left-wheel" : "right-wheel");
    s.chip = "C" + std::to_string(i + 1);
    s.file = "dir/tri_C" + std::to_string(i + 1) + "_imu.bin";
    s.format = i == 1 ? SampleFormat::kIncrement : SampleFormat::kRate;
    s.layout = i == 2 ? FileLayout::kText : FileLayout::kBinary;
    s.rate_hz = 200.0 - 0.5 * i;
    s.time_offset = -0.0125 * i;
    s.p_inV = Vec3(0.01 * i, i == 0 ? -0.165 : 0.165, 0.1);
    s.lever_arm_inB = i == 2 ? Vec3::Zero() : Vec3(-0.015, 0.005, 0.005);
    s.mounting_rpy = Vec3(0.3, -1.7, 91.0 + i) * kDeg;
    s.axle_sign = i == 0 ? -1 : 1;
    s.wheel_radius = i == 2 ? 0.0 : 0.097 + 0.001 * i;
    s.noise.gyro_arw = 0.31 * kDeg / 60.0;
    s.noise.acc_vrw = 0.07 / 60.0;
    s.noise.gyro_bias_std = (20.0 + i) * kDeg / 3600.0;
    s.noise.acc_bias_std = 0.02;
    s.noise.gyro_sf_std = 1500e-6;
    s.noise.acc_sf_std = 2500e-6;
    s.noise.gyro_bias_tau = 0.5 * 3600.0;
    s.noise.acc_bias_tau = 1.5 * 3600.0;
    s.noise.gyro_sf_tau = 2 * 3600.0;
    s.noise.acc_sf_tau = 0.25 * 3600.0;
    m.modules.push_back(s);
  }
  return m;
}

void expect_same_noise(const ImuNoise& a, const ImuNoise& b) {
  EXPECT_EQ(a.gyro_arw, b.gyro_arw);
  EXPECT_EQ(a.acc_vrw, b.acc_vrw);
  EXPECT_EQ(a.gyro_bias_std, b.gyro_bias_std);
  EXPECT_EQ(a.acc_bias_std, b.acc_bias_std);
  EXPECT_EQ(a.gyro_sf_std, b.gyro_sf_std);
  EXPECT_EQ(a.acc_sf_std, b.acc_sf_std);
  EXPECT_EQ(a.gyro_bias_tau, b.gyro_bias_tau);
  EXPECT_EQ(a.acc_bias_tau, b.acc_bias_tau);
  EXPECT_EQ(a.gyro_sf_tau, b.gyro_sf_tau);
  EXPECT_EQ(a.acc_sf_tau, b.acc_sf_tau);
}

/// Exact equality of every value (paths compared as written).
void expect_same(const Manifest& a, const Manifest& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.truth_file, b.truth_file);
  EXPECT_EQ(a.odometer_file, b.odometer_file);
  EXPECT_EQ(a.static_start, b.static_start);
  EXPECT_EQ(a.static_end, b.static_end);
  EXPECT_EQ(a.origin.lat, b.origin.lat);
  EXPECT_EQ(a.origin.lon, b.origin.lon);
  EXPECT_EQ(a.origin.h, b.origin.h);
  EXPECT_EQ(a.initial_heading, b.initial_heading);
  EXPECT_EQ(a.gravity, b.gravity);
  EXPECT_EQ(a.earth_rotation, b.earth_rotation);
  EXPECT_EQ(a.track_width, b.track_width);
  ASSERT_EQ(a.modules.size(), b.modules.size());
  for (std::size_t i = 0; i < a.modules.size(); ++i) {
    SCOPED_TRACE("module " + std::to_string(i));
    const ModuleSpec &x = a.modules[i], &y = b.modules[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.kind, y.kind);
    EXPECT_EQ(x.group, y.group);
    EXPECT_EQ(x.chip, y.chip);
    EXPECT_EQ(x.file, y.file);
    EXPECT_EQ(x.format, y.format);
    EXPECT_EQ(x.layout, y.layout);
    EXPECT_EQ(x.rate_hz, y.rate_hz);
    EXPECT_EQ(x.time_offset, y.time_offset);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(x.p_inV[k], y.p_inV[k]);
      EXPECT_EQ(x.lever_arm_inB[k], y.lever_arm_inB[k]);
      EXPECT_EQ(x.mounting_rpy[k], y.mounting_rpy[k]);
    }
    EXPECT_EQ(x.axle_sign, y.axle_sign);
    EXPECT_EQ(x.wheel_radius, y.wheel_radius);
    expect_same_noise(x.noise, y.noise);
  }
}

const char* kMinimal = R"(format: wheelins-manifest-1
initial: {lat_deg: 30.5, lon_deg: 114.25, h_m: 20, heading_deg: 90}
modules:
  - name: left
    kind: wheel
    file: left.bin
    wheel_radius_m: 0.097
)";

/// kMinimal's module list replaced by `modules_yaml` (which starts with "modules:").
std::string with_modules(const std::string& modules_yaml) {
  return "format: wheelins-manifest-1\n"
         "initial: {lat_deg: 30.5, lon_deg: 114.25, h_m: 20, heading_deg: 90}\n" +
         modules_yaml;
}

const WarningSink kQuiet = [](const std::string&) {};

std::string load_error(const ScratchDir& dir, const std::string& yaml) {
  const auto file = dir / "m.yaml";
  write_text(file, yaml);
  return error_of([&] { load_manifest(file, kQuiet); });
}

}  // namespace

TEST(IoManifest, SaveLoadRoundTripIsExact) {
  ScratchDir dir;
  const Manifest m = sample_manifest();
  save_manifest(m, dir / "m.yaml");
  const Manifest back = load_manifest(dir / "m.yaml", kQuiet);
  expect_same(m, back);
  EXPECT_EQ(back.path, std::filesystem::absolute(dir / "m.yaml").lexically_normal());
  EXPECT_FALSE(iotest::partial_left(dir / "m.yaml"));
  // Saving the loaded manifest again gives the same text.
  save_manifest(back, dir / "m2.yaml");
  std::ifstream a(dir / "m.yaml"), b(dir / "m2.yaml");
  std::stringstream sa, sb;
  sa << a.rdbuf();
  sb << b.rdbuf();
  EXPECT_EQ(sa.str(), sb.str());
}

TEST(IoManifest, RoundTripOfArbitrarySiValues) {
  // Values that did not come from human units still come back bit-identical.
  std::mt19937_64 rng(42);
  // Within the keys' physical ranges (docs/manifest.md).
  std::uniform_real_distribution<double> u(-3.0, 3.0), pos(1e-2, 5.0);
  ScratchDir dir;
  for (int trial = 0; trial < 50; ++trial) {
    Manifest m = sample_manifest();
    m.origin = {u(rng) / 2.0, u(rng), u(rng) * 100.0};
    m.initial_heading = u(rng);
    for (auto& s : m.modules) {
      s.mounting_rpy = Vec3(u(rng), u(rng) / 2.0, u(rng));
      s.p_inV = Vec3(u(rng), u(rng), u(rng));
      s.noise.gyro_arw = pos(rng) * 1e-3;
      s.noise.acc_vrw = pos(rng) * 1e-2;
      s.noise.gyro_bias_std = pos(rng) * 1e-4;
      s.noise.gyro_sf_std = pos(rng) * 1e-3;
      s.noise.gyro_bias_tau = pos(rng) * 1e4;
      s.noise.acc_sf_tau = pos(rng) * 1e3;
    }
    save_manifest(m, dir / "r.yaml");
    expect_same(m, load_manifest(dir / "r.yaml", kQuiet));
  }
}

TEST(IoManifest, WithoutAnInitialHeadingTheRunStartsInALocalFrame) {
  ScratchDir dir;
  std::string text = kMinimal;
  text.replace(text.find(", heading_deg: 90"), 17, "");
  write_text(dir / "m.yaml", text);
  const Manifest m = load_manifest(dir / "m.yaml", kQuiet);
  EXPECT_FALSE(m.heading_known);
  EXPECT_EQ(m.initial_heading, 0.0);
  EXPECT_FALSE(vehicle_setup(m).heading_known);
  // Saved and read back: still no heading (none is invented).
  save_manifest(m, dir / "m2.yaml");
  EXPECT_EQ(read_text_file(dir / "m2.yaml").find("heading_deg"), std::string::npos);
  EXPECT_FALSE(load_manifest(dir / "m2.yaml", kQuiet).heading_known);
  write_text(dir / "m.yaml", kMinimal);
  EXPECT_TRUE(load_manifest(dir / "m.yaml", kQuiet).heading_known);
}

TEST(IoManifest, AxleAxisAntennaWheelbaseAndTruthOffsetRoundTrip) {
  ScratchDir dir;
  std::string text = kMinimal;
  text += "    axle_axis: z\n";
  text.insert(text.find("modules:"), "truth_time_offset_s: 847.85\nvehicle: {track_m: 1.46, wheelbase_m: 2.62, antenna_v_m: [0.4, 0.1, -1.5]}\n");
  write_text(dir / "m.yaml", text);
  const Manifest m = load_manifest(dir / "m.yaml", kQuiet);
  EXPECT_EQ(m.modules[0].axle_axis, 2);
  EXPECT_EQ(m.truth_time_offset, 847.85);
  EXPECT_EQ(m.wheelbase, 2.62);
  ASSERT_TRUE(m.antenna_inV.has_value());
  EXPECT_EQ(*m.antenna_inV, Vec3(0.4, 0.1, -1.5));
  save_manifest(m, dir / "m2.yaml");
  const Manifest m2 = load_manifest(dir / "m2.yaml", kQuiet);
  EXPECT_EQ(m2.modules[0].axle_axis, 2);
  EXPECT_EQ(m2.truth_time_offset, 847.85);
  EXPECT_EQ(m2.wheelbase, 2.62);
  EXPECT_EQ(*m2.antenna_inV, *m.antenna_inV);
  text = kMinimal;
  text += "    axle_axis: w\n";
  write_text(dir / "m.yaml", text);
  EXPECT_HAS(load_error(dir, text), "axle_axis");
}

TEST(IoManifest, MinimalManifestUsesDefaultsAndConvertsUnits) {
  ScratchDir dir;
  write_text(dir / "m.yaml", kMinimal);
  const Manifest m = load_manifest(dir / "m.yaml", kQuiet);
  EXPECT_DOUBLE_EQ(m.origin.lat, 30.5 * kDeg);
  EXPECT_DOUBLE_EQ(m.origin.lon, 114.25 * kDeg);
  EXPECT_EQ(m.origin.h, 20.0);
  EXPECT_DOUBLE_EQ(m.initial_heading, kPi / 2);
  EXPECT_FALSE(m.gravity.has_value());
  EXPECT_NEAR(m.gravity_or_default(), 9.7936, 1e-3);
  EXPECT_TRUE(m.earth_rotation);
  ASSERT_EQ(m.modules.size(), 1u);
  const ModuleSpec& s = m.modules[0];
  EXPECT_EQ(s.group, "left");  // defaults to the name
  EXPECT_EQ(s.rate_hz, 200.0);
  EXPECT_EQ(s.format, SampleFormat::kRate);
  EXPECT_EQ(s.layout, FileLayout::kBinary);
  EXPECT_EQ(s.axle_sign, 1);
  // No noise stated: ImuNoise's defaults, with the velocity random walk of a wheel module.
  ImuNoise defaults;
  defaults.acc_vrw = kDefaultWheelVrw;
  expect_same_noise(s.noise, defaults);
  EXPECT_EQ(s.noise_stated, 0u);
  EXPECT_EQ(m.resolve(s.file), m.path.parent_path() / "left.bin");
  EXPECT_EQ(m.resolve("/x/y.bin"), std::filesystem::path("/x/y.bin"));
  EXPECT_EQ(m.find("left"), &m.modules[0]);
  EXPECT_EQ(m.find("right"), nullptr);
}

TEST(IoManifest, HumanNoiseUnitsBecomeSi) {
  ScratchDir dir;
  write_text(dir / "m.yaml", with_modules(R"(modules:
  - {name: b, kind: body, file: b.bin, mounting_deg: [0, 0, 90],
     noise: {gyro_arw_deg_sqrt_h: 0.6, acc_vrw_m_s_sqrt_h: 0.12, gyro_bias_deg_h: 36,
             acc_bias_m_s2: 0.05, gyro_sf_ppm: 1000, acc_sf_ppm: 2000, gyro_bias_tau_h: 2,
             acc_bias_tau_h: 0.5, gyro_sf_tau_h: 1, acc_sf_tau_h: 4}}
)"));
  const ImuNoise n = load_manifest(dir / "m.yaml", kQuiet).modules[0].noise;
  EXPECT_DOUBLE_EQ(n.gyro_arw, 0.6 * kDeg / 60.0);
  EXPECT_DOUBLE_EQ(n.acc_vrw, 0.002);
  EXPECT_DOUBLE_EQ(n.gyro_bias_std, 0.01 * kDeg);
  EXPECT_DOUBLE_EQ(n.acc_bias_std, 0.05);
  EXPECT_DOUBLE_EQ(n.gyro_sf_std, 1e-3);
  EXPECT_DOUBLE_EQ(n.acc_sf_std, 2e-3);
  EXPECT_DOUBLE_EQ(n.gyro_bias_tau, 7200.0);
  EXPECT_DOUBLE_EQ(n.acc_bias_tau, 1800.0);
  EXPECT_DOUBLE_EQ(n.gyro_sf_tau, 3600.0);
  EXPECT_DOUBLE_EQ(n.acc_sf_tau, 14400.0);
}

TEST(IoManifest, SavingElsewhereKeepsRelativePathsPointingAtTheSameFiles) {
  ScratchDir dir;
  write_text(dir / "data/m.yaml", kMinimal);
  const Manifest m = load_manifest(dir / "data/m.yaml", kQuiet);
  save_manifest(m, dir / "configs/copy.yaml");
  const Manifest c = load_manifest(dir / "configs/copy.yaml", kQuiet);
  EXPECT_EQ(c.modules[0].file, std::filesystem::path("../data/left.bin"));
  EXPECT_EQ(c.resolve(c.modules[0].file).lexically_normal(), m.resolve(m.modules[0].file));
}

TEST(IoManifest, AnnotationsAreWrittenAsComments) {
  ScratchDir dir;
  ManifestAnnotations notes;
  notes.header = {"made by a test"};
  notes.comments["modules[1].wheel_radius_m"] = "TODO: measure";
  save_manifest(sample_manifest(), dir / "m.yaml", notes);
  std::ifstream in(dir / "m.yaml");
  std::string line, radius_line;
  bool header = false;
  int radius_lines = 0;
  while (std::getline(in, line)) {
    if (line == "# made by a test") header = true;
    if (line.find("wheel_radius_m:") != std::string::npos && ++radius_lines == 2) radius_line = line;
  }
  EXPECT_TRUE(header);
  EXPECT_HAS(radius_line, "0.098");
  EXPECT_HAS(radius_line, "# TODO: measure");
  expect_same(sample_manifest(), load_manifest(dir / "m.yaml", kQuiet));
}

TEST(IoManifest, MalformedYamlNamesFileAndLine) {
  ScratchDir dir;
  const std::string msg =
      load_error(dir, "format: wheelins-manifest-1\nmodules:\n  - name: a\n    kind: wheel\n  x: : y\n");
  EXPECT_HAS(msg, "m.yaml': line 5, column 3: malformed YAML: end of map not found");
}

TEST(IoManifest, WrongTypeNamesKeyPathAndValue) {
  ScratchDir dir;
  const std::string msg = load_error(dir, with_modules(R"(modules:
  - {name: a, kind: wheel, file: a.bin, wheel_radius_m: 0.1}
  - {name: b, kind: wheel, file: b.bin, wheel_radius_m: 0.1}
  - name: c
    kind: wheel
    file: c.bin
    wheel_radius_m: abc
)"));
  EXPECT_HAS(msg, "m.yaml': modules[2].wheel_radius_m: expected a number, got 'abc'");
  EXPECT_HAS(msg, "line 9");
  EXPECT_HAS(load_error(dir, with_modules("modules:\n  - {name: a, kind: wheel, file: a.bin, "
                                          "wheel_radius_m: 0.1, position_v_m: [1, 2]}\n")),
             "modules[0].position_v_m: expected a list of 3 numbers");
  EXPECT_HAS(load_error(dir, with_modules("modules:\n  - {name: a, kind: wheel, file: a.bin, "
                                          "wheel_radius_m: 0.1, lever_arm_b_m: [1, x, 2]}\n")),
             "modules[0].lever_arm_b_m[1]: expected a number, got 'x'");
  EXPECT_HAS(load_error(dir, with_modules("modules:\n  - {name: a, kind: tyre, file: a.bin}\n")),
             "modules[0].kind: expected wheel or body, got 'tyre'");
  EXPECT_HAS(load_error(dir, std::string(kMinimal) + "earth_rotation: maybe\n"),
             "earth_rotation: expected true or false, got 'maybe'");
  EXPECT_HAS(load_error(dir, std::string(kMinimal) + "gravity_m_s2: .nan\n"),
             "gravity_m_s2: expected a finite number");
  EXPECT_HAS(load_error(dir, with_modules("modules: {name: a}\n")), "modules: expected a list of modules");
}

TEST(IoManifest, MissingRequiredKeys) {
  ScratchDir dir;
  EXPECT_HAS(load_error(dir, with_modules("modules:\n  - {name: a, kind: wheel, wheel_radius_m: 0.1}\n")),
             "m.yaml': modules[0]: missing required key 'file'");
  EXPECT_HAS(load_error(dir, "initial: {lat_deg: 1, lon_deg: 2, h_m: 3, heading_deg: 4}\nmodules: []\n"),
             "missing required key 'format'");
  EXPECT_HAS(load_error(dir, "format: wheelins-manifest-1\ninitial: {lat_deg: 1, lon_deg: 2}\n"),
             "initial: missing required key 'h_m'");
  EXPECT_HAS(load_error(dir, "format: wheelins-manifest-2\n"), "unsupported manifest format 'wheelins-manifest-2'");
  EXPECT_HAS(load_error(dir, ""), "the manifest is empty");
}

TEST(IoManifest, NoModuleAtAll) {
  ScratchDir dir;
  EXPECT_HAS(load_error(dir, with_modules("modules: []\n")), "modules: no IMU module listed");
  EXPECT_HAS(load_error(dir, with_modules("")), "missing required key 'modules'");
}

TEST(IoManifest, DuplicateModuleNamesAndKeys) {
  ScratchDir dir;
  EXPECT_HAS(load_error(dir, with_modules(R"(modules:
  - {name: a, kind: wheel, file: a.bin, wheel_radius_m: 0.1}
  - {name: a, kind: body, file: b.bin}
)")),
             "modules[1].name: duplicate module name 'a' (also modules[0])");
  EXPECT_HAS(load_error(dir, with_modules("modules:\n  - {name: a, kind: wheel, file: a.bin, "
                                          "wheel_radius_m: 0.1, rate_hz: 100, rate_hz: 200}\n")),
             "modules[0].rate_hz: duplicate key");
}

TEST(IoManifest, SteeredWheelRoundTripsAndIsChecked) {
  ScratchDir dir;
  const auto mod = [&](const std::string& extra) {
    return with_modules("modules:\n  - {name: a, file: a.bin" + extra + "}\n");
  };
  write_text(dir / "m.yaml", mod(", kind: wheel, wheel_radius_m: 0.3, steered: true, position_v_m: [2.6, -0.75, 0]"));
  const Manifest m = load_manifest(dir / "m.yaml", kQuiet);
  EXPECT_TRUE(m.modules[0].steered);
  save_manifest(m, dir / "m2.yaml");
  EXPECT_TRUE(load_manifest(dir / "m2.yaml", kQuiet).modules[0].steered);
  EXPECT_HAS(load_error(dir, mod(", kind: body, steered: true")),
             "modules[0].steered: only a wheel module can be steered");
  EXPECT_HAS(load_error(dir, mod(", kind: wheel, wheel_radius_m: 0.3, steered: maybe")),
             "modules[0].steered: expected true or false");
  EXPECT_HAS(load_error(dir, mod(", kind: wheel, wheel_radius_m: 0.3, steered: true, position_v_m: [0.1, 0, 0]")),
             "modules[0].position_v_m: a steered wheel's x is its distance ahead of the rear axle");
}

TEST(IoManifest, YawScaleRoundTripsAndIsChecked) {
  ScratchDir dir;
  const auto mod = [&](const std::string& extra) {
    return with_modules("modules:\n  - {name: a, file: a.bin" + extra + "}\n");
  };
  write_text(dir / "m.yaml", mod(", kind: wheel, wheel_radius_m: 0.3, yaw_scale_ppm: -4200.5"));
  const Manifest m = load_manifest(dir / "m.yaml", kQuiet);
  EXPECT_DOUBLE_EQ(m.modules[0].yaw_scale, -4200.5e-6);
  save_manifest(m, dir / "m2.yaml");
  EXPECT_DOUBLE_EQ(load_manifest(dir / "m2.yaml", kQuiet).modules[0].yaw_scale, -4200.5e-6);
  // Left out when zero.
  write_text(dir / "m3.yaml", mod(", kind: wheel, wheel_radius_m: 0.3"));
  save_manifest(load_manifest(dir / "m3.yaml", kQuiet), dir / "m4.yaml");
  EXPECT_EQ(read_text_file(dir / "m4.yaml").find("yaw_scale_ppm"), std::string::npos);
  EXPECT_HAS(load_error(dir, mod(", kind: body, yaw_scale_ppm: 100")),
             "modules[0].yaw_scale_ppm: only a wheel module has a yaw scale factor");
  EXPECT_HAS(load_error(dir, mod(", kind: wheel, wheel_radius_m: 0.3, yaw_scale_ppm: 60000")), "modules[0].yaw_scale_ppm");
  EXPECT_HAS(load_error(dir, mod(", kind: wheel, wheel_radius_m: 0.3, yaw_scale_ppm: much")), "modules[0].yaw_scale_ppm");
}

TEST(IoManifest, PhysicallyImpossibleValues) {
  ScratchDir dir;
  const auto mod = [&](const std::string& extra) {
    return load_error(dir, with_modules("modules:\n  - {name: a, kind: wheel, file: a.bin" + extra + "}\n"));
  };
  EXPECT_HAS(mod(", wheel_radius_m: -0.1"), "modules[0].wheel_radius_m: must be in [0.01, 2] m");
  EXPECT_HAS(mod(", wheel_radius_m: 0"), "modules[0].wheel_radius_m: must be in [0.01, 2] m");
  EXPECT_HAS(mod(""), "modules[0]: missing required key 'wheel_radius_m'");
  EXPECT_HAS(mod(", wheel_radius_m: 0.1, rate_hz: 0"), "modules[0].rate_hz: must be in [1, 10000] Hz");
  EXPECT_HAS(mod(", wheel_radius_m: 0.1, rate_hz: -200"), "modules[0].rate_hz: must be in [1, 10000] Hz");
  EXPECT_HAS(mod(", wheel_radius_m: 0.1, axle_sign: 2"), "modules[0].axle_sign: must be +1");
  EXPECT_HAS(mod(", wheel_radius_m: 0.1, axle_sign: 0"), "modules[0].axle_sign: must be +1");
  EXPECT_HAS(mod(", wheel_radius_m: 0.1, noise: {gyro_arw_deg_sqrt_h: 0}"),
             "modules[0].noise.gyro_arw_deg_sqrt_h: must be in [0.0001, 100]");
  EXPECT_HAS(mod(", wheel_radius_m: 0.1, noise: {acc_sf_tau_h: -1}"),
             "modules[0].noise.acc_sf_tau_h: must be in [0.001, 10000] h");
  EXPECT_HAS(mod(", wheel_radius_m: 0.1, mounting_deg: [0, 95, 0]"), "modules[0].mounting_deg[1]: pitch");
  EXPECT_HAS(load_error(dir, std::string(kMinimal) + "static_period_s: [10, 5]\n"),
             "static_period_s: end 5 is before start 10");
  EXPECT_HAS(load_error(dir, std::string(kMinimal) + "gravity_m_s2: -9.8\n"), "gravity_m_s2: must be in [9.7, 9.9]");
  // A body module needs no radius; +1 written as "+1" is accepted.
  write_text(dir / "ok.yaml", with_modules("modules:\n  - {name: a, kind: body, file: a.bin, axle_sign: +1}\n"));
  EXPECT_EQ(load_manifest(dir / "ok.yaml", kQuiet).modules[0].axle_sign, 1);
}

TEST(IoManifest, UnknownKeyWarnsWithClosestKnownKey) {
  ScratchDir dir;
  write_text(dir / "m.yaml", std::string(kMinimal) + "    wheel_radius: 0.1\n    noise: {gyro_arw: 1}\nstatic_period: [0, 1]\n");
  std::vector<std::string> warnings;
  const Manifest m = load_manifest(dir / "m.yaml", [&](const std::string& w) { warnings.push_back(w); });
  ASSERT_EQ(warnings.size(), 3u);
  EXPECT_HAS(warnings[0], "m.yaml': static_period: unknown key ignored");
  EXPECT_HAS(warnings[0], "did you mean 'static_period_s'?");
  EXPECT_HAS(warnings[1], "modules[0].wheel_radius: unknown key ignored");
  EXPECT_HAS(warnings[1], "did you mean 'wheel_radius_m'?");
  EXPECT_HAS(warnings[2], "modules[0].noise.gyro_arw: unknown key");
  EXPECT_HAS(warnings[2], "did you mean 'gyro_arw_deg_sqrt_h'?");
  EXPECT_EQ(m.modules[0].wheel_radius, 0.097);
}

TEST(IoManifest, MissingFileOrDirectory) {
  ScratchDir dir;
  EXPECT_HAS(error_of([&] { load_manifest(dir / "nope.yaml", kQuiet); }), "nope.yaml': manifest file not found");
  EXPECT_HAS(error_of([&] { load_manifest(dir.path(), kQuiet); }), "is a directory");
  EXPECT_HAS(error_of([&] { save_manifest(sample_manifest(), dir.path()); }), "is a directory");
}

TEST(IoManifest, DefaultsAndTypicalValuesAreWrittenAsPeopleWriteThem) {
  Manifest m;
  ModuleSpec s;
  s.name = "w";
  s.file = "w.bin";
  s.wheel_radius = 0.097;
  s.mounting_rpy = Vec3(0.5, -1.25, 90.0) * kDeg;
  m.modules.push_back(s);
  m.origin = {30.5 * kDeg, 114.25 * kDeg, 20.0};
  const std::string yaml = manifest_to_yaml(m, ".");
  for (const char* line : {"gyro_arw_deg_sqrt_h: 0.24\n", "acc_vrw_m_s_sqrt_h: 0.3\n", "gyro_bias_deg_h: 50\n",
                           "gyro_sf_ppm: 3000\n", "gyro_bias_tau_h: 1\n", "lat_deg: 30.5\n",
                           "lon_deg: 114.25\n", "wheel_radius_m: 0.097\n"})
    EXPECT_HAS(yaml, line);
  EXPECT_HAS(yaml, "mounting_deg: [0.5, -1.25, 90]");
}

TEST(IoManifest, LargeAndSmallNumbersArePlainDigits) {
  Manifest m;
  ModuleSpec s;
  s.name = "w";
  s.file = "w.bin";
  s.wheel_radius = 0.097;
  s.noise.acc_bias_std = 2e-5;
  m.modules.push_back(s);
  m.static_start = 100000.0;
  m.static_end = 100030.0;
  const std::string yaml = manifest_to_yaml(m, ".");
  EXPECT_HAS(yaml, "static_period_s: [100000, 100030]");
  EXPECT_HAS(yaml, "acc_bias_m_s2: 0.00002\n");
  ScratchDir dir;
  save_manifest(m, dir / "m.yaml");
  const Manifest back = load_manifest(dir / "m.yaml", kQuiet);
  EXPECT_EQ(back.static_start, 100000.0);
  EXPECT_EQ(back.modules[0].noise.acc_bias_std, 2e-5);
}
