// Fuzzes the text truth readers (a GNSS track with columns found by header name or given
// by index, with and without collapsing repeated fixes; TUM in ENU and NED) and the truth
// quality checks on what they accept.
#include "fuzz_common.hpp"
#include "wheelins/eval/truth_quality.hpp"
#include "wheelins/io/truth.hpp"
#include "wheelins/io/truth_text.hpp"

using namespace wheelins;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::uint8_t mode = data[0] % 5;
  static const auto file = fuzz::scratch_file("truth.txt");
  fuzz::write_bytes(file, data + 1, size - 1);
  TruthReadOptions o;
  TruthLayout layout = TruthLayout::kAuto;
  switch (mode) {
    case 0: break;  // detected, columns by header name
    case 1:
      layout = TruthLayout::kText;
      o.time_scale = 0.1;
      o.collapse_repeated = false;
      o.time_column.index = 0;
      o.lat_column.index = 1;
      o.lon_column.index = 2;
      o.height_column.index = 3;
      break;
    case 2:
      layout = TruthLayout::kText;
      o.delimiter = ';';
      o.time_offset = -5.0;
      break;
    default:
      layout = TruthLayout::kTum;
      o.tum_frame = mode == 3 ? TumFrame::kEnu : TumFrame::kNed;
      o.tum_origin = earth::Geodetic{30.5 * kDeg, 114.3 * kDeg, 20.0};
      break;
  }
  try {
    const TruthData d = read_truth(file, layout, o);
    (void)eval::describe_truth_quality(eval::check_truth_quality(d));
  } catch (const InputError&) {
  }
  return 0;
}
