// Run configuration and configuration presets: values land in SI, bad values are
// errors naming the file, key and line, unknown keys are warnings naming the closest key.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <optional>

#include "dataset_test_util.hpp"
#include "io_test_util.hpp"
#include "wheelins/run/presets.hpp"
#include "wheelins/run/run_config.hpp"
#include "wheelins/run/run_options.hpp"

using namespace wheelins;
using iotest::error_of;
using iotest::ScratchDir;
using iotest::write_text;

namespace {

/// What a run configuration holds, as text to compare two: every setting's value.
std::string config_text(const RunConfig& c) { return run_options_listing(c); }

RunConfig config_with(std::vector<NamedSetting> named, std::vector<std::string> settings = {}) {
  RunOverrides o;
  o.named = std::move(named);
  o.named.insert(o.named.begin(), cli_setting("-m", "m.yaml"));
  o.settings = std::move(settings);
  return run_config_with(o, {});
}

Manifest three_groups() {
  Manifest m;
  m.path = "/data/m.yaml";
  for (const char* side : {"left", "right"})
    for (const char* chip : {"C1", "C2"}) {
      ModuleSpec s;
      s.name = std::string(side) + "-" + chip;
      s.kind = ModuleKind::kWheel;
      s.chip = chip;
      s.p_inV = Vec3(0, std::string(side) == "left" ? -0.165 : 0.165, 0);
      s.wheel_radius = 0.1;
      m.modules.push_back(s);
    }
  for (const char* chip : {"C1", "C4"}) {
    ModuleSpec s;
    s.name = std::string("body-") + chip;
    s.kind = ModuleKind::kBody;
    s.chip = chip;
    m.modules.push_back(s);
  }
  return m;
}
}  // namespace

TEST(FusionPresets, ResolveByGroupAndChip) {
  const Manifest m = three_groups();
  EXPECT_EQ(configuration_modules(m, "single", {}), std::vector<std::string>{"left-C1"});
  EXPECT_EQ(configuration_modules(m, "dual-wheel", {"C2", "C1"}),
            (std::vector<std::string>{"left-C2", "right-C1"}));
  EXPECT_EQ(configuration_modules(m, "body-wheel", {"C1", "C4"}),
            (std::vector<std::string>{"left-C1", "body-C4"}));
  EXPECT_EQ(configuration_modules(m, "triple", {}),
            (std::vector<std::string>{"left-C1", "right-C1", "body-C1"}));
  EXPECT_NE(error_of([&] { configuration_modules(m, "triple", {"C1", "C2"}); }).find("takes 3 chips"),
            std::string::npos);
  EXPECT_NE(error_of([&] { configuration_modules(m, "dual-wheel", {"C1", "C9"}); }).find("chip 'C9'"),
            std::string::npos);
  EXPECT_NE(error_of([&] { configuration_modules(m, "quad", {}); }).find("unknown configuration"),
            std::string::npos);
}

TEST(FusionRunConfig, LoadsHumanUnitsIntoSi) {
  ScratchDir dir;
  write_text(dir / "run.yaml", R"(dataset: data/manifest.yaml
configuration: triple
chips: [C1, C2, C4]
output: {dir: out/t, formats: [csv], interval_s: 0.1, overwrite: true}
filter:
  velocity_update_hz: 4
  velocity_average: whole-turns
  covariance_interval_s: 0.02
  wheel_velocity_std_m_s: [0.05, 0.03, 0.03]
  initial_std: {heading_deg: 0.5}
fusion: {speed: own, position_update_hz: 2, position_std_m: 0.3, centralized: true}
faults: {heading_gate_deg: 8, window: 30, max_failed: 20, probation_s: 5}
)");
  std::vector<std::string> warnings;
  const RunConfig c = load_run_config(dir / "run.yaml", [&](const std::string& w) { warnings.push_back(w); });
  EXPECT_TRUE(warnings.empty());
  EXPECT_EQ(c.manifest, dir / "data/manifest.yaml");
  EXPECT_EQ(c.configuration, "triple");
  EXPECT_EQ(c.chips.size(), 3u);
  EXPECT_EQ(c.output_dir, dir / "out/t");
  EXPECT_TRUE(c.overwrite);
  EXPECT_DOUBLE_EQ(c.nav.output_interval, 0.1);
  EXPECT_DOUBLE_EQ(c.nav.wheel.velocity_update_interval, 0.25);
  EXPECT_TRUE(c.nav.wheel.turn_average);
  EXPECT_DOUBLE_EQ(c.nav.covariance_interval, 0.02);
  EXPECT_DOUBLE_EQ(c.nav.wheel.velocity_std.x(), 0.05);
  EXPECT_NEAR(c.nav.wheel.init.heading, 0.5 * kDeg, 1e-15);
  EXPECT_EQ(c.nav.fusion.speed, SpeedSharing::kOwn);
  EXPECT_DOUBLE_EQ(c.nav.fusion.position_update_interval, 0.5);
  EXPECT_DOUBLE_EQ(c.nav.fusion.position_std, 0.3);
  EXPECT_TRUE(c.nav.fusion.centralized);
  EXPECT_TRUE(c.nav.faults.enabled);
  EXPECT_NEAR(c.nav.faults.heading_gate, 8.0 * kDeg, 1e-15);
  EXPECT_EQ(c.nav.faults.window, 30);
  EXPECT_EQ(c.nav.faults.max_failed, 20);
  EXPECT_DOUBLE_EQ(c.nav.faults.probation, 5.0);
}

TEST(FusionRunConfig, BadValuesNameTheKeyAndLine) {
  ScratchDir dir;
  auto load = [&](const std::string& text) {
    write_text(dir / "run.yaml", text);
    return error_of([&] { load_run_config(dir / "run.yaml", {}); });
  };
  std::string e = load("configuration: single\n");
  EXPECT_NE(e.find("run.yaml"), std::string::npos) << e;
  EXPECT_NE(e.find("missing required key 'dataset'"), std::string::npos) << e;
  e = load("dataset: m.yaml\nfilter:\n  velocity_update_hz: fast\n");
  EXPECT_NE(e.find("filter.velocity_update_hz: expected a number, got 'fast' (line 3)"),
            std::string::npos) << e;
  e = load("dataset: m.yaml\nfilter:\n  velocity_average: turns\n");
  EXPECT_NE(e.find("filter.velocity_average"), std::string::npos) << e;
  EXPECT_NE(e.find("whole-turns"), std::string::npos) << e;
  e = load("dataset: m.yaml\nfilter:\n  wheel_velocity_std_m_s: [0.03, -1, 0.02]\n");
  EXPECT_NE(e.find("filter.wheel_velocity_std_m_s[1]: must be in [0.0001, 10] m/s, got -1"), std::string::npos) << e;
  e = load("dataset: m.yaml\nfilter:\n  covariance_interval_s: 2\n");
  EXPECT_NE(e.find("filter.covariance_interval_s: must be in [0, 0.5] s"), std::string::npos) << e;
  e = load("dataset: m.yaml\nfusion: {speed: fastest}\n");
  EXPECT_NE(e.find("fusion.speed: expected mean or own"), std::string::npos) << e;
  e = load("dataset: m.yaml\nfaults:\n  window: 10\n  max_failed: 12\n");
  EXPECT_NE(e.find("faults.max_failed: must be 1..window (10), got 12"), std::string::npos) << e;
  e = load("dataset: m.yaml\nfaults:\n  enabled: maybe\n");
  EXPECT_NE(e.find("faults.enabled"), std::string::npos) << e;
  EXPECT_NE(e.find("line 3"), std::string::npos) << e;
  e = load("dataset: m.yaml\nfaults:\n  window: 2.5\n");
  EXPECT_NE(e.find("faults.window: must be a whole number"), std::string::npos) << e;
  e = load("dataset: [unclosed\n");
  EXPECT_NE(e.find("malformed YAML"), std::string::npos) << e;
  e = error_of([&] { load_run_config(dir / "missing.yaml", {}); });
  EXPECT_NE(e.find("missing.yaml': run configuration file not found"), std::string::npos) << e;
}

TEST(FusionRunConfig, YawScaleFactorsAndTheOlderKey) {
  ScratchDir dir;
  auto load = [&](const std::string& text) {
    write_text(dir / "run.yaml", text);
    return load_run_config(dir / "run.yaml", {});
  };
  EXPECT_EQ(load("dataset: m.yaml\n").nav.yaw_scale_factors, YawScaleFactorChoice::kAuto);
  EXPECT_EQ(load("dataset: m.yaml\n").nav.fusion.speed, SpeedSharing::kOwn);
  EXPECT_EQ(load("dataset: m.yaml\nfilter: {yaw_scale_factors: constraint}\n").nav.yaw_scale_factors,
            YawScaleFactorChoice::kFromConstraint);
  EXPECT_EQ(load("dataset: m.yaml\nfilter: {yaw_scale_factors: held}\n").nav.yaw_scale_factors,
            YawScaleFactorChoice::kHeld);
  EXPECT_EQ(load("dataset: m.yaml\nfilter: {estimate_yaw_scale_factors: true}\n").nav.yaw_scale_factors,
            YawScaleFactorChoice::kEstimated);
  EXPECT_EQ(load("dataset: m.yaml\nfilter: {estimate_yaw_scale_factors: false}\n").nav.yaw_scale_factors,
            YawScaleFactorChoice::kHeld);
  std::string e = error_of([&] { load("dataset: m.yaml\nfilter: {yaw_scale_factors: sometimes}\n"); });
  EXPECT_NE(e.find("filter.yaw_scale_factors: expected auto or held or constraint or estimated, got 'sometimes'"),
            std::string::npos) << e;
  e = error_of([&] {
    load("dataset: m.yaml\nfilter:\n  yaw_scale_factors: held\n  estimate_yaw_scale_factors: true\n");
  });
  EXPECT_NE(e.find("filter.estimate_yaw_scale_factors: conflicts with filter.yaw_scale_factors"), std::string::npos) << e;
  EXPECT_EQ(config_with({cli_setting("--yaw-scale-factors", "estimated")}).nav.yaw_scale_factors,
            YawScaleFactorChoice::kEstimated);
  EXPECT_NE(error_of([] { config_with({cli_setting("--yaw-scale-factors", "x")}); })
                .find("--yaw-scale-factors: filter.yaw_scale_factors: expected auto or held or constraint or estimated"),
            std::string::npos);
}

TEST(FusionNavigator, YawScaleFactorsResolvedByConfiguration) {
  // auto: from the constraint when a Body-IMU and another module are in it (either filter);
  // held otherwise; an explicit choice is taken as given.
  NavigatorOptions o;
  auto mode = [](const NavigatorOptions& r) {
    EXPECT_EQ(r.wheel.yaw_scale_factors, r.body.yaw_scale_factors);
    return r.wheel.yaw_scale_factors;
  };
  EXPECT_EQ(mode(o.resolved(3, true)), YawScaleFactors::kFromConstraint);
  EXPECT_EQ(mode(o.resolved(2, true)), YawScaleFactors::kFromConstraint);
  EXPECT_EQ(mode(o.resolved(2, false)), YawScaleFactors::kHeld);
  EXPECT_EQ(mode(o.resolved(1, false)), YawScaleFactors::kHeld);
  NavigatorOptions c = o;
  c.fusion.centralized = true;
  EXPECT_EQ(mode(c.resolved(3, true)), YawScaleFactors::kFromConstraint);
  EXPECT_EQ(mode(c.resolved(2, false)), YawScaleFactors::kHeld);
  NavigatorOptions n = o;
  n.fusion.position_constraint = false;
  EXPECT_EQ(mode(n.resolved(3, true)), YawScaleFactors::kHeld);
  NavigatorOptions e = c;
  e.yaw_scale_factors = YawScaleFactorChoice::kFromConstraint;
  EXPECT_EQ(mode(e.resolved(2, false)), YawScaleFactors::kFromConstraint);
  e.yaw_scale_factors = YawScaleFactorChoice::kEstimated;
  EXPECT_EQ(mode(e.resolved(1, false)), YawScaleFactors::kEstimated);
  e.yaw_scale_factors = YawScaleFactorChoice::kHeld;
  EXPECT_EQ(mode(e.resolved(3, true)), YawScaleFactors::kHeld);
}

TEST(FusionRunConfig, UnknownKeyWarnsWithClosestKnown) {
  ScratchDir dir;
  write_text(dir / "run.yaml", "dataset: m.yaml\nfusion:\n  centralised: true\n");
  std::vector<std::string> warnings;
  load_run_config(dir / "run.yaml", [&](const std::string& w) { warnings.push_back(w); });
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("fusion.centralised: unknown key ignored (line 3); did you mean 'centralized'?"),
            std::string::npos) << warnings[0];
}

TEST(FusionNavigator, NeedsAWheelImuAndKnownModules) {
  Manifest m = three_groups();
  const auto err = [&](const std::vector<std::string>& mods) {
    return error_of([&] { Navigator(m, mods, NavigatorOptions{}, [](int, const TrajectoryRecord&) {}); });
  };
  EXPECT_NE(err({"body-C1"}).find("no Wheel-IMU among the selected modules"), std::string::npos);
  EXPECT_NE(err({"left-C1", "left-C9"}).find("no module named 'left-C9'"), std::string::npos);
  EXPECT_NE(err({"left-C1", "body-C1", "body-C4"}).find("only one Body-IMU"), std::string::npos);
  EXPECT_NE(err({}).find("no module selected"), std::string::npos);
}

TEST(FusionNavigator, RefusesOptionsOutOfRange) {
  // The navigator checks its options itself (NavigatorOptions::validate()), whoever made
  // them: an interval of 0 would never advance its schedule.
  Manifest m = three_groups();
  const auto err = [&](const NavigatorOptions& o) {
    return error_of([&] { Navigator(m, {"left-C1"}, o, [](int, const TrajectoryRecord&) {}); });
  };
  NavigatorOptions o;
  o.covariance_interval = 0.6;
  EXPECT_NE(err(o).find("covariance interval: must be in [0, 0.5"), std::string::npos) << err(o);
  o = NavigatorOptions{};
  o.wheel.velocity_update_interval = 0.0;
  EXPECT_NE(err(o).find("velocity update interval: must be > 0 s"), std::string::npos) << err(o);
  o = NavigatorOptions{};
  o.fusion.position_update_interval = -1.0;
  EXPECT_NE(err(o).find("position update interval"), std::string::npos) << err(o);
  o = NavigatorOptions{};
  o.output_interval = -0.1;
  EXPECT_NE(err(o).find("output interval"), std::string::npos) << err(o);
  EXPECT_NO_THROW(Navigator(m, {"left-C1"}, NavigatorOptions{}, [](int, const TrajectoryRecord&) {}));
}

// The settings are declared once (run/run_options.hpp); the documentation's table of them is
// that declaration, printed.
TEST(RunOptions, TheDocumentationsTableIsTheDeclarations) {
  const std::string doc =
      iotest::read_text_file(std::filesystem::path(WHEELINS_SOURCE_DIR) / "docs" / "run-config.md");
  const std::string begin = "<!-- settings: from src/wheelins/run/run_options.hpp -->\n",
                    end = "<!-- end of the settings -->";
  const std::size_t a = doc.find(begin), b = doc.find(end);
  ASSERT_NE(a, std::string::npos) << "docs/run-config.md lacks the line " << begin;
  ASSERT_NE(b, std::string::npos) << "docs/run-config.md lacks the line " << end;
  // The table, then a blank line before the closing comment.
  EXPECT_EQ(doc.substr(a + begin.size(), b - a - begin.size()), run_options_markdown() + "\n")
      << "docs/run-config.md's table of settings is not the declarations; as declared it reads:\n"
      << run_options_markdown();
}

// Every declared key is read: a file giving each of them is accepted without a warning.
TEST(RunOptions, EveryDeclaredKeyIsKnownToTheReader) {
  const std::string table = run_options_markdown();
  std::vector<std::string> keys;
  for (std::size_t at = table.find("\n| `"); at != std::string::npos; at = table.find("\n| `", at + 1))
    keys.push_back(table.substr(at + 4, table.find('`', at + 4) - at - 4));
  EXPECT_GT(keys.size(), 60u);
  EXPECT_NE(std::find(keys.begin(), keys.end(), "fusion.position_std_m"), keys.end());
  EXPECT_NE(std::find(keys.begin(), keys.end(), "filter.initial_std.heading_deg"), keys.end());
  // The reader warns about an unknown key: a made-up one in each section is warned about,
  // none of the declared ones.
  ScratchDir dir;
  write_text(dir / "run.yaml",
             "dataset: m.yaml\nfilter: {initial_std: {heading_deg: 0.2, hedding_deg: 1}, speed_windw_s: 1}\n"
             "fusion: {position_std_m: 0.3}\nfaults: {window: 3, max_failed: 2}\n");
  std::vector<std::string> warnings;
  const RunConfig c = load_run_config(dir / "run.yaml", [&](const std::string& w) { warnings.push_back(w); });
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[0].find("speed_window_s"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[1].find("heading_deg"), std::string::npos) << warnings[1];
  EXPECT_DOUBLE_EQ(c.nav.fusion.position_std, 0.3);
  EXPECT_DOUBLE_EQ(c.nav.wheel.init.heading, 0.2 * kDeg);
  EXPECT_DOUBLE_EQ(c.nav.body.init.heading, 0.2 * kDeg);
  EXPECT_EQ(c.nav.faults.window, 3);
}

// The command-line option a declaration names is one of `wheelins run`'s.
TEST(RunOptions, TheDeclaredCommandLineOptionsExist) {
  ScratchDir dir;
  const dstest::CmdResult help = dstest::wheelins_cli("run --help", dir / "");
  ASSERT_EQ(help.code, 0) << help.err;
  const std::string table = run_options_markdown();
  int named = 0;
  for (std::size_t row = table.find("\n| `"); row != std::string::npos; row = table.find("\n| `", row + 1)) {
    const std::size_t cell = table.find(" | ", row + 3) + 3;
    if (table.compare(cell, 1, "`") != 0) continue;
    const std::string flags = table.substr(cell + 1, table.find('`', cell + 1) - cell - 1);
    for (std::size_t at = 0; at <= flags.size();) {  // each name of "--out,-o"
      const std::size_t end = std::min(flags.find(',', at), flags.size());
      const std::string flag = flags.substr(at, end - at);
      const bool listed = help.out.find(flag + " ") != std::string::npos || help.out.find(flag + ",") != std::string::npos;
      EXPECT_TRUE(listed) << flag << " is not an option of wheelins run";
      at = end + 1;
    }
    ++named;
  }
  EXPECT_GT(named, 15);
}

// `--set KEY=VALUE` (RunOverrides::settings): any declared key, over the file, with the file's
// checks; a mistake is an error naming the setting.
TEST(RunOptions, SetGivesAnyDeclaredKeyOverTheFile) {
  ScratchDir dir;
  write_text(dir / "run.yaml", "dataset: m.yaml\nfusion: {position_std_m: 0.3, weights: covariance}\n");
  RunOverrides o;
  o.config = dir / "run.yaml";
  o.settings = {"fusion.position_std_m=0.5", "filter.velocity_update_hz=4", "fusion.weights=[1, 2]",
                "standstill.rate_std_deg_s=0.1", "faults.window=30", "output.formats=[csv]"};
  const RunConfig c = run_config_with(o, {});
  EXPECT_DOUBLE_EQ(c.nav.fusion.position_std, 0.5);
  EXPECT_DOUBLE_EQ(c.nav.wheel.velocity_update_interval, 0.25);
  EXPECT_EQ(c.nav.fusion.weights, (std::vector<double>{1.0, 2.0}));
  EXPECT_EQ(c.nav.fusion.weighting, ReferenceWeighting::kCovariance);  // from the file, not set
  EXPECT_DOUBLE_EQ(c.nav.standstill.rate_std, 0.1 * kDeg);
  EXPECT_EQ(c.nav.faults.window, 30);
  ASSERT_EQ(c.formats.size(), 1u);
  EXPECT_EQ(c.manifest, dir / "m.yaml");

  auto error = [](std::vector<std::string> settings) {
    RunConfig r;
    return error_of([&] { apply_run_settings(settings, r); });
  };
  std::string e = error({"fusion.position_std=0.5"});
  EXPECT_NE(e.find("--set: fusion.position_std: unknown key"), std::string::npos) << e;
  EXPECT_NE(e.find("position_std_m"), std::string::npos) << e;
  e = error({"fusion.position_std_m=500"});
  EXPECT_NE(e.find("--set: fusion.position_std_m: must be in [0.001, 100] m"), std::string::npos) << e;
  EXPECT_EQ(e.find("line"), std::string::npos) << e;
  EXPECT_NE(error({"fusion.position_std_m"}).find("expected KEY=VALUE"), std::string::npos);
  EXPECT_NE(error({"fusion.position_std_m="}).find("no value after '='"), std::string::npos);
  EXPECT_NE(error({"fusion..position_std_m=1"}).find("an empty part"), std::string::npos);
  EXPECT_NE(error({"fusion.position_std_m=1", "fusion.position_std_m=2"}).find("is set twice"), std::string::npos);
  EXPECT_NE(error({"fusion=1", "fusion.position_std_m=2"}).find("as a value and as a section"), std::string::npos);
  EXPECT_NE(error({"fusion.weights=[1, 0]"}).find("fusion.weights[1]: must be in (0, 1e6]"), std::string::npos);
  EXPECT_NE(error({"faults.window=3", "faults.max_failed=5"}).find("faults.max_failed"), std::string::npos);
  e = error({"fusion.speed=fast"});
  EXPECT_NE(e.find("--set: fusion.speed: expected mean or own"), std::string::npos) << e;
}

namespace {

// Issue 35: the front ends' named options come from the declarations. Each sets its key as
// `--set KEY=VALUE` does (the switches what their text says), by any of its names.
TEST(RunOptions, EachNamedOptionSetsItsDeclaredKey) {
  const std::string defaults = config_text(config_with({}));
  int switches = 0;
  for (const NamedOption& o : run_named_options()) {
    if (o.sets.empty()) continue;
    const std::string named = config_text(config_with({cli_setting(o.option)}));
    EXPECT_EQ(named, config_text(config_with({}, {o.key + "=" + o.sets}))) << o.option;
    EXPECT_NE(named, defaults) << o.option << " changes nothing";
    ++switches;
  }
  EXPECT_GE(switches, 8);
  const std::vector<std::array<const char*, 3>> values = {
      {"--duration", "60", "duration_s=60"},
      {"--chips", "C1,C4", "chips=[C1, C4]"},
      {"--configuration", "triple", "configuration=triple"},
      {"-c", "dual-wheel", "configuration=dual-wheel"},
      {"--modules", "left-C1", "modules=[left-C1]"},
      {"--out", "somewhere", "output.dir=somewhere"},
      {"-o", "a,b", "output.dir='a,b'"},
      {"--formats", "csv,kml", "output.formats=[csv, kml]"},
      {"--tum-frame", "enu", "output.tum_frame=enu"},
      {"--output-interval", "0.5", "output.interval_s=0.5"},
      {"--covariance-interval", "0.1", "filter.covariance_interval_s=0.1"},
      {"--speed", "mean", "fusion.speed=mean"},
      {"--yaw-scale-factors", "estimated", "filter.yaw_scale_factors=estimated"},
      {"--weights", "covariance", "fusion.weights=covariance"},
      {"--weights", "1,2,1", "fusion.weights=[1, 2, 1]"},
      {"--calibration", "manifest", "calibration=manifest"}};
  for (const auto& [option, value, set] : values) {
    const std::string named = config_text(config_with({cli_setting(option, value)}));
    EXPECT_EQ(named, config_text(config_with({}, {set}))) << option << " " << value;
    EXPECT_NE(named, defaults) << option << " " << value << " changes nothing";
  }
  EXPECT_EQ(config_with({cli_setting("--out", "x")}).output_dir, "x");  // relative to the working directory
  EXPECT_NE(error_of([] { (void)cli_setting("--antenna", "1,2,3"); }).find("not an option of a run setting"),
            std::string::npos);
}

// Named options over --set over the file; the file's modules and fixed weights give way to a
// named configuration and named weights.
TEST(RunOptions, NamedOptionsGoOverSettingsAndTheFile) {
  ScratchDir dir;
  write_text(dir / "run.yaml", "dataset: m.yaml\nmodules: [left-C1]\nfusion: {weights: [1, 2]}\nduration_s: 10\n");
  RunOverrides o;
  o.config = dir / "run.yaml";
  o.settings = {"duration_s=20"};
  o.named = {cli_setting("--duration", "30"), cli_setting("-c", "triple"), cli_setting("--weights", "covariance")};
  const RunConfig c = run_config_with(o, {});
  EXPECT_DOUBLE_EQ(c.max_duration, 30.0);
  EXPECT_EQ(c.configuration, "triple");
  EXPECT_TRUE(c.modules.empty());
  EXPECT_TRUE(c.nav.fusion.weights.empty());
  EXPECT_EQ(c.nav.fusion.weighting, ReferenceWeighting::kCovariance);
  o.named = {cli_setting("--duration", "30")};
  EXPECT_EQ(run_config_with(o, {}).modules, std::vector<std::string>{"left-C1"});
}

// A mistake in a named option names the option (and the key), and stops the command before a
// file is read; modules exclude a configuration and chips.
TEST(RunOptions, ANamedOptionsMistakeNamesIt) {
  auto error = [](std::vector<NamedSetting> named) {
    RunOverrides o;
    o.config = "/nonexistent/run.yaml";  // never read: the options are checked first
    o.named = std::move(named);
    return error_of([&] { run_config_with(o, {}); });
  };
  EXPECT_NE(error({cli_setting("--duration", "0")}).find("--duration: duration_s: must be > 0 s"), std::string::npos)
      << error({cli_setting("--duration", "0")});
  EXPECT_NE(error({cli_setting("--duration", "1e400")}).find("--duration: duration_s:"), std::string::npos);
  EXPECT_NE(error({cli_setting("--duration", "abc")}).find("--duration: duration_s:"), std::string::npos);
  EXPECT_NE(error({cli_setting("--output-interval", "9")}).find("--output-interval: output.interval_s: must be in [0, 5]"),
            std::string::npos);
  EXPECT_NE(error({cli_setting("--speed", "fast")}).find("--speed: fusion.speed:"), std::string::npos);
  EXPECT_NE(error({cli_setting("--chips", "C1,,C4")}).find("--chips: chips[1]"), std::string::npos);
  EXPECT_NE(error({cli_setting("--tum-frame", "xyz")}).find("--tum-frame: output.tum_frame: 'xyz'"), std::string::npos);
  EXPECT_NE(error({cli_setting("--modules", "left-C1"), cli_setting("-c", "triple")})
                .find("modules and configuration both given"),
            std::string::npos);
  EXPECT_NE(error({cli_setting("--modules", "left-C1"), cli_setting("--chips", "C1")}).find("modules and chips"),
            std::string::npos);
  EXPECT_NE(error({}).find("/nonexistent/run.yaml"), std::string::npos);  // the file is read when the options are good
}

// Python's keywords are the options' names: a switch's keyword takes True or False.
TEST(RunOptions, PythonsKeywordsAreTheOptionsNames) {
  auto keyword = [](const char* name) {
    const NamedOption* o = find_named_option(name);
    EXPECT_NE(o, nullptr) << name;
    return o;
  };
  EXPECT_EQ(keyword("position_constraint")->option, "--no-position-constraint");
  EXPECT_EQ(keyword("position_constraint")->keyword_value(false), "false");
  EXPECT_EQ(keyword("position_constraint")->keyword_value(true), "true");
  EXPECT_EQ(keyword("fixed_noise")->keyword_value(true), "false");  // noise.adapt
  EXPECT_EQ(keyword("fixed_noise")->keyword_value(false), "true");
  EXPECT_EQ(keyword("full_rate")->keyword_value(true), "0");
  EXPECT_EQ(keyword("full_rate")->keyword_value(false), std::nullopt);
  EXPECT_EQ(keyword("centralized")->keyword_value(false), "false");
  EXPECT_EQ(keyword("output_interval")->key, "output.interval_s");
  EXPECT_EQ(keyword("out")->key, "output.dir");
  EXPECT_EQ(keyword("--out"), keyword("out"));
  EXPECT_EQ(find_named_option("no_such_option"), nullptr);
  EXPECT_THROW((void)keyword("duration")->keyword_value(true), std::logic_error);
}

}  // namespace
