// Fuzzes the YAML loaders: the dataset manifest and the run configuration.
#include "fuzz_common.hpp"
#include "wheelins/fusion/run_config.hpp"
#include "wheelins/io/manifest.hpp"

using namespace wheelins;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const auto file = fuzz::scratch_file("config.yaml");
  fuzz::write_bytes(file, data + 1, size - 1);
  const WarningSink quiet = [](const std::string&) {};
  try {
    if (data[0] & 1) load_run_config(file, quiet);
    else load_manifest(file, quiet);
  } catch (const InputError&) {
  }
  return 0;
}
