// Truth trajectories as text: a GNSS track in CSV or blank-separated columns (kText) and
// a TUM file in a local frame (kTum). Both are streamed line by line (constant memory)
// into TruthRecords; TruthReader and read_truth() (truth.hpp) use them for these layouts.
//
// kText, one record per line:
//   * '#' starts a comment line; blank lines are skipped; a UTF-8 byte-order mark is ignored.
//   * The first other line is a header when any of its fields is not a number. The
//     delimiter (TruthReadOptions::delimiter, 0 = from that line): ',' if it holds one,
//     else ';', else a tab, else runs of blanks. Fields are trimmed and unquoted.
//   * Columns not given in TruthReadOptions are found in the header, names compared
//     without regard to case, with a trailing unit in brackets ("time [s]") and blanks
//     or '-' read as '_':
//       time:   t, t_s, sec, seconds, or beginning with "time" or "gps_time"
//       lat:    beginning with "lat"
//       lon:    beginning with "lon" (so "long") or "lng"
//       height: h, h_m, or beginning with "height" or "alt"
//     A role matched by two columns, or by none, is an InputError naming the columns
//     (give them explicitly then). A file without a header needs all four given as
//     0-based indices.
//   * Values: time [file units] -> t = time_scale * time + time_offset [s]; lat, lon
//     [deg]; h [m]. Each must be a finite number, |lat| <= 90, |lon| <= 180.
//   * Repeated fixes (collapse_repeated, the default): consecutive rows with identical
//     lat, lon and h are one fix, kept at its first row's time. (A receiver logged at the
//     IMU rate repeats its 5 Hz fix for 20 rows; without collapsing, every row but the
//     first of a fix would carry a position up to 0.2 s old.)
//   * After collapsing, time must increase strictly.
//   Errors name the file, the 0-based data row ("record"), the 1-based line and the column.
//
// kTum ("t x y z qx qy qz qw", evo's format), one record per line, blank- or
// comma-separated, '#' comments:
//   * TumFrame::kEnu: x east, y north, z up [m]; q rotates body (x forward, y left,
//     z up) vectors into ENU. TumFrame::kNed: x north, y east, z down; q rotates body
//     (x forward, y right, z down) vectors into NED -- what wheelins writes.
//   * The position is taken relative to the geodetic origin of that frame (required) and
//     turned into lat/lon/h exactly (through ECEF, earth.hpp); the attitude into the
//     vehicle's roll, pitch and heading C_v^n (FRD into NED). There is no velocity.
//   * q must have unit norm (within 1e-3); time must increase strictly.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "wheelins/io/truth.hpp"

namespace wheelins {

/// True when the first 4096 bytes of `file` look like text (no control characters but
/// tab, CR and LF, and at least one line end).
bool looks_like_text_file(const std::filesystem::path& file);

/// kText or kTum for a text file, by its first line that is not a comment: 8 numbers, or
/// a header naming qx, qy, qz and qw, is TUM; a header otherwise is a text track. A file
/// without such a line, or whose first line is numbers but not 8, is an InputError (give
/// the layout and the columns).
TruthLayout detect_text_truth_layout(const std::filesystem::path& file);

/// "TIME,LAT,LON,HEIGHT" as four columns, each a header name or a 0-based index (all
/// digits); sets the four columns of `options`. InputError for another count or an empty one.
void set_truth_columns(TruthReadOptions& options, const std::string& spec);


/// The streaming reader of one kText or kTum file (the rules above). The constructor reads
/// the header (kText) and checks the options; next() validates each record as it goes.
class TextTruthReader {
 public:
  TextTruthReader(const std::filesystem::path& file, TruthLayout layout,
                  const TruthReadOptions& options);
  ~TextTruthReader();
  TextTruthReader(const TextTruthReader&) = delete;
  TextTruthReader& operator=(const TextTruthReader&) = delete;

  /// The next record (the next fix when collapsing); false at the end. An empty file (no
  /// record at all) is an InputError on the first call.
  bool next(TruthRecord& out);
  std::uint64_t rows() const { return rows_; }            ///< data rows read so far
  std::uint64_t collapsed() const { return collapsed_; }  ///< rows merged so far
  /// The columns or frame used and the time mapping, e.g. "time 'Timestamp' (column 0)
  /// x 0.1 s, lat 'Lat_GNSS' (1), lon 'Long_GNSS' (2), h 'Height_GNSS' (3); repeated fixes
  /// collapsed".
  std::string describe() const;

 private:
  bool next_text(TruthRecord& out);
  bool next_tum(TruthRecord& out);
  bool next_line(std::string& line);
  void split(const std::string& line);
  std::string where(std::uint64_t record, int col) const;
  void read_header();

  std::filesystem::path file_;
  TruthLayout layout_;
  TruthReadOptions opt_;
  std::ifstream in_;
  std::string line_, pending_line_;
  bool have_pending_ = false;
  std::uint64_t line_no_ = 0, pending_line_no_ = 0;
  std::vector<std::string> fields_;
  char delim_ = ' ';
  int col_[4] = {-1, -1, -1, -1};  // time, lat, lon, height
  std::string col_name_[4];
  int needed_fields_ = 0;
  std::uint64_t rows_ = 0, collapsed_ = 0, records_ = 0;
  bool have_prev_ = false;
  double prev_t_ = 0.0, prev_lat_ = 0.0, prev_lon_ = 0.0, prev_h_ = 0.0;
  std::uint64_t prev_line_ = 0;
  earth::LocalFrame frame_;
};

}  // namespace wheelins
