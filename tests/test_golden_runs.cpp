// Golden runs: change indication in the spirit of PX4's CSV comparisons. A short
// simulated dataset (field profile, 150 s) is navigated in five ways (single
// Wheel-INS, Body/Wheel-INS, Triple INS distributed and centralized, and Triple
// INS through a dropout and a wheel-slip fault), and the vehicle solution at 1 Hz
// is compared with the files in tests/golden/. The simulated data themselves are
// pinned by tests/golden/sim.csv (every 3000th sample of every module), so a
// change of the simulator and a change of the filter tell themselves apart.
//
// A change that moves these numbers must say why in its commit; regenerate with
//   WHEELINS_UPDATE_GOLDEN=1 build/wheelins_tests --gtest_filter='GoldenRuns.*'
// which rewrites tests/golden/*.csv in the source tree.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>

#include "wheelins/run/presets.hpp"
#include "wheelins/run/run.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/sim/simulator.hpp"

using namespace wheelins;
namespace fs = std::filesystem;

namespace {

const fs::path kGoldenDir = fs::path(WHEELINS_SOURCE_DIR) / "tests" / "golden";

bool updating() {
  const char* e = std::getenv("WHEELINS_UPDATE_GOLDEN");
  return e != nullptr && std::string(e) == "1";
}

fs::path scratch(const std::string& name) {
  std::random_device rd;
  const fs::path p =
      fs::temp_directory_path() / ("wheelins-golden-" + name + "-" + std::to_string(rd()));
  fs::create_directories(p);
  return p;
}

/// A table of numbers with named columns (the golden file format: a header line, then
/// rows of shortest round-trip numbers, comma separated).
struct Table {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;

  std::string text() const {
    std::string s;
    for (std::size_t c = 0; c < columns.size(); ++c) s += (c ? "," : "") + columns[c];
    s += "\n";
    for (const auto& r : rows) {
      for (std::size_t c = 0; c < r.size(); ++c) s += (c ? "," : "") + io_detail::format_double(r[c]);
      s += "\n";
    }
    return s;
  }
  static Table read(const fs::path& file) {
    Table t;
    std::ifstream in(file);
    if (!in) throw std::runtime_error("cannot read " + file.string());
    std::string line;
    std::getline(in, line);
    std::stringstream hs(line);
    for (std::string c; std::getline(hs, c, ',');) t.columns.push_back(c);
    while (std::getline(in, line)) {
      if (line.empty()) continue;
      std::vector<double> r;
      std::stringstream ls(line);
      for (std::string v; std::getline(ls, v, ',');) r.push_back(std::strtod(v.c_str(), nullptr));
      t.rows.push_back(r);
    }
    return t;
  }
};

/// Compares `got` with the golden file `name`; with WHEELINS_UPDATE_GOLDEN=1 rewrites it.
/// `tolerance[c]` is the absolute tolerance of column c. Prints the largest difference of
/// every column that moved (bit-identical files print one line).
void check_golden(const std::string& name, const Table& got, const std::vector<double>& tolerance) {
  const fs::path file = kGoldenDir / name;
  if (updating()) {
    fs::create_directories(kGoldenDir);
    std::ofstream(file, std::ios::binary) << got.text();
    std::printf("[ golden   ] rewrote %s (%zu rows)\n", file.c_str(), got.rows.size());
    return;
  }
  ASSERT_TRUE(fs::exists(file)) << file << " is missing: run with WHEELINS_UPDATE_GOLDEN=1";
  const Table want = Table::read(file);
  ASSERT_EQ(want.columns, got.columns) << name << ": the columns changed";
  ASSERT_EQ(want.rows.size(), got.rows.size()) << name << ": the number of rows changed";
  std::vector<double> max_diff(got.columns.size(), 0.0);
  std::vector<std::size_t> worst_row(got.columns.size(), 0);
  bool identical = true;
  for (std::size_t r = 0; r < got.rows.size(); ++r) {
    ASSERT_EQ(want.rows[r].size(), got.columns.size()) << name << " row " << r;
    for (std::size_t c = 0; c < got.columns.size(); ++c) {
      const double a = want.rows[r][c], b = got.rows[r][c];
      if (a == b || (std::isnan(a) && std::isnan(b))) continue;
      identical = false;
      const double d = std::isfinite(a) && std::isfinite(b) ? std::abs(a - b) : INFINITY;
      if (d > max_diff[c]) {
        max_diff[c] = d;
        worst_row[c] = r;
      }
    }
  }
  if (identical) {
    std::printf("[ golden   ] %s: bit-identical (%zu rows)\n", name.c_str(), got.rows.size());
    return;
  }
  for (std::size_t c = 0; c < got.columns.size(); ++c) {
    if (max_diff[c] == 0.0) continue;
    std::printf("[ golden   ] %s: %s moved by up to %.3g (row %zu, tolerance %.3g)\n", name.c_str(),
                got.columns[c].c_str(), max_diff[c], worst_row[c], tolerance[c]);
    EXPECT_LE(max_diff[c], tolerance[c])
        << name << ": column " << got.columns[c] << " row " << worst_row[c] << " was "
        << want.rows[worst_row[c]][c] << ", is " << got.rows[worst_row[c]][c];
  }
}

/// The vehicle columns compared, and their tolerances: 1e-9 in the SI/degree units of the
/// trajectory CSV (a change of the algorithm moves them by orders of magnitude more; a
/// different but equivalent order of floating-point operations by orders less).
const std::vector<std::string> kVehicleColumns = {
    "t_s",         "north_m",     "east_m",      "down_m",         "vn_m_s",
    "ve_m_s",      "vd_m_s",      "roll_deg",    "pitch_deg",      "heading_deg",
    "north_std_m", "east_std_m",  "down_std_m",  "heading_std_deg"};

std::vector<double> vehicle_row(const TrajectoryRecord& r) {
  return {r.t,          r.p_inN.x(),        r.p_inN.y(),        r.p_inN.z(),
          r.v_inN.x(),  r.v_inN.y(),        r.v_inN.z(),        r.rpy.x() / kDeg,
          r.rpy.y() / kDeg, r.rpy.z() / kDeg, r.p_std.x(),      r.p_std.y(),
          r.p_std.z(),  r.rpy_std.z() / kDeg};
}

class GoldenRuns : public ::testing::Test {
 protected:
  static sim::SimConfig config() {
    sim::SimConfig cfg;  // the `field` profile: every effect of the simulator on
    cfg.seed = 11;
    cfg.chips = 1;
    cfg.duration = 150.0;
    cfg.write_ideal = false;
    return cfg;
  }
  static void SetUpTestSuite() {
    plain_ = new fs::path(scratch("plain"));
    sim::Simulation(config()).write(*plain_, true, false);
    faulty_ = new fs::path(scratch("faults"));
    sim::SimConfig f = config();
    f.faults.push_back(sim::parse_fault_spec("dropout:left-C1:70:85"));
    f.faults.push_back(sim::parse_fault_spec("slip:right-wheel:110:113:ratio=0.5"));
    sim::Simulation(f).write(*faulty_, true, false);
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*plain_, ec);
    fs::remove_all(*faulty_, ec);
    delete plain_;
    delete faulty_;
  }

  /// Navigates `configuration` of the dataset in memory; the vehicle solution at 1 Hz.
  static Table navigate(const fs::path& dataset, const std::string& configuration,
                        bool centralized, CalibrationMode calibration = CalibrationMode::kEstimate) {
    RunRequest r;
    r.calibration = calibration;
    r.manifest = load_manifest(dataset / "manifest.yaml", {});
    r.modules = configuration_modules(r.manifest, configuration, {});
    r.nav.earth_rotation = r.manifest.earth_rotation;
    r.nav.fusion.centralized = centralized;
    r.nav.output_interval = 1.0;
    r.nav.module_records = false;
    r.progress = false;
    Table t;
    t.columns = kVehicleColumns;
    r.on_record = [&](const TrajectoryRecord& rec) { t.rows.push_back(vehicle_row(rec)); };
    run_navigation(r);
    return t;
  }
  static std::vector<double> tolerances() { return std::vector<double>(kVehicleColumns.size(), 1e-9); }

  static fs::path* plain_;
  static fs::path* faulty_;
};
fs::path* GoldenRuns::plain_ = nullptr;
fs::path* GoldenRuns::faulty_ = nullptr;

}  // namespace

TEST_F(GoldenRuns, SimulatedData) {
  const Manifest m = load_manifest(*plain_ / "manifest.yaml", {});
  Table t;
  t.columns = {"module", "record", "t_s", "gx", "gy", "gz", "ax", "ay", "az"};
  for (std::size_t i = 0; i < m.modules.size(); ++i) {
    const ModuleSpec& spec = m.modules[i];
    ImuFileReader reader(m.resolve(spec.file), imu_read_options(spec));
    ImuSample s;
    for (std::uint64_t k = 0; reader.next(s); ++k) {
      if (k % 3000 != 0) continue;
      t.rows.push_back({static_cast<double>(i), static_cast<double>(k), s.t, s.dtheta.x() / s.dt,
                        s.dtheta.y() / s.dt, s.dtheta.z() / s.dt, s.dvel.x() / s.dt,
                        s.dvel.y() / s.dt, s.dvel.z() / s.dt});
    }
  }
  EXPECT_GE(t.rows.size(), 30u);
  check_golden("sim.csv", t, std::vector<double>(t.columns.size(), 1e-12));
}

TEST_F(GoldenRuns, SingleWheelIns) {
  check_golden("single.csv", navigate(*plain_, "single", false), tolerances());
}

// The manifest's geometry as it is (calibration: manifest): the pipeline before the
// installation calibration, pinned on its own.
TEST_F(GoldenRuns, SingleWheelInsManifestGeometry) {
  check_golden("single-manifest.csv", navigate(*plain_, "single", false, CalibrationMode::kManifest),
               tolerances());
}

TEST_F(GoldenRuns, BodyWheelIns) {
  check_golden("body-wheel.csv", navigate(*plain_, "body-wheel", false), tolerances());
}

TEST_F(GoldenRuns, TripleInsDistributed) {
  check_golden("triple.csv", navigate(*plain_, "triple", false), tolerances());
}

TEST_F(GoldenRuns, TripleInsCentralized) {
  check_golden("triple-centralized.csv", navigate(*plain_, "triple", true), tolerances());
}

TEST_F(GoldenRuns, TripleInsThroughFaults) {
  check_golden("triple-faults.csv", navigate(*faulty_, "triple", false), tolerances());
}
