// Truth files (truth.hpp): the layout detection (text, or 11- or 5-column rows checked
// against the content), the streaming reader of every layout, read_truth() and the writers.
#include "wheelins/io/truth.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <system_error>

#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/binary.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/io/truth_text.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins {
namespace {

constexpr int kCols11 = 11;
constexpr int kCols5 = 5;
constexpr double kWeekSeconds = 604800.0;
constexpr std::uint64_t kProbeRows = 256;

std::string quote(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

std::string where(const std::filesystem::path& file, std::uint64_t record) {
  return quote(file) + ": record " + std::to_string(record) + ": ";
}

std::string num(double v) {
  std::string s;
  append_double(s, v, 12);
  return s;
}

bool lat_lon_ok(double lat_deg, double lon_deg) {
  return std::abs(lat_deg) <= 90.0 && std::abs(lon_deg) <= 180.0;
}

// Content test of the first rows read as `ncols` columns (see truth.hpp).
bool plausible(const std::filesystem::path& file, int ncols) {
  BinaryRowReader rd(file, ncols);
  const std::uint64_t n = std::min<std::uint64_t>(rd.rows(), kProbeRows);
  double prev_week = -1.0, prev_t = -INFINITY;
  for (std::uint64_t i = 0; i < n; ++i) {
    const double* r = rd.next();
    if (ncols == kCols11) {
      for (int c = 0; c < kCols11; ++c)
        if (!std::isfinite(r[c])) return false;
      const double week = r[0];
      if (week < 0.0 || week >= 1e5 || week != std::floor(week) || week < prev_week) return false;
      // Within one week t must increase; a week change may reset it.
      if (week == prev_week && !(r[1] > prev_t)) return false;
      if (!lat_lon_ok(r[2], r[3])) return false;
      prev_week = week;
      prev_t = r[1];
    } else {
      for (int c = 0; c < 4; ++c)
        if (!std::isfinite(r[c])) return false;
      if (!(r[0] > prev_t)) return false;
      if (!lat_lon_ok(r[1], r[2])) return false;
      prev_t = r[0];
    }
  }
  return true;
}

}  // namespace

TruthLayout truth_layout_from_name(const std::string& name) {
  if (name == "auto") return TruthLayout::kAuto;
  if (name == "gins11" || name == "11") return TruthLayout::kGins11;
  if (name == "pos5" || name == "5") return TruthLayout::kPos5;
  if (name == "text" || name == "csv") return TruthLayout::kText;
  if (name == "tum") return TruthLayout::kTum;
  throw InputError("unknown truth layout '" + name + "' (expected auto, gins11, pos5, text or tum)");
}

const char* truth_layout_name(TruthLayout layout) {
  switch (layout) {
    case TruthLayout::kAuto: return "auto";
    case TruthLayout::kGins11: return "gins11";
    case TruthLayout::kPos5: return "pos5";
    case TruthLayout::kText: return "text";
    case TruthLayout::kTum: return "tum";
  }
  return "?";
}

TruthLayout detect_truth_layout(const std::filesystem::path& file) {
  const std::uint64_t bytes = io_detail::check_input_file(file, "a truth file (GINS.bin)");
  if (bytes == 0) throw InputError(quote(file) + ": empty truth file");
  if (looks_like_text_file(file)) return detect_text_truth_layout(file);
  const bool fits11 = bytes % (8 * kCols11) == 0;
  const bool fits5 = bytes % (8 * kCols5) == 0;
  if (!fits11 && !fits5)
    throw InputError(quote(file) + ": size " + std::to_string(bytes) +
                     " bytes fits neither truth layout (11 float64 = 88 bytes per record: "
                     "gps_week, t, lat, lon, h, vn, ve, vd, roll, pitch, yaw; or 5 float64 = "
                     "40 bytes: t, lat, lon, h, unused); truncated or not a truth file");
  // One layout fits the size: the content must fit it too, or the file is most likely the
  // other layout cut short (a truncated GINS.bin can be a whole number of 40-byte rows).
  auto only = [&](int cols, TruthLayout layout, int other_cols) {
    if (plausible(file, cols)) return layout;
    throw InputError(quote(file) + ": size " + std::to_string(bytes) + " bytes fits only the " +
                     std::to_string(cols) + "-column truth layout (" + std::to_string(8 * cols) +
                     " bytes per record), but its first records are not such a truth file; " +
                     (other_cols == kCols11 ? "an " : "a ") +
                     std::to_string(other_cols) + "-column file (" + std::to_string(8 * other_cols) +
                     " bytes per record) of this size would be truncated or misaligned");
  };
  if (fits11 && !fits5) return only(kCols11, TruthLayout::kGins11, kCols5);
  if (fits5 && !fits11) return only(kCols5, TruthLayout::kPos5, kCols11);
  const bool ok11 = plausible(file, kCols11);
  const bool ok5 = plausible(file, kCols5);
  if (ok11 && !ok5) return TruthLayout::kGins11;
  if (ok5 && !ok11) return TruthLayout::kPos5;
  throw InputError(quote(file) + ": size " + std::to_string(bytes) +
                   " bytes fits both truth layouts and the content " +
                   (ok11 ? "looks valid in both" : "is valid in neither") +
                   " (11 columns: integer GPS week, increasing time, lat/lon; 5 columns: "
                   "increasing time, lat/lon); give the layout explicitly (gins11 or pos5)");
}

TruthReader::TruthReader(const std::filesystem::path& file, TruthLayout layout,
                         const TruthReadOptions& options)
    : file_(file), layout_(layout == TruthLayout::kAuto ? detect_truth_layout(file) : layout),
      options_(options) {
  if (!(std::isfinite(options.time_scale) && options.time_scale > 0.0))
    throw InputError(quote(file) + ": time scale " + num(options.time_scale) + " must be a positive number");
  if (!std::isfinite(options.time_offset))
    throw InputError(quote(file) + ": time offset " + num(options.time_offset) + " must be finite");
  if (layout_ == TruthLayout::kText || layout_ == TruthLayout::kTum) {
    text_ = std::make_unique<TextTruthReader>(file, layout_, options);
    return;
  }
  rows_ = std::make_unique<BinaryRowReader>(file, layout_ == TruthLayout::kGins11 ? kCols11 : kCols5);
  if (rows_->rows() == 0) throw InputError(quote(file) + ": empty truth file");
}

TruthReader::~TruthReader() = default;

std::uint64_t TruthReader::rows() const { return text_ ? text_->rows() : rows_->rows(); }

std::uint64_t TruthReader::collapsed() const { return text_ ? text_->collapsed() : 0; }

std::string TruthReader::describe() const {
  std::string s = truth_layout_name(layout_);
  if (text_) return s + ": " + text_->describe();
  s += layout_ == TruthLayout::kGins11 ? ": position, velocity, attitude" : ": position only";
  if (options_.time_scale != 1.0) s += "; time x " + num(options_.time_scale);
  if (options_.time_offset != 0.0)
    s += std::string("; time ") + (options_.time_offset > 0.0 ? "+ " : "- ") + num(std::abs(options_.time_offset)) + " s";
  return s;
}

bool TruthReader::next(TruthRecord& rec) {
  if (text_) return text_->next(rec);
  if (!next_binary(rec)) return false;
  if (options_.time_scale != 1.0 || options_.time_offset != 0.0) {
    rec.t = options_.time_scale * rec.t + options_.time_offset;
    if (!std::isfinite(rec.t))
      throw InputError(where(file_, rows_->index()) + "time is not finite after scaling");
  }
  return true;
}

bool TruthReader::next_binary(TruthRecord& rec) {
  const double* r = rows_->next();
  if (!r) return false;
  const std::uint64_t i = rows_->index();
  const bool gins = layout_ == TruthLayout::kGins11;
  static const char* const kNames11[kCols11] = {"gps_week", "t",  "lat",  "lon",   "h",  "vn",
                                                "ve",       "vd", "roll", "pitch", "yaw"};
  static const char* const kNames5[4] = {"t", "lat", "lon", "h"};
  const int checked = gins ? kCols11 : 4;
  for (int c = 0; c < checked; ++c)
    if (!std::isfinite(r[c]))
      throw InputError(where(file_, i) + "column " + std::to_string(c) + " (" +
                       (gins ? kNames11[c] : kNames5[c]) + ") is " + num(r[c]) +
                       "; values must be finite");
  rec = TruthRecord{};
  double lat_deg, lon_deg;
  if (gins) {
    const double week = r[0];
    if (week < 0.0 || week != std::floor(week))
      throw InputError(where(file_, i) + "GPS week " + num(week) +
                       " is not a non-negative integer (is this an 11-column GINS file?)");
    if (!started_) first_week_ = week;
    if (week < first_week_)
      throw InputError(where(file_, i) + "GPS week " + num(week) +
                       " is before the first record's week " + num(first_week_));
    rec.t = r[1] + kWeekSeconds * (week - first_week_);
    lat_deg = r[2];
    lon_deg = r[3];
    rec.lla.h = r[4];
    rec.v_ned = Vec3(r[5], r[6], r[7]);
    rec.rpy = Vec3(r[8], r[9], r[10]) * kDeg;
  } else {
    rec.t = r[0];
    lat_deg = r[1];
    lon_deg = r[2];
    rec.lla.h = r[3];
  }
  if (!lat_lon_ok(lat_deg, lon_deg))
    throw InputError(where(file_, i) + "latitude " + num(lat_deg) + " / longitude " +
                     num(lon_deg) + " deg out of range (|lat| <= 90, |lon| <= 180)");
  if (started_ && !(rec.t > prev_t_))
    throw InputError(where(file_, i) + "time " + num(rec.t) +
                     " s does not increase (previous record: " + num(prev_t_) + " s)");
  started_ = true;
  prev_t_ = rec.t;
  rec.lla.lat = lat_deg * kDeg;
  rec.lla.lon = lon_deg * kDeg;
  return true;
}

TruthData read_truth(const std::filesystem::path& file, TruthLayout layout,
                     const TruthReadOptions& options) {
  TruthReader rd(file, layout, options);
  TruthData out;
  out.file = file;
  out.layout = rd.layout();
  out.has_velocity = rd.has_velocity();
  out.has_attitude = rd.has_attitude();
  if (rd.layout() == TruthLayout::kGins11 || rd.layout() == TruthLayout::kPos5) out.records.reserve(rd.rows());
  TruthRecord rec;
  while (rd.next(rec)) out.records.push_back(rec);
  out.gps_week = rd.gps_week();
  out.rows = rd.rows();
  out.collapsed = rd.collapsed();
  out.description = rd.describe();
  if (out.collapsed > 0)
    out.description += "; " + std::to_string(out.rows) + " rows, " + std::to_string(out.collapsed) +
                       " repeating the fix before them, " + std::to_string(out.records.size()) + " fixes";
  return out;
}

TruthWriter::TruthWriter(const std::filesystem::path& file, bool overwrite, double gps_week)
    : TruthWriter(file, TruthLayout::kGins11, overwrite, gps_week) {}

TruthWriter::TruthWriter(const std::filesystem::path& file, TruthLayout layout, bool overwrite,
                         double gps_week)
    : file_(file), layout_(layout), overwrite_(overwrite), gps_week_(gps_week) {
  if (layout != TruthLayout::kGins11 && layout != TruthLayout::kPos5)
    throw InputError(quote(file) + ": truth files are written as gins11 or pos5, not " +
                     truth_layout_name(layout));
  if (!std::isfinite(gps_week) || gps_week < 0.0 || gps_week != std::floor(gps_week))
    throw InputError(quote(file) + ": GPS week " + num(gps_week) +
                     " is not a non-negative integer");
  check_output_target(file, overwrite);
  out_ = std::make_unique<BinaryRowWriter>(file, layout == TruthLayout::kGins11 ? kCols11 : kCols5);
}

TruthWriter::~TruthWriter() = default;

void TruthWriter::write(const TruthRecord& rec) {
  const double row11[kCols11] = {gps_week_,           rec.t,         rec.lla.lat / kDeg, rec.lla.lon / kDeg,
                                 rec.lla.h,           rec.v_ned.x(), rec.v_ned.y(),      rec.v_ned.z(),
                                 rec.rpy.x() / kDeg,  rec.rpy.y() / kDeg, rec.rpy.z() / kDeg};
  const double row5[kCols5] = {rec.t, rec.lla.lat / kDeg, rec.lla.lon / kDeg, rec.lla.h, 0.0};
  const bool pos5 = layout_ == TruthLayout::kPos5;
  const double* row = pos5 ? row5 : row11;
  for (int i = 0; i < (pos5 ? kCols5 : kCols11); ++i)
    if (!std::isfinite(row[i])) throw InputError(where(file_, rows_) + "cannot write a non-finite truth value");
  if (!lat_lon_ok(row5[1], row5[2])) throw InputError(where(file_, rows_) + "latitude/longitude out of range");
  if (rows_ > 0 && !(rec.t > last_t_))
    throw InputError(where(file_, rows_) + "time " + num(rec.t) + " s does not increase (previous record: " +
                     num(last_t_) + " s)");
  if (pos5) out_->write(row5);
  else out_->write(row11);
  last_t_ = rec.t;
  ++rows_;
}

void TruthWriter::commit() {
  // BinaryRowWriter renames unconditionally; refuse a target that appeared meanwhile.
  check_output_target(file_, overwrite_);
  out_->commit();
}

void write_truth(const std::filesystem::path& file, const std::vector<TruthRecord>& records,
                 bool overwrite, double gps_week) {
  TruthWriter w(file, overwrite, gps_week);
  for (const auto& r : records) w.write(r);
  w.commit();
}

void write_truth(const std::filesystem::path& file, const std::vector<TruthRecord>& records,
                 TruthLayout layout, bool overwrite) {
  TruthWriter w(file, layout, overwrite);
  for (const auto& r : records) w.write(r);
  w.commit();
}

}  // namespace wheelins
