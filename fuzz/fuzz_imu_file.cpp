// Fuzzes the IMU and odometer readers: binary and text layouts, rates and increments.
#include "fuzz_common.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/odometer.hpp"

using namespace wheelins;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::uint8_t mode = data[0];
  static const auto file = fuzz::scratch_file("imu");
  fuzz::write_bytes(file, data + 1, size - 1);
  try {
    if (mode & 4) {
      OdoReader odo(file, (mode & 1) ? FileLayout::kText : FileLayout::kBinary);
      OdoSample s;
      while (odo.next(s)) {
      }
    } else {
      ImuReadOptions o;
      o.layout = (mode & 1) ? FileLayout::kText : FileLayout::kBinary;
      o.format = (mode & 2) ? SampleFormat::kIncrement : SampleFormat::kRate;
      o.warn = [](const std::string&) {};
      ImuFileReader r(file, o);
      ImuSample s;
      while (r.next(s)) {
      }
    }
  } catch (const InputError&) {
  }
  return 0;
}
