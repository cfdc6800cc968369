// Fuzzes the truth reader (11- and 5-column layouts, auto-detection) and the
// trajectory readers (CSV by header, TUM, Wheel-INS traj.txt).
#include "fuzz_common.hpp"
#include "wheelins/io/trajectory.hpp"
#include "wheelins/io/truth.hpp"

using namespace wheelins;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::uint8_t mode = data[0] % 5;
  static const auto bin = fuzz::scratch_file("truth.bin");
  static const auto csv = fuzz::scratch_file("traj.csv");
  static const auto tum = fuzz::scratch_file("traj.tum");
  static const auto txt = fuzz::scratch_file("traj.txt");
  try {
    switch (mode) {
      case 0: fuzz::write_bytes(bin, data + 1, size - 1); read_truth(bin); break;
      case 1: fuzz::write_bytes(bin, data + 1, size - 1); read_truth(bin, TruthLayout::kPos5); break;
      case 2: fuzz::write_bytes(csv, data + 1, size - 1); read_trajectory(csv); break;
      case 3: fuzz::write_bytes(tum, data + 1, size - 1); read_trajectory(tum); break;
      default: fuzz::write_bytes(txt, data + 1, size - 1); read_trajectory(txt, TrajectoryFormat::kWheelInsTraj); break;
    }
  } catch (const InputError&) {
  }
  return 0;
}
