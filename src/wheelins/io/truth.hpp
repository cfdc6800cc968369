// Reference ("truth") trajectories: the Wheel-INS dataset's GINS.bin files.
//
// Two little-endian float64 row layouts exist:
//   kGins11: gps_week, t [s of week], lat [deg], lon [deg], h [m],
//            v_north, v_east, v_down [m/s], roll, pitch, yaw [deg]
//   kPos5:   t, lat [deg], lon [deg], h [m], (unused)   -- no velocity/attitude
//
// Auto-detection (TruthLayout::kAuto), see detect_truth_layout():
//   * the file size must be a non-zero multiple of the row size of a layout
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
// continuous: t = sow + 604800 * (week - first_week).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "wheelins/nav/earth.hpp"

namespace wheelins {

class BinaryRowReader;
class BinaryRowWriter;

/// One reference epoch. Angles in radians, lat/lon in radians (earth::Geodetic).
struct TruthRecord {
  double t = 0.0;
  earth::Geodetic lla;
  Vec3 v_ned = Vec3::Zero();  ///< [m/s]
  Vec3 rpy = Vec3::Zero();    ///< vehicle roll, pitch, yaw(heading) [rad]
};

enum class TruthLayout { kAuto, kGins11, kPos5 };

/// A whole truth file in memory (a 1 h, 200 Hz file is ~720k records, ~60 MB).
struct TruthData {
  std::filesystem::path file;
  TruthLayout layout = TruthLayout::kGins11;  ///< as read (never kAuto)
  /// False for kPos5: v_ned and rpy are zero and must not be used (no heading metrics).
  bool has_velocity_attitude = true;
  double gps_week = 0.0;  ///< the first record's week (kGins11), 0 otherwise
  std::vector<TruthRecord> records;
};

/// Decides the layout of `file` by the rule above. Throws InputError naming the
/// file when it fits neither layout or the content is ambiguous.
TruthLayout detect_truth_layout(const std::filesystem::path& file);

/// Streams a truth file record by record (constant memory), validating each as
/// read_truth() does; the same InputError names the file and the record.
class TruthReader {
 public:
  explicit TruthReader(const std::filesystem::path& file, TruthLayout layout = TruthLayout::kAuto);
  ~TruthReader();
  TruthReader(const TruthReader&) = delete;
  TruthReader& operator=(const TruthReader&) = delete;
  /// The next record; false at the end.
  bool next(TruthRecord& out);
  const std::filesystem::path& file() const { return file_; }
  TruthLayout layout() const { return layout_; }
  bool has_velocity_attitude() const { return layout_ == TruthLayout::kGins11; }
  double gps_week() const { return first_week_; }  ///< the first record's week (kGins11)
  std::uint64_t rows() const;                       ///< records in the file

 private:
  std::filesystem::path file_;
  TruthLayout layout_;
  std::unique_ptr<BinaryRowReader> rows_;
  double first_week_ = 0.0, prev_t_ = 0.0;
  bool started_ = false;
};

/// Reads and validates a truth file. Every record must have finite values (the
/// unused kPos5 column excepted), strictly increasing time, |lat| <= 90 deg and
/// |lon| <= 180 deg; the first violation throws InputError naming the file and the
/// 0-based record index. An empty file is an error.
TruthData read_truth(const std::filesystem::path& file, TruthLayout layout = TruthLayout::kAuto);

/// "gins11" / "pos5" / "auto" <-> TruthLayout (InputError for other names).
TruthLayout truth_layout_from_name(const std::string& name);
const char* truth_layout_name(TruthLayout layout);

/// Streams truth records into a kGins11 file (constant memory), through
/// `file.partial` and a rename on commit(). Refuses an existing `file` unless
/// `overwrite`. write() validates like read_truth() (finite, increasing time,
/// lat/lon range) so a broken producer fails loudly, naming the record.
class TruthWriter {
 public:
  explicit TruthWriter(const std::filesystem::path& file, bool overwrite = false,
                       double gps_week = 0.0);
  ~TruthWriter();
  TruthWriter(const TruthWriter&) = delete;
  TruthWriter& operator=(const TruthWriter&) = delete;

  void write(const TruthRecord& rec);
  void commit();
  std::uint64_t rows() const { return rows_; }

 private:
  std::filesystem::path file_;
  bool overwrite_;
  double gps_week_;
  std::unique_ptr<BinaryRowWriter> out_;
  std::uint64_t rows_ = 0;
  double last_t_ = 0.0;
};

/// Writes a whole truth set at once (kGins11) through TruthWriter.
void write_truth(const std::filesystem::path& file, const std::vector<TruthRecord>& records,
                 bool overwrite = false, double gps_week = 0.0);

}  // namespace wheelins
