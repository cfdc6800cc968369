// Fuzzes the table reader (vendor CSV / text exports) with the xsens-dot and csv presets,
// and the command-line column-map parser. The first byte picks: bit 0 the preset, bit 1
// the bad-row limit (1 % or any), bit 2 the column-map string parser instead of a file.
#include <cmath>
#include <string_view>

#include "fuzz_common.hpp"
#include "wheelins/io/column_map.hpp"
#include "wheelins/io/table_reader.hpp"

using namespace wheelins;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::uint8_t mode = data[0];
  const ColumnMap preset = column_map_preset((mode & 1) ? "xsens-dot" : "csv");
  try {
    if (mode & 4) {
      const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
      const ColumnMap m = parse_column_map(text, preset);
      // A map that parses prints itself and reads back to the same map.
      if (!(parse_column_map(m.to_string()) == m)) __builtin_trap();
      (void)m.describe();
      return 0;
    }
    static const auto file = fuzz::scratch_file("table");
    fuzz::write_bytes(file, data + 1, size - 1);
    TableReadOptions o;
    o.max_bad_fraction = (mode & 2) ? 1.0 : 0.01;
    o.warn = [](const std::string&) {};
    TableReader r(file, preset, o);
    ImuRow row;
    double last = 0.0;
    bool first = true;
    while (r.next(row)) {
      // What the reader yields is a sample: finite, in range, time increasing.
      if (!std::isfinite(row.t) || !row.gyro.allFinite() || !row.accel.allFinite()) __builtin_trap();
      if (!first && !(row.t > last)) __builtin_trap();
      last = row.t;
      first = false;
    }
    const TableSummary& s = r.summary();
    if (s.rows_kept + s.faults.total() != s.rows_read) __builtin_trap();
  } catch (const InputError&) {
  }
  return 0;
}
