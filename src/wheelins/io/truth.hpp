// Reference ("truth") trajectories: the Wheel-INS dataset's GINS.bin files, GNSS tracks
// as CSV/text and TUM files.
//
// Two little-endian float64 row layouts exist:
//   kGins11: gps_week, t [s of week], lat [deg], lon [deg], h [m],
//            v_north, v_east, v_down [m/s], roll, pitch, yaw [deg]
//   kPos5:   t, lat [deg], lon [deg], h [m], (unused)   -- no velocity/attitude
// and two text layouts (truth_text.hpp has their rules):
//   kText:   a GNSS track, one row per line, columns found by header name (time, lat, lon,
//            h) or given; consecutive rows repeating a fix are one fix -- no velocity/attitude
//   kTum:    "t x y z qx qy qz qw" in a local ENU or NED frame about a given geodetic
//            origin -- attitude from the quaternion, no velocity
//
// Auto-detection (TruthLayout::kAuto), see detect_truth_layout():
//   * a file whose first 4096 bytes are text (no control characters but tab, CR and LF,
//     and at least one line end) is a text truth: kTum when its first line that is not a
//     '#' comment holds 8 numbers (or is a header naming qx qy qz qw), kText otherwise;
//   * otherwise the file size must be a non-zero multiple of the row size of a layout
//     (88 bytes for kGins11, 40 bytes for kPos5); if only one fits, it is used;
//   * when both fit (sizes that are multiples of 440 bytes) the content decides:
//     the first rows (up to 256) are read in each layout and tested for
//       kGins11: column 0 a non-negative integer below 100000 that never decreases
//                (the GPS week), column 1 strictly increasing, lat in [-90, 90],
//                lon in [-180, 180], all 11 values finite;
//       kPos5:   column 0 strictly increasing, lat in [-90, 90], lon in [-180, 180],
//                columns 0..3 finite;
//     exactly one must pass, otherwise InputError asks for an explicit layout.
//   (Read as the wrong layout, a real file fails these tests at once: the wrong
//   column 0 cycles through times, latitudes, velocities and angles.)
//
// Times: TruthRecord::t is column 1 (kGins11) or column 0 (kPos5). A kGins11
// file whose week increases part-way (a run over a week boundary) keeps t
// continuous: t = sow + 604800 * (week - first_week). Every layout's time is then
// mapped as t = time_scale * t + time_offset (TruthReadOptions; 1 and 0 by default).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "wheelins/io/trajectory.hpp"  // TumFrame
#include "wheelins/nav/earth.hpp"

namespace wheelins {

class BinaryRowReader;
class BinaryRowWriter;
class TextTruthReader;

/// One reference epoch. Angles in radians, lat/lon in radians (earth::Geodetic).
struct TruthRecord {
  double t = 0.0;
  earth::Geodetic lla;
  Vec3 v_ned = Vec3::Zero();  ///< [m/s]
  Vec3 rpy = Vec3::Zero();    ///< vehicle roll, pitch, yaw(heading) [rad]
};

enum class TruthLayout { kAuto, kGins11, kPos5, kText, kTum };

/// One column of a text truth file: a header name (matched without regard to case) or a
/// 0-based index. Neither given: the column is found by its header name (truth_text.hpp).
struct TruthColumn {
  std::string name;
  int index = -1;
  bool given() const { return !name.empty() || index >= 0; }
};

/// How a truth file is read beyond its layout. The time mapping applies to every layout;
/// the rest to the text layouts named.
struct TruthReadOptions {
  double time_scale = 1.0;   ///< t = time_scale * (the file's time) + time_offset; > 0
  double time_offset = 0.0;  ///< [s]
  // kText
  TruthColumn time_column{}, lat_column{}, lon_column{}, height_column{};
  char delimiter = 0;             ///< 0: the first line decides (',', ';', tab, else blanks)
  bool collapse_repeated = true;  ///< consecutive rows with identical lat/lon/h are one fix
  // kTum
  /// Unset: the file's "# frame:" line (trajectory.hpp), else ENU.
  std::optional<TumFrame> tum_frame{};
  /// The local frame's origin; for kTum, given or from the file's "# origin:" line.
  std::optional<earth::Geodetic> tum_origin{};
};

/// A whole truth file in memory (a 1 h, 200 Hz file is ~720k records, ~60 MB).
struct TruthData {
  std::filesystem::path file;
  TruthLayout layout = TruthLayout::kGins11;  ///< as read (never kAuto)
  /// False for kPos5, kText and kTum: v_ned is zero and must not be used.
  bool has_velocity = true;
  /// False for kPos5 and kText: rpy is zero and must not be used (no truth heading).
  bool has_attitude = true;
  /// Both of the above (the 11-column layout).
  bool has_velocity_attitude() const { return has_velocity && has_attitude; }
  double gps_week = 0.0;  ///< the first record's week (kGins11), 0 otherwise
  std::uint64_t rows = 0;       ///< data rows read (more than records when fixes repeat)
  std::uint64_t collapsed = 0;  ///< rows merged into the fix before them (kText)
  /// What was read and how, for people ("columns: time 'Timestamp' (0) x 0.1 s, ...").
  std::string description;
  std::vector<TruthRecord> records;
};

/// Decides the layout of `file` by the rule above. Throws InputError naming the
/// file when it fits neither layout or the content is ambiguous.
TruthLayout detect_truth_layout(const std::filesystem::path& file);

/// Streams a truth file record by record (constant memory, text layouts included),
/// validating each as read_truth() does; the same InputError names the file and the record.
class TruthReader {
 public:
  explicit TruthReader(const std::filesystem::path& file, TruthLayout layout = TruthLayout::kAuto,
                       const TruthReadOptions& options = {});
  ~TruthReader();
  TruthReader(const TruthReader&) = delete;
  TruthReader& operator=(const TruthReader&) = delete;
  /// The next record; false at the end.
  bool next(TruthRecord& out);
  const std::filesystem::path& file() const { return file_; }
  TruthLayout layout() const { return layout_; }
  bool has_velocity() const { return layout_ == TruthLayout::kGins11; }
  bool has_attitude() const { return layout_ == TruthLayout::kGins11 || layout_ == TruthLayout::kTum; }
  bool has_velocity_attitude() const { return has_velocity() && has_attitude(); }
  double gps_week() const { return first_week_; }  ///< the first record's week (kGins11)
  /// Records in the file for the binary layouts; for the text layouts the data rows read so
  /// far (not known in advance).
  std::uint64_t rows() const;
  /// Rows merged into the fix before them so far (kText).
  std::uint64_t collapsed() const;
  /// The layout and what was applied (columns, time mapping, frame); for the text layouts
  /// complete once the header has been read (after the constructor).
  std::string describe() const;

 private:
  bool next_binary(TruthRecord& out);
  std::filesystem::path file_;
  TruthLayout layout_;
  TruthReadOptions options_;
  std::unique_ptr<BinaryRowReader> rows_;
  std::unique_ptr<TextTruthReader> text_;
  double first_week_ = 0.0, prev_t_ = 0.0;
  bool started_ = false;
};

/// Reads and validates a truth file. Every record must have finite values (the
/// unused kPos5 column excepted), strictly increasing time, |lat| <= 90 deg and
/// |lon| <= 180 deg; the first violation throws InputError naming the file and the
/// 0-based record index (and for text the line and the column). An empty file is an error.
TruthData read_truth(const std::filesystem::path& file, TruthLayout layout = TruthLayout::kAuto,
                     const TruthReadOptions& options = {});

/// "auto" / "gins11" / "pos5" / "text" / "tum" <-> TruthLayout (InputError for other names).
TruthLayout truth_layout_from_name(const std::string& name);
const char* truth_layout_name(TruthLayout layout);

/// Streams truth records into a kGins11 or a kPos5 file (constant memory), through
/// `file.partial` and a rename on commit(). Refuses an existing `file` unless
/// `overwrite`. write() validates like read_truth() (finite, increasing time,
/// lat/lon range) so a broken producer fails loudly, naming the record. A kPos5 row is
/// t, lat, lon, h, 0 (velocity and attitude are not written, nor checked).
class TruthWriter {
 public:
  explicit TruthWriter(const std::filesystem::path& file, bool overwrite = false,
                       double gps_week = 0.0);
  /// A writer of `layout` (kGins11 or kPos5; others throw InputError).
  TruthWriter(const std::filesystem::path& file, TruthLayout layout, bool overwrite = false,
              double gps_week = 0.0);
  ~TruthWriter();
  TruthWriter(const TruthWriter&) = delete;
  TruthWriter& operator=(const TruthWriter&) = delete;

  void write(const TruthRecord& rec);
  void commit();
  std::uint64_t rows() const { return rows_; }

 private:
  std::filesystem::path file_;
  TruthLayout layout_ = TruthLayout::kGins11;
  bool overwrite_;
  double gps_week_;
  std::unique_ptr<BinaryRowWriter> out_;
  std::uint64_t rows_ = 0;
  double last_t_ = 0.0;
};

/// Writes a whole truth set at once (kGins11) through TruthWriter.
void write_truth(const std::filesystem::path& file, const std::vector<TruthRecord>& records,
                 bool overwrite = false, double gps_week = 0.0);
/// Writes a whole truth set at once in `layout` (kGins11 or kPos5) through TruthWriter;
/// kPos5 stores positions only (a GNSS track converted to binary).
void write_truth(const std::filesystem::path& file, const std::vector<TruthRecord>& records,
                 TruthLayout layout, bool overwrite = false);

}  // namespace wheelins
