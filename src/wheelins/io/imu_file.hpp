// IMU data files: 7 columns `t, gyro x y z, accel x y z` per record, as binary
// little-endian float64 rows (the Wheel-INS `*_imu.bin` layout) or as text
// (blank- or comma-separated, '#' comments). The columns hold rates (rad/s, m/s^2)
// or increments over the sample (rad, m/s), see SampleFormat.
//
// Readers stream (constant memory) and yield ImuSample increments:
//   dt = t - t_prev (the first record: 1 / rate_hz),
//   rates:      dtheta = gyro * dt, dvel = accel * dt;   increments: as stored,
//   t = file time + time_offset.
// Every record is validated; the first bad one throws InputError naming the file,
// the 0-based record index (and the line, for text) and the column.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "wheelins/io/diagnostics.hpp"
#include "wheelins/io/manifest.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins {

class RowReader;
class BinaryRowWriter;
class AtomicTextFile;

/// One record as stored in an IMU file (rates or increments, per the file's format).
struct ImuRow {
  double t = 0.0;
  Vec3 gyro = Vec3::Zero();
  Vec3 accel = Vec3::Zero();
};

/// Column names of the 7-column layout, for messages and text headers.
extern const char* const kImuColumnNames[7];

/// [s] the longest interval between two records of one IMU file (a day); longer is an error.
constexpr double kMaxImuInterval = 86400.0;

struct ImuReadOptions {
  SampleFormat format = SampleFormat::kRate;
  FileLayout layout = FileLayout::kBinary;
  double rate_hz = 200.0;     ///< nominal rate: the first record's dt and the gap threshold
  double time_offset = 0.0;   ///< added to every timestamp [s]
  double gap_factor = 5.0;    ///< an interval longer than gap_factor / rate_hz is a gap
  WarningSink warn;           ///< receives one message per gap (up to max_gap_warnings); may be empty
  int max_gap_warnings = 10;  ///< then one "further gaps ..." message, the rest only counted
  /// A NaN or infinite gyro or accelerometer value is passed on (the run's input checks
  /// leave the sample out as a fault, as one beyond the sensor range) instead of being an
  /// error; a non-finite time is an error either way.
  bool pass_nonfinite = false;
};

/// The read options a manifest gives a module (rate, format, layout, time offset).
ImuReadOptions imu_read_options(const ModuleSpec& spec, const WarningSink& warn = {});

/// The sample a record gives, as ImuFileReader yields it: t + time_offset, the interval dt
/// (t - the previous record's t; 1 / rate_hz for the first), and the increments (rates
/// times dt, or the stored increments). Streams of records that do not come from a file
/// (the Python module's navigator) use it so they navigate exactly like the file.
ImuSample imu_sample(const ImuRow& row, double dt, const ImuReadOptions& options);

/// A time gap in a data file: the interval before record `record` (0-based).
struct DataGap {
  std::uint64_t record = 0;
  double t_before = 0.0;  ///< time of the record before the gap (offset applied)
  double t_after = 0.0;   ///< time of record `record`
  double length() const { return t_after - t_before; }
};

/// Anything that yields IMU samples in time order (files, simulators, tests).
class ImuStream {
 public:
  virtual ~ImuStream() = default;
  /// Fills `out` with the next sample; false at the end.
  virtual bool next(ImuSample& out) = 0;
};

/// Streams one IMU file. The constructor reads the first record (an empty file is
/// an error), so first_time() is known before the first next().
class ImuFileReader final : public ImuStream {
 public:
  ImuFileReader(const std::filesystem::path& file, const ImuReadOptions& options = {});
  ~ImuFileReader() override;
  ImuFileReader(const ImuFileReader&) = delete;
  ImuFileReader& operator=(const ImuFileReader&) = delete;

  bool next(ImuSample& out) override;

  /// The record last returned by next(), as stored (time without the offset).
  const ImuRow& row() const { return row_; }
  /// 0-based index of the record last returned by next().
  std::uint64_t index() const { return index_; }
  /// Time of the first record (offset applied).
  double first_time() const { return first_t_ + options_.time_offset; }
  const std::filesystem::path& file() const { return file_; }
  const ImuReadOptions& options() const { return options_; }

  /// Gaps found so far: the first kMaxStoredGaps of them; gap_count() counts all.
  static constexpr std::size_t kMaxStoredGaps = 1000;
  const std::vector<DataGap>& gaps() const { return gaps_; }
  std::uint64_t gap_count() const { return gap_count_; }
  double longest_gap() const { return longest_gap_; }  ///< [s], 0 if none

 private:
  bool read_row(ImuRow& r);
  std::filesystem::path file_;
  ImuReadOptions options_;
  std::unique_ptr<RowReader> rows_;
  ImuRow row_, pending_;
  bool has_pending_ = false;
  bool started_ = false;
  double first_t_ = 0.0, prev_t_ = 0.0;
  std::uint64_t index_ = 0;
  std::vector<DataGap> gaps_;
  std::uint64_t gap_count_ = 0;
  double longest_gap_ = 0.0;
};

/// Writes a 7-column IMU file through `file.partial`; commit() moves it into place
/// (without commit() nothing is left behind). Refuses an existing file unless `overwrite`.
class ImuFileWriter {
 public:
  ImuFileWriter(const std::filesystem::path& file, SampleFormat format = SampleFormat::kRate,
                FileLayout layout = FileLayout::kBinary, bool overwrite = false);
  ~ImuFileWriter();
  ImuFileWriter(const ImuFileWriter&) = delete;
  ImuFileWriter& operator=(const ImuFileWriter&) = delete;

  /// Writes a sample in the file's format (rates: dtheta / dt, dvel / dt; needs dt > 0).
  void write(const ImuSample& s);
  /// Writes a record as stored.
  void write_row(const ImuRow& r);
  void commit();
  std::uint64_t rows() const { return rows_; }

 private:
  std::filesystem::path file_;
  SampleFormat format_;
  std::unique_ptr<BinaryRowWriter> bin_;
  std::unique_ptr<AtomicTextFile> text_;
  std::uint64_t rows_ = 0;
  double last_t_ = 0.0;
};

/// Merges several IMU streams into one time-ordered sequence of (stream index,
/// sample). Equal times come out in stream-index order. No allocation per sample.
class ImuMerger {
 public:
  /// Non-owning: the streams must outlive the merger.
  explicit ImuMerger(const std::vector<ImuStream*>& streams);
  /// Owning.
  explicit ImuMerger(std::vector<std::unique_ptr<ImuStream>> streams);

  /// The next sample of all streams; false when every stream is exhausted.
  bool next(std::size_t& stream, ImuSample& out);
  std::size_t size() const { return streams_.size(); }

 private:
  void prime();
  std::vector<std::unique_ptr<ImuStream>> owned_;
  std::vector<ImuStream*> streams_;
  std::vector<ImuSample> head_;
  std::vector<char> live_;
};

/// Opens a reader for every module of a manifest (in manifest order), files resolved
/// against the manifest's directory; gap warnings (naming the file) go to `warn`.
std::vector<std::unique_ptr<ImuFileReader>> open_imu_files(const Manifest& m,
                                                           const WarningSink& warn = {});
/// Plain pointers to readers, for the non-owning ImuMerger constructor.
std::vector<ImuStream*> stream_pointers(const std::vector<std::unique_ptr<ImuFileReader>>& readers);

}  // namespace wheelins
