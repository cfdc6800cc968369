// The in-memory IMU stream of a simulation (sim/imu_stream.hpp) against the files the
// same simulation writes: every sample of every module (chips with a dropout and a
// stuck axis, and the error-free streams) bit for bit as ImuFileReader reads it, and
// a Triple INS navigated from memory giving the trajectory it gives from the files.
#include <gtest/gtest.h>

#include <random>

#include "wheelins/fusion/navigator.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/run/presets.hpp"
#include "wheelins/sim/imu_stream.hpp"

using namespace wheelins;
namespace fs = std::filesystem;

namespace {

class SimImuStream : public ::testing::Test {
 protected:
  static sim::SimConfig config() {
    sim::SimConfig cfg;  // field profile: clock offsets, vibration, every sensor error
    cfg.seed = 5;
    cfg.chips = 2;
    cfg.duration = 90.0;
    cfg.faults.push_back(sim::parse_fault_spec("dropout:left-C1:50:52"));
    cfg.faults.push_back(sim::parse_fault_spec("stuck:right-C2:60:61:sensor=gyro,axis=x"));
    return cfg;
  }
  static void SetUpTestSuite() {
    std::random_device rd;
    dir_ = new fs::path(fs::temp_directory_path() / ("wheelins-stream-" + std::to_string(rd())));
    sim_ = new sim::Simulation(config());
    sim_->write(*dir_, true, false);
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*dir_, ec);
    delete sim_;
    delete dir_;
  }

  /// The vehicle records at 1 Hz of `modules` navigated from `streams`.
  static std::vector<TrajectoryRecord> navigate(const Manifest& m,
                                                const std::vector<std::string>& modules,
                                                std::vector<std::unique_ptr<ImuStream>> streams) {
    NavigatorOptions opt;
    opt.earth_rotation = m.earth_rotation;
    opt.output_interval = 1.0;
    std::vector<TrajectoryRecord> out;
    Navigator nav(m, modules, opt, [&](int stream, const TrajectoryRecord& r) {
      if (stream == 0) out.push_back(r);
    });
    ImuMerger merger(std::move(streams));
    std::size_t k = 0;
    ImuSample s;
    while (merger.next(k, s)) nav.process(static_cast<int>(k), s);
    nav.finish();
    return out;
  }

  static fs::path* dir_;
  static sim::Simulation* sim_;
};
fs::path* SimImuStream::dir_ = nullptr;
sim::Simulation* SimImuStream::sim_ = nullptr;

}  // namespace

TEST_F(SimImuStream, YieldsTheSamplesOfTheFiles) {
  for (const fs::path& manifest : {*dir_ / "manifest.yaml", *dir_ / "manifest-ideal.yaml"}) {
    const Manifest m = load_manifest(manifest, {});
    for (const ModuleSpec& spec : m.modules) {
      SCOPED_TRACE(spec.name);
      ImuFileReader file(m.resolve(spec.file), imu_read_options(spec));
      sim::SimulatedImuStream memory(*sim_, spec.name);
      ImuSample a, b;
      std::uint64_t n = 0, gaps = 0;
      while (file.next(a)) {
        ASSERT_TRUE(memory.next(b)) << "the stream ends at sample " << n;
        ASSERT_EQ(a.t, b.t) << n;
        ASSERT_EQ(a.dt, b.dt) << n;
        ASSERT_EQ(a.dtheta, b.dtheta) << n;
        ASSERT_EQ(a.dvel, b.dvel) << n;
        gaps += a.dt > 1.5 / spec.rate_hz;
        ++n;
      }
      EXPECT_FALSE(memory.next(b)) << "the stream goes on after the file";
      EXPECT_EQ(n + (spec.name == "left-C1" ? 400u : 0u), sim_->sample_count());  // 2 s dropped
      EXPECT_EQ(gaps, spec.name == "left-C1" ? 1u : 0u);
    }
  }
}

TEST_F(SimImuStream, NavigatesTheTrajectoryOfTheFiles) {
  const Manifest m = load_manifest(*dir_ / "manifest.yaml", {});
  const auto modules = configuration_modules(m, "triple", {});  // left-C1 with its dropout
  std::vector<std::unique_ptr<ImuStream>> files;
  for (const auto& name : modules) {
    const ModuleSpec& spec = *m.find(name);
    files.push_back(std::make_unique<ImuFileReader>(m.resolve(spec.file), imu_read_options(spec)));
  }
  const std::vector<TrajectoryRecord> from_files = navigate(m, modules, std::move(files));
  const std::vector<TrajectoryRecord> from_memory =
      navigate(m, modules, sim::simulated_streams(*sim_, modules));
  ASSERT_GT(from_files.size(), 50u);
  ASSERT_EQ(from_files.size(), from_memory.size());
  for (std::size_t i = 0; i < from_files.size(); ++i) {
    EXPECT_EQ(from_files[i].t, from_memory[i].t) << i;
    EXPECT_EQ(from_files[i].p_inN, from_memory[i].p_inN) << i;
    EXPECT_EQ(from_files[i].rpy, from_memory[i].rpy) << i;
    EXPECT_EQ(from_files[i].p_std, from_memory[i].p_std) << i;
  }
}

TEST_F(SimImuStream, UnknownModuleIsNamed) {
  try {
    sim::SimulatedImuStream s(*sim_, "left-C7");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no module named 'left-C7' (modules: left-C1, left-C2"),
              std::string::npos)
        << e.what();
  }
}
