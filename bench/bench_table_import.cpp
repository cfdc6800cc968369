// Google Benchmark: importing vendor tables (io/table_import.hpp) -- a synthetic
// two-minute, 120 Hz set of five Xsens DOT exports, generated in the setup, imported into
// `<module>_imu.bin` files; the figure is rows per second (items_per_second).
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "wheelins/io/table_import.hpp"
#include "wheelins/io/table_reader.hpp"

using namespace wheelins;
namespace fs = std::filesystem;

namespace {

/// Five DOT exports written once per process into a temporary directory (removed at exit).
struct DotSet {
  static constexpr int kFiles = 5;
  static constexpr int kRows = 120 * 120;  // two minutes at 120 Hz
  fs::path dir;
  std::vector<TableInput> inputs;
  std::uint64_t rows = 0, bytes = 0;

  DotSet() {
    dir = fs::temp_directory_path() / ("wheelins-bench-table-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    std::uint64_t state = 12345;
    const auto noise = [&state]() {  // a small LCG: the same text every run
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      return static_cast<double>(state >> 11) / 9007199254740992.0 - 0.5;
    };
    for (int f = 0; f < kFiles; ++f) {
      const bool mag = f >= 3;  // some exports carry magnetometer and status columns
      std::string text = "sep=,\nPacketCounter,SampleTimeFine,Euler_X,Euler_Y,Euler_Z,Acc_X,Acc_Y,Acc_Z,Gyr_X,Gyr_Y,Gyr_Z,";
      text += mag ? "Mag_X,Mag_Y,Mag_Z,Status,\n" : "\n";
      char line[512];
      std::uint64_t t = 715399356 + 1000 * static_cast<std::uint64_t>(f);
      for (int k = 0; k < kRows; ++k, t += 8333) {
        // Values as the app prints float32 readings: up to 17 significant digits.
        const auto v = [&](double x) { return static_cast<double>(static_cast<float>(x)); };
        int n = std::snprintf(line, sizeof line, "%d, %llu, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, ",
                              k, static_cast<unsigned long long>(t), v(-84 + noise()), v(-40 + noise()), v(3.6 + noise()),
                              v(5 * noise()), v(-8 + noise()), v(0.2 + noise()), v(300 * noise()), v(noise()),
                              v(noise()));
        if (mag)
          n += std::snprintf(line + n, sizeof line - static_cast<std::size_t>(n), "%.17g, %.17g, %.17g, 0, ",
                             v(0.1 + 0.01 * noise()), v(0.4 + 0.01 * noise()), v(1.26 + 0.01 * noise()));
        text.append(line, static_cast<std::size_t>(n));
        text += '\n';
      }
      const fs::path file = dir / ("IMU" + std::to_string(f + 1) + ".csv");
      std::FILE* out = std::fopen(file.c_str(), "wb");
      if (!out || std::fwrite(text.data(), 1, text.size(), out) != text.size()) std::abort();
      std::fclose(out);
      inputs.push_back({module_name_from_file(file), file, column_map_preset("xsens-dot")});
      rows += kRows;
      bytes += text.size();
    }
  }
  ~DotSet() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

const DotSet& dot_set() {
  static const DotSet set;
  return set;
}

/// The whole import: read, check, convert and write the five files.
void BM_ImportDotSet(benchmark::State& state) {
  const DotSet& set = dot_set();
  TableImportOptions o;
  o.overwrite = true;
  for (auto _ : state) {
    auto result = import_tables(set.inputs, set.dir / "out", o);
    benchmark::DoNotOptimize(result);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(set.rows));
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(set.bytes));
}
BENCHMARK(BM_ImportDotSet)->Unit(benchmark::kMillisecond);

/// Reading alone (one file, nothing written).
void BM_ReadDotTable(benchmark::State& state) {
  const DotSet& set = dot_set();
  for (auto _ : state) {
    TableReader reader(set.inputs[0].file, set.inputs[0].map);
    ImuRow row;
    while (reader.next(row)) benchmark::DoNotOptimize(row);
  }
  state.SetItemsProcessed(state.iterations() * DotSet::kRows);
}
BENCHMARK(BM_ReadDotTable)->Unit(benchmark::kMillisecond);

}  // namespace
