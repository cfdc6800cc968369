// Block-buffered readers and writers of little-endian float64 rows (binary.hpp).
#include "wheelins/io/binary.hpp"

#include <bit>
#include <cerrno>
#include <cstring>
#include <system_error>

#include "wheelins/io/text_util.hpp"
#include "wheelins/nav/types.hpp"

static_assert(std::endian::native == std::endian::little,
              "wheelins reads little-endian float64 files natively; add byte swapping here");

namespace wheelins {
namespace {
constexpr std::size_t kBlockBytes = 1 << 20;  // 1 MiB of rows per read/write

std::string quote(const std::filesystem::path& p) { return "'" + p.string() + "'"; }
}  // namespace

BinaryRowReader::BinaryRowReader(const std::filesystem::path& file, int ncols)
    : file_(file), ncols_(ncols) {
  const std::uint64_t bytes = io_detail::check_input_file(file, "a binary data file");
  const std::uint64_t row_bytes = sizeof(double) * static_cast<std::uint64_t>(ncols);
  if (bytes % row_bytes != 0)
    throw InputError(quote(file) + ": size " + std::to_string(bytes) +
                     " bytes is not a multiple of the row size (" + std::to_string(ncols) +
                     " float64 = " + std::to_string(row_bytes) + " bytes): truncated, or not a " +
                     std::to_string(ncols) + "-column file; the last complete record is " +
                     std::to_string(bytes / row_bytes));
  rows_ = bytes / row_bytes;
  fp_ = std::fopen(file.c_str(), "rb");
  if (!fp_) throw InputError(quote(file) + ": cannot open: " + std::strerror(errno));
  block_.resize(std::max<std::size_t>(1, kBlockBytes / row_bytes) * ncols);
}

BinaryRowReader::~BinaryRowReader() {
  if (fp_) std::fclose(fp_);
}

const double* BinaryRowReader::next() {
  if (block_pos_ == block_rows_) {
    if (next_row_ >= rows_) return nullptr;
    const std::size_t want = block_.size() / ncols_;
    block_rows_ = std::fread(block_.data(), sizeof(double) * ncols_, want, fp_);
    block_pos_ = 0;
    if (block_rows_ == 0)
      throw InputError(quote(file_) + ": read failed at record " + std::to_string(next_row_) +
                       " (file changed while reading?)");
  }
  const double* row = block_.data() + block_pos_ * ncols_;
  ++block_pos_;
  ++next_row_;
  return row;
}

BinaryRowWriter::BinaryRowWriter(const std::filesystem::path& file, int ncols)
    : out_(file, AtomicFileOptions{}), ncols_(ncols) {
  block_.reserve(kBlockBytes / sizeof(double));
}

void BinaryRowWriter::write(const double* row) {
  block_.insert(block_.end(), row, row + ncols_);
  ++rows_;
  if (block_.size() + ncols_ > block_.capacity()) flush();
}

void BinaryRowWriter::flush() {
  if (block_.empty()) return;
  out_.write(block_.data(), block_.size() * sizeof(double));
  block_.clear();
}

void BinaryRowWriter::commit() {
  flush();
  out_.commit();
}

}  // namespace wheelins
