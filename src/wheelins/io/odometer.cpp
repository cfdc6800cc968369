// Odometer file reading and writing (odometer.hpp).
#include "wheelins/io/odometer.hpp"

#include <cmath>

#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/binary.hpp"
#include "wheelins/io/row_reader.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins {
using io_detail::format_double;
using io_detail::quote;

const char* const kOdoColumnNames[2] = {"t", "speed"};

OdoReader::OdoReader(const std::filesystem::path& file, FileLayout layout, double time_offset)
    : file_(file), offset_(time_offset) {
  if (!std::isfinite(time_offset)) throw InputError(quote(file) + ": time offset must be finite");
  rows_ = std::make_unique<RowReader>(file, layout, 2, kOdoColumnNames);
  if (!read(first_)) throw InputError(quote(file) + ": contains no odometer records (empty file)");
}

OdoReader::~OdoReader() = default;

bool OdoReader::read(OdoSample& s) {
  const double* v = rows_->next();
  if (!v) return false;
  for (int c = 0; c < 2; ++c) {
    if (std::isnan(v[c])) rows_->fail(c, "value is NaN");
    if (std::isinf(v[c])) rows_->fail(c, "value is infinite");
  }
  if (started_ && !(v[0] > prev_t_))
    rows_->fail(0, "time " + format_double(v[0]) +
                       (v[0] == prev_t_ ? " repeats the previous record's time"
                                        : " goes back from the previous record's " + format_double(prev_t_)) +
                       " (timestamps must be strictly increasing)");
  started_ = true;
  prev_t_ = v[0];
  s.t = v[0] + offset_;
  s.speed = v[1];
  return true;
}

bool OdoReader::next(OdoSample& out) {
  if (has_first_) {
    out = first_;
    has_first_ = false;
  } else if (!read(out)) {
    return false;
  }
  index_ = rows_->index();
  return true;
}

OdoWriter::OdoWriter(const std::filesystem::path& file, FileLayout layout, bool overwrite)
    : file_(file) {
  check_output_target(file, overwrite);
  if (layout == FileLayout::kBinary) {
    bin_ = std::make_unique<BinaryRowWriter>(file, 2);
  } else {
    text_ = std::make_unique<AtomicTextFile>(file, overwrite);
    text_->write("# t [s], forward speed [m/s]\n");
  }
}

OdoWriter::~OdoWriter() = default;

void OdoWriter::write(const OdoSample& s) {
  const double v[2] = {s.t, s.speed};
  for (int c = 0; c < 2; ++c)
    if (!std::isfinite(v[c]))
      throw InputError(quote(file_) + ": record " + std::to_string(rows_) + " (0-based), column " +
                       std::to_string(c) + " (" + kOdoColumnNames[c] + "): value is not finite");
  if (rows_ > 0 && !(s.t > last_t_))
    throw InputError(quote(file_) + ": record " + std::to_string(rows_) + " (0-based): time " +
                     format_double(s.t) + " is not after the previous record's " + format_double(last_t_));
  last_t_ = s.t;
  if (bin_) {
    bin_->write(v);
  } else {
    std::string& b = text_->buffer();
    append_double(b, v[0]);
    b += ' ';
    append_double(b, v[1]);
    b += '\n';
    text_->maybe_flush();
  }
  ++rows_;
}

void OdoWriter::commit() {
  if (bin_) bin_->commit();
  else text_->commit();
}

}  // namespace wheelins
