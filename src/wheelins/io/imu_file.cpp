// IMU file reading and writing (imu_file.hpp): the validating streaming reader with its gap
// report, the writer, and the time-ordered merger of several streams.
#include "wheelins/io/imu_file.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/binary.hpp"
#include "wheelins/io/row_reader.hpp"
#include "wheelins/io/text_util.hpp"

namespace wheelins {
using io_detail::format_double;
using io_detail::quote;

const char* const kImuColumnNames[7] = {"t",       "gyro_x",  "gyro_y", "gyro_z",
                                        "accel_x", "accel_y", "accel_z"};

ImuReadOptions imu_read_options(const ModuleSpec& spec, const WarningSink& warn) {
  ImuReadOptions o;
  o.format = spec.format;
  o.layout = spec.layout;
  o.rate_hz = spec.rate_hz;
  o.time_offset = spec.time_offset;
  o.warn = warn;
  return o;
}

// ------------------------------------------------------------------------------- reader

ImuFileReader::ImuFileReader(const std::filesystem::path& file, const ImuReadOptions& options)
    : file_(file), options_(options) {
  if (!(options.rate_hz > 0.0) || !std::isfinite(options.rate_hz))
    throw InputError(quote(file) + ": nominal rate must be > 0 Hz, got " + format_double(options.rate_hz));
  if (!std::isfinite(options.time_offset))
    throw InputError(quote(file) + ": time offset must be finite");
  rows_ = std::make_unique<RowReader>(file, options.layout, 7, kImuColumnNames);
  if (!read_row(pending_))
    throw InputError(quote(file) + ": contains no IMU records (empty file)");
  has_pending_ = true;
  first_t_ = pending_.t;
}

ImuFileReader::~ImuFileReader() = default;

bool ImuFileReader::read_row(ImuRow& r) {
  const double* v = rows_->next();
  if (!v) return false;
  for (int c = 0; c < (options_.pass_nonfinite ? 1 : 7); ++c) {
    if (std::isnan(v[c])) rows_->fail(c, "value is NaN");
    if (std::isinf(v[c])) rows_->fail(c, "value is infinite");
  }
  r.t = v[0];
  r.gyro = Vec3(v[1], v[2], v[3]);
  r.accel = Vec3(v[4], v[5], v[6]);
  return true;
}

bool ImuFileReader::next(ImuSample& out) {
  if (has_pending_) {
    row_ = pending_;
    has_pending_ = false;
  } else if (!read_row(row_)) {
    return false;
  }
  index_ = rows_->index();
  double dt;
  if (!started_) {
    dt = 1.0 / options_.rate_hz;
    started_ = true;
  } else {
    dt = row_.t - prev_t_;
    if (!(dt > 0.0))
      rows_->fail(0, "time " + format_double(row_.t) +
                         (dt == 0.0 ? " repeats the previous record's time"
                                    : " goes back from the previous record's " + format_double(prev_t_)) +
                         " (timestamps must be strictly increasing)");
    // A time scale that is absurd: no recording pauses for more than a day. Such a jump is
    // times in another unit (milliseconds) or two recordings joined, and everything after it
    // (calibration bins, outages, positions) would be nonsense: said here, at its record.
    if (dt > kMaxImuInterval)
      rows_->fail(0, "time " + format_double(row_.t) + " is " + format_double(dt) +
                         " s after the previous record's " + format_double(prev_t_) +
                         ": more than a day (are the times in another unit than seconds, e.g. "
                         "milliseconds, or are two recordings joined?)");
    const double nominal = 1.0 / options_.rate_hz;
    if (dt > options_.gap_factor * nominal) {
      DataGap g{index_, prev_t_ + options_.time_offset, row_.t + options_.time_offset};
      if (gaps_.size() < kMaxStoredGaps) gaps_.push_back(g);
      ++gap_count_;
      if (dt > longest_gap_) longest_gap_ = dt;
      if (options_.warn) {
        if (gap_count_ <= static_cast<std::uint64_t>(options_.max_gap_warnings))
        {
          char buf[160];
          std::snprintf(buf, sizeof buf, ": record %llu (0-based): gap of %.4g s (%.0f nominal intervals) after t=%.3f",
                        static_cast<unsigned long long>(index_), dt, dt / nominal, prev_t_);
          options_.warn(quote(file_) + buf);
        }
        else if (gap_count_ == static_cast<std::uint64_t>(options_.max_gap_warnings) + 1)
          options_.warn(quote(file_) + ": further gaps are counted but not reported one by one");
      }
    }
  }
  prev_t_ = row_.t;
  out = imu_sample(row_, dt, options_);
  return true;
}

ImuSample imu_sample(const ImuRow& row, double dt, const ImuReadOptions& options) {
  ImuSample out;
  out.t = row.t + options.time_offset;
  out.dt = dt;
  if (options.format == SampleFormat::kRate) {
    out.dtheta = row.gyro * dt;
    out.dvel = row.accel * dt;
  } else {
    out.dtheta = row.gyro;
    out.dvel = row.accel;
  }
  return out;
}

// ------------------------------------------------------------------------------- writer

ImuFileWriter::ImuFileWriter(const std::filesystem::path& file, SampleFormat format,
                             FileLayout layout, bool overwrite)
    : file_(file), format_(format) {
  check_output_target(file, overwrite);
  if (layout == FileLayout::kBinary) {
    bin_ = std::make_unique<BinaryRowWriter>(file, 7);
  } else {
    text_ = std::make_unique<AtomicTextFile>(file, overwrite);
    text_->write(format == SampleFormat::kRate
                     ? "# t [s], gyro x y z [rad/s], accel x y z [m/s^2]\n"
                     : "# t [s], dtheta x y z [rad], dvel x y z [m/s] (increments per sample)\n");
  }
}

ImuFileWriter::~ImuFileWriter() = default;

void ImuFileWriter::write(const ImuSample& s) {
  if (format_ == SampleFormat::kIncrement) {
    write_row({s.t, s.dtheta, s.dvel});
    return;
  }
  if (!(s.dt > 0.0))
    throw InputError(quote(file_) + ": record " + std::to_string(rows_) +
                     " (0-based): a rate file needs dt > 0, got " + format_double(s.dt));
  write_row({s.t, s.dtheta / s.dt, s.dvel / s.dt});
}

void ImuFileWriter::write_row(const ImuRow& r) {
  const double v[7] = {r.t, r.gyro.x(), r.gyro.y(), r.gyro.z(), r.accel.x(), r.accel.y(), r.accel.z()};
  for (int c = 0; c < 7; ++c)
    if (!std::isfinite(v[c]))
      throw InputError(quote(file_) + ": record " + std::to_string(rows_) + " (0-based), column " +
                       std::to_string(c) + " (" + kImuColumnNames[c] + "): value is not finite");
  if (rows_ > 0 && !(r.t > last_t_))
    throw InputError(quote(file_) + ": record " + std::to_string(rows_) + " (0-based): time " +
                     format_double(r.t) + " is not after the previous record's " +
                     format_double(last_t_));
  last_t_ = r.t;
  if (bin_) {
    bin_->write(v);
  } else {
    std::string& b = text_->buffer();
    for (int c = 0; c < 7; ++c) {
      if (c) b += ' ';
      append_double(b, v[c]);
    }
    b += '\n';
    text_->maybe_flush();
  }
  ++rows_;
}

void ImuFileWriter::commit() {
  if (bin_) bin_->commit();
  else text_->commit();
}

// ------------------------------------------------------------------------------- merger

ImuMerger::ImuMerger(const std::vector<ImuStream*>& streams) : streams_(streams) { prime(); }

ImuMerger::ImuMerger(std::vector<std::unique_ptr<ImuStream>> streams) : owned_(std::move(streams)) {
  for (auto& s : owned_) streams_.push_back(s.get());
  prime();
}

void ImuMerger::prime() {
  head_.resize(streams_.size());
  live_.resize(streams_.size());
  for (std::size_t i = 0; i < streams_.size(); ++i) live_[i] = streams_[i]->next(head_[i]) ? 1 : 0;
}

bool ImuMerger::next(std::size_t& stream, ImuSample& out) {
  std::size_t best = streams_.size();
  for (std::size_t i = 0; i < streams_.size(); ++i)
    if (live_[i] && (best == streams_.size() || head_[i].t < head_[best].t)) best = i;
  if (best == streams_.size()) return false;
  stream = best;
  out = head_[best];
  live_[best] = streams_[best]->next(head_[best]) ? 1 : 0;
  return true;
}

std::vector<std::unique_ptr<ImuFileReader>> open_imu_files(const Manifest& m, const WarningSink& warn) {
  std::vector<std::unique_ptr<ImuFileReader>> out;
  out.reserve(m.modules.size());
  for (const auto& spec : m.modules)
    out.push_back(std::make_unique<ImuFileReader>(m.resolve(spec.file), imu_read_options(spec, warn)));
  return out;
}

std::vector<ImuStream*> stream_pointers(const std::vector<std::unique_ptr<ImuFileReader>>& readers) {
  std::vector<ImuStream*> out;
  out.reserve(readers.size());
  for (const auto& r : readers) out.push_back(r.get());
  return out;
}

}  // namespace wheelins
