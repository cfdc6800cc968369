// The row readers of row_reader.hpp (binary and text) with the location of every value.
#include "wheelins/io/row_reader.hpp"

#include <charconv>
#include <cerrno>
#include <cstring>
#include <system_error>

#include "wheelins/io/text_util.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins {
using io_detail::quote;

RowReader::RowReader(const std::filesystem::path& file, FileLayout layout, int ncols,
                     const char* const* column_names)
    : file_(file), layout_(layout), ncols_(ncols), names_(column_names) {
  if (layout == FileLayout::kBinary) {
    bin_ = std::make_unique<BinaryRowReader>(file, ncols);
    return;
  }
  io_detail::check_input_file(file, "a text data file");
  text_buf_.resize(1 << 20);
  text_.rdbuf()->pubsetbuf(text_buf_.data(), static_cast<std::streamsize>(text_buf_.size()));
  text_.open(file, std::ios::binary);
  if (!text_) throw InputError(quote(file) + ": cannot open: " + std::strerror(errno));
  row_.resize(static_cast<std::size_t>(ncols));
  line_.reserve(256);
}

RowReader::~RowReader() = default;

const double* RowReader::next() {
  const double* row = bin_ ? bin_->next() : next_text();
  if (row) index_ = returned_++;
  return row;
}

const double* RowReader::next_text() {
  while (io_detail::bounded_getline(text_, line_, io_detail::kMaxTextLine,
                                    quote(file_) + ": line " + std::to_string(line_no_ + 1))) {
    ++line_no_;
    const char* p = line_.data();
    const char* end = p + line_.size();
    if (const void* hash = std::memchr(p, '#', line_.size())) end = static_cast<const char*>(hash);
    const auto is_sep = [](char c) { return c == ' ' || c == '\t' || c == ',' || c == '\r' || c == ';'; };
    int col = 0;
    while (true) {
      while (p < end && is_sep(*p)) ++p;
      if (p == end) break;
      const char* tok_end = p;
      while (tok_end < end && !is_sep(*tok_end)) ++tok_end;
      if (col == ncols_) {
        index_ = returned_;
        fail(-1, "more than " + std::to_string(ncols_) + " values on the line (expected " +
                     std::to_string(ncols_) + " columns)");
      }
      const char* q = p;
      if (q < tok_end && *q == '+') ++q;
      double v = 0.0;
      const auto res = std::from_chars(q, tok_end, v);
      if (res.ec == std::errc::result_out_of_range || res.ec != std::errc() || res.ptr != tok_end) {
        index_ = returned_;
        fail(col, "cannot read '" + std::string(p, tok_end) + "' as a number" +
                      (returned_ == 0 && line_no_ == 1 ? " (a header line must start with '#')" : ""));
      }
      row_[static_cast<std::size_t>(col++)] = v;
      p = tok_end;
    }
    if (col == 0) continue;  // blank or comment line
    if (col != ncols_) {
      index_ = returned_;
      fail(-1, "found " + std::to_string(col) + " values, expected " + std::to_string(ncols_) +
                   " columns");
    }
    return row_.data();
  }
  if (text_.bad())
    throw InputError(quote(file_) + ": read failed after line " + std::to_string(line_no_));
  return nullptr;
}

std::string RowReader::where(int col) const {
  std::string s = quote(file_) + ": record " + std::to_string(index_) + " (0-based";
  if (!bin_) s += ", line " + std::to_string(line_no_);
  s += ")";
  if (col >= 0) s += ", column " + std::to_string(col) + " (" + names_[col] + ")";
  return s;
}

void RowReader::fail(int col, const std::string& what) const {
  throw InputError(where(col) + ": " + what);
}

}  // namespace wheelins
