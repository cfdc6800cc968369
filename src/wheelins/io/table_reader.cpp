// The table reader of table_reader.hpp: a block-buffered line source, the header and the
// units, the per-row checks with their fault classes, and the interval statistics.
#include "wheelins/io/table_reader.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <system_error>

#include "wheelins/io/text_util.hpp"
#include "wheelins/math/rotation.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins {
namespace fs = std::filesystem;
using io_detail::format_double;
using io_detail::quote;

const char* to_string(RowFault f) {
  switch (f) {
    case RowFault::kColumns: return "wrong column count";
    case RowFault::kUnparsable: return "unparsable value";
    case RowFault::kNonFinite: return "NaN or infinite";
    case RowFault::kAllZero: return "all zero";
    case RowFault::kBeyondRange: return "beyond range";
    case RowFault::kTimeNotIncreasing: return "time not increasing";
  }
  return "?";
}

const char* short_name(RowFault f) {
  switch (f) {
    case RowFault::kColumns: return "columns";
    case RowFault::kUnparsable: return "unparsable";
    case RowFault::kNonFinite: return "non-finite";
    case RowFault::kAllZero: return "zero";
    case RowFault::kBeyondRange: return "range";
    case RowFault::kTimeNotIncreasing: return "time";
  }
  return "?";
}

std::uint64_t RowFaults::total() const {
  std::uint64_t n = 0;
  for (auto c : count) n += c;
  return n;
}

std::string RowFaults::summary(bool details) const {
  std::string s;
  for (RowFault f : kRowFaults) {
    const std::uint64_t n = (*this)[f];
    if (!n) continue;
    const RowFaultExample& e = first_of(f);
    s += (s.empty() ? "" : details ? "; " : ", ") + std::to_string(n) + " " + to_string(f);
    if (details)
      s += " (first: data row " + std::to_string(e.row) + " (0-based), line " + std::to_string(e.line) + ": " + e.what + ")";
    else
      s += " (" + std::string(n > 1 ? "first " : "") + "row " + std::to_string(e.row) + ")";
  }
  return s.empty() ? "none" : s;
}

namespace {

constexpr std::size_t kBufferBytes = 1 << 20;
static_assert(kBufferBytes > io_detail::kMaxTextLine + 1);

/// Lines of a file, block-buffered (no copy per line); a line is valid until the next call.
class LineSource {
 public:
  explicit LineSource(const fs::path& file) : file_(file), buf_(kBufferBytes) {
    fp_ = std::fopen(file.c_str(), "rb");
    if (!fp_) throw InputError(quote(file) + ": cannot open: " + std::strerror(errno));
  }
  ~LineSource() {
    if (fp_) std::fclose(fp_);
  }
  LineSource(const LineSource&) = delete;
  LineSource& operator=(const LineSource&) = delete;

  /// The next line without its '\n' (and '\r'); false at the end of the file.
  bool next(std::string_view& line) {
    while (true) {
      const char* b = buf_.data() + begin_;
      const std::size_t n = end_ - begin_;
      const void* nl = n ? std::memchr(b, '\n', n) : nullptr;
      if (nl || (eof_ && n > 0)) {
        std::size_t len = nl ? static_cast<std::size_t>(static_cast<const char*>(nl) - b) : n;
        if (len > io_detail::kMaxTextLine) too_long(line_no_ + 1);
        last_begin_ = begin_;
        begin_ += nl ? len + 1 : len;
        ++line_no_;
        if (len && b[len - 1] == '\r') --len;
        line = std::string_view(b, len);
        if (line_no_ == 1 && len >= 3 && std::memcmp(b, "\xEF\xBB\xBF", 3) == 0) line.remove_prefix(3);  // BOM
        return true;
      }
      if (eof_) return false;
      if (n > io_detail::kMaxTextLine) too_long(line_no_ + 1);
      if (begin_ > 0) {
        std::memmove(buf_.data(), b, n);
        begin_ = 0;
        end_ = n;
      }
      const std::size_t got = std::fread(buf_.data() + end_, 1, buf_.size() - end_, fp_);
      if (got == 0) {
        if (std::ferror(fp_))
          throw InputError(quote(file_) + ": read failed after line " + std::to_string(line_no_) + ": " +
                           std::strerror(errno));
        eof_ = true;
      }
      end_ += got;
    }
  }
  /// Gives the line last returned back (before any other call).
  void unread() {
    begin_ = last_begin_;
    --line_no_;
  }
  std::uint64_t line_no() const { return line_no_; }

 private:
  [[noreturn]] void too_long(std::uint64_t line) const {
    throw InputError(quote(file_) + ": line " + std::to_string(line) + ": a line longer than " +
                     std::to_string(io_detail::kMaxTextLine) +
                     " characters: not a text table (binary data, or a device?)");
  }
  fs::path file_;
  std::FILE* fp_ = nullptr;
  std::vector<char> buf_;
  std::size_t begin_ = 0, end_ = 0, last_begin_ = 0;
  bool eof_ = false;
  std::uint64_t line_no_ = 0;
};

bool is_blank(char c) { return c == ' ' || c == '\t'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  return s;
}

/// A field as written: blanks around it and surrounding double quotes removed.
std::string_view clean(std::string_view s) {
  s = trim(s);
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') s = trim(s.substr(1, s.size() - 2));
  return s;
}

/// Splits `line` into at most `max` fields (delimiter 0: runs of blanks) into `out`
/// (which has room for `max`); returns how many it found.
std::size_t split(std::string_view line, char delim, std::size_t max, std::vector<std::string_view>& out) {
  std::size_t n = 0;
  const char* p = line.data();
  const char* end = p + line.size();
  if (delim) {
    while (n < max) {
      const void* hit = std::memchr(p, delim, static_cast<std::size_t>(end - p));
      const char* q = hit ? static_cast<const char*>(hit) : end;
      out[n++] = clean(std::string_view(p, static_cast<std::size_t>(q - p)));
      if (q == end) break;
      p = q + 1;
    }
    return n;
  }
  while (n < max) {
    while (p < end && is_blank(*p)) ++p;
    if (p == end) break;
    const char* q = p;
    while (q < end && !is_blank(*q)) ++q;
    out[n++] = clean(std::string_view(p, static_cast<std::size_t>(q - p)));
    p = q;
  }
  return n;
}

std::vector<std::string> split_all(std::string_view line, char delim) {
  std::vector<std::string_view> v(line.size() + 1);
  v.resize(split(line, delim, v.size(), v));
  return {v.begin(), v.end()};
}

enum class Parse { kOk = 0, kOverflow = 1, kNonFinite = 2, kBad = 3 };  // worse is larger

/// A number as a vendor writes it: from_chars' spellings (NaN, Infinity, inf, ...), a
/// leading '+'; an exponent too large is kOverflow (v = +-inf), one too small is 0.
Parse parse_value(std::string_view f, double& v) {
  const char* b = f.data();
  const char* e = b + f.size();
  if (b != e && *b == '+') {
    ++b;
    if (b == e || *b == '-') return Parse::kBad;
  }
  if (b == e) return Parse::kBad;
  const auto r = std::from_chars(b, e, v);
  if (r.ptr != e) return Parse::kBad;
  if (r.ec == std::errc::result_out_of_range) {
    const char* x = std::find_if(b, e, [](char c) { return c == 'e' || c == 'E'; });
    const bool negative = *b == '-';
    if (x + 1 < e && x[1] == '-') {
      v = negative ? -0.0 : 0.0;
      return Parse::kOk;
    }
    v = negative ? -HUGE_VAL : HUGE_VAL;
    return Parse::kOverflow;
  }
  if (r.ec != std::errc()) return Parse::kBad;
  return std::isfinite(v) ? Parse::kOk : Parse::kNonFinite;
}

/// A time value: integers exactly (counters in us or ns pass 2^53), else a double.
Parse parse_time(std::string_view f, long double& ticks) {
  const char* b = f.data();
  const char* e = b + f.size();
  if (b != e && *b == '+') {
    ++b;
    if (b == e || *b == '-') return Parse::kBad;
  }
  long long i = 0;
  const auto r = std::from_chars(b, e, i);
  if (r.ec == std::errc() && r.ptr == e) {
    ticks = static_cast<long double>(i);
    return Parse::kOk;
  }
  double v = 0.0;
  const Parse p = parse_value(f, v);
  if (p == Parse::kOverflow) return Parse::kBad;  // a time of 1e400 is not a time
  ticks = v;
  return p;
}

/// The interval statistics of TableTiming in constant memory: the first kExact intervals
/// exactly, then a histogram around their median.
class IntervalStats {
 public:
  void add(const TableGap& g) {
    const double dt = g.length();
    if (n_++ == 0) min_ = max_ = dt;
    min_ = std::min(min_, dt);
    max_ = std::max(max_, dt);
    if (count_.empty()) {
      if (early_.empty()) early_.reserve(kExact);
      early_.push_back(g);
      if (early_.size() == kExact) start_histogram();
      return;
    }
    bin(dt);
    if (dt > threshold_) gap(g);
  }

  void finish(TableTiming& out) {
    out.intervals = n_;
    if (n_ == 0) return;
    out.interval_min = min_;
    out.interval_max = max_;
    if (count_.empty()) {
      std::vector<double> d(early_.size());
      for (std::size_t i = 0; i < early_.size(); ++i) d[i] = early_[i].length();
      const auto q = [&](double p) {
        auto k = static_cast<std::ptrdiff_t>(p * static_cast<double>(d.size() - 1));
        std::nth_element(d.begin(), d.begin() + k, d.end());
        return d[static_cast<std::size_t>(k)];
      };
      out.interval_median = q(0.5);
      out.interval_p05 = q(0.05);
      out.interval_p95 = q(0.95);
      threshold_ = TableTiming::kGapFactor * out.interval_median;
      for (const auto& g : early_)
        if (g.length() > threshold_) gap(g);
    } else {
      out.interval_median = quantile(0.5);
      out.interval_p05 = quantile(0.05);
      out.interval_p95 = quantile(0.95);
    }
    out.gap_count = gap_count_;
    out.longest_gap = longest_;
    out.gaps = std::move(gaps_);
  }

 private:
  static constexpr std::size_t kExact = 4096, kBins = 16384;
  static constexpr double kSpan = 8.0;  ///< the histogram covers [0, kSpan * m0)

  void start_histogram() {
    std::vector<double> d(early_.size());
    for (std::size_t i = 0; i < early_.size(); ++i) d[i] = early_[i].length();
    const auto mid = d.begin() + static_cast<std::ptrdiff_t>((d.size() - 1) / 2);
    std::nth_element(d.begin(), mid, d.end());
    const double m0 = *mid;
    width_ = kSpan * m0 / static_cast<double>(kBins);
    threshold_ = TableTiming::kGapFactor * m0;
    count_.assign(kBins, 0);
    sum_.assign(kBins, 0.0);
    for (const auto& g : early_) {
      bin(g.length());
      if (g.length() > threshold_) gap(g);
    }
    early_.clear();
    early_.shrink_to_fit();
  }

  void bin(double dt) {
    const double x = dt / width_;
    if (x < static_cast<double>(kBins)) {
      const auto i = static_cast<std::size_t>(x);
      ++count_[i];
      sum_[i] += dt;
    } else {
      ++over_n_;
      over_sum_ += dt;
    }
  }

  /// The mean of the bin holding the value of rank floor(p (n - 1)).
  double quantile(double p) const {
    const auto k = static_cast<std::uint64_t>(p * static_cast<double>(n_ - 1));
    std::uint64_t cum = 0;
    for (std::size_t i = 0; i < kBins; ++i) {
      cum += count_[i];
      if (cum > k) return sum_[i] / static_cast<double>(count_[i]);
    }
    return over_sum_ / static_cast<double>(over_n_);
  }

  void gap(const TableGap& g) {
    ++gap_count_;
    longest_ = std::max(longest_, g.length());
    if (gaps_.size() < TableTiming::kMaxStoredGaps) gaps_.push_back(g);
  }

  std::vector<TableGap> early_;
  std::vector<std::uint64_t> count_;
  std::vector<double> sum_;
  std::uint64_t n_ = 0, over_n_ = 0, gap_count_ = 0;
  double over_sum_ = 0.0, width_ = 0.0, threshold_ = 0.0, min_ = 0.0, max_ = 0.0, longest_ = 0.0;
  std::vector<TableGap> gaps_;
};

/// A header field's name and the unit in brackets after it: "gyro_x[deg/s]", "t (s)".
struct HeaderName {
  std::string full, base, unit;
};

HeaderName header_name(std::string_view field) {
  HeaderName h;
  h.full = std::string(field);
  h.base = h.full;
  if (field.size() >= 3 && (field.back() == ']' || field.back() == ')')) {
    const char open = field.back() == ']' ? '[' : '(';
    const std::size_t at = field.rfind(open);
    if (at != std::string_view::npos && at > 0) {
      h.base = std::string(trim(field.substr(0, at)));
      h.unit = std::string(trim(field.substr(at + 1, field.size() - at - 2)));
    }
  }
  return h;
}

std::string lower(std::string_view s) {
  std::string o(s);
  for (auto& c : o) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return o;
}

/// The quantities of a row, in the order of the map and ImuRow.
constexpr int kT = 0;
const char* const kQuantity[7] = {"time", "gyro[0]", "gyro[1]", "gyro[2]", "accel[0]", "accel[1]", "accel[2]"};

}  // namespace

// ----------------------------------------------------------------------------- the reader

struct TableReader::Impl {
  Impl(const fs::path& f, const ColumnMap& m, const TableReadOptions& o)
      : file(f), map(m), opt(o), src(f) {}

  fs::path file;
  ColumnMap map;
  TableReadOptions opt;
  LineSource src;
  char delim = ',';                 ///< 0: blanks
  std::array<int, 7> col{};         ///< table column of t, gyro xyz, accel xyz
  std::array<std::string, 7> label;  ///< "column 8 (Gyr_X)"
  std::size_t need = 0;             ///< fields a row needs (the largest column + 1)
  int last_col = 0;                 ///< the quantity with the largest column
  std::array<int, 6> sensor_order{1, 2, 3, 4, 5, 6};  ///< gyro and accel quantities by column
  std::vector<std::string_view> fields;
  long double seconds_per_tick = 1.0L;
  long double wrap = 0.0L;
  double gyro_factor = 1.0, accel_factor = 1.0, gyro_limit = 0.0, accel_limit = 0.0;
  bool have_prev = false;
  long double prev_raw = 0.0L;
  std::uint64_t wraps = 0;
  double prev_t = 0.0;
  std::uint64_t prev_row = 0;
  IntervalStats stats;
  bool done = false;

  [[noreturn]] void fail_line(std::uint64_t line, const std::string& what) const {
    throw InputError(quote(file) + ": line " + std::to_string(line) + ": " + what);
  }

  void prepare(TableSummary& sum);
  void resolve_columns(const std::vector<std::string>& header, std::uint64_t header_line);
  void resolve_units(TableSummary& sum, const std::vector<std::string>& header,
                     const std::vector<std::string>& units_line, std::uint64_t units_line_no);
  bool row(std::string_view line, std::uint64_t r, ImuRow& out, TableSummary& sum);
  template <class F>
  void fault(TableSummary& sum, RowFault f, std::uint64_t r, const F& what) {
    const auto i = static_cast<std::size_t>(f);
    if (sum.faults.count[i]++ == 0) sum.faults.first[i] = RowFaultExample{r, src.line_no(), what()};
  }
  void finish(TableSummary& sum);
};

TableReader::TableReader(const fs::path& file, const ColumnMap& map, const TableReadOptions& options)
    : file_(file) {
  try {
    map.validate();
  } catch (const InputError& e) {
    throw InputError(quote(file) + ": " + e.what());
  }
  if (!(options.max_bad_fraction >= 0.0 && options.max_bad_fraction <= 1.0))
    throw InputError(quote(file) + ": the largest fraction of bad rows must be in [0, 1], got " +
                     format_double(options.max_bad_fraction));
  io_detail::check_input_file(file, "a text table (CSV or text export)");
  impl_ = std::make_unique<Impl>(file, map, options);
  impl_->prepare(summary_);
}

TableReader::~TableReader() = default;

std::uint64_t TableReader::lines_read() const { return impl_->src.line_no(); }

void TableReader::Impl::prepare(TableSummary& sum) {
  std::string_view line;
  const auto next_line = [&]() { return src.next(line); };
  Delimiter d = map.delimiter;
  // Lines before the header: a number of them, or a first `sep=X` line (its X the delimiter).
  if (map.skip_lines >= 0) {
    for (int i = 0; i < map.skip_lines; ++i)
      if (!next_line()) throw InputError(quote(file) + ": ends within the " + std::to_string(map.skip_lines) +
                                         " lines to skip before the header");
  } else if (next_line()) {
    if (line.size() >= 4 && lower(line.substr(0, 4)) == "sep=") {
      const std::string_view x = line.substr(4);
      if (d == Delimiter::kAuto && x.size() == 1) {
        if (x[0] == ',') d = Delimiter::kComma;
        else if (x[0] == ';') d = Delimiter::kSemicolon;
        else if (x[0] == '\t') d = Delimiter::kTab;
        else if (x[0] == ' ') d = Delimiter::kBlanks;
        if (d != Delimiter::kAuto) sum.notes.push_back("delimiter " + std::string(to_string(d)) + ", from the 'sep=' line");
      }
    } else {
      src.unread();
    }
  }
  // The header (or the first data row), comment lines and a units line before the data.
  std::vector<std::string> header, units;
  std::uint64_t header_line = 0, units_line_no = 0;
  bool have_header_decision = false;
  while (next_line()) {
    const std::string_view t = trim(line);
    if (t.empty()) continue;
    if (t.front() == '#') {
      std::string_view c = trim(t.substr(1));
      if (units.empty() && c.size() > 5 && lower(c.substr(0, 5)) == "units") {
        c = trim(c.substr(5));
        if (!c.empty() && (c.front() == ':' || c.front() == '=')) {
          c = trim(c.substr(1));
          units = split_all(c, c.find(',') != std::string_view::npos ? ',' : 0);
          units_line_no = src.line_no();
        }
      }
      continue;
    }
    if (have_header_decision) {  // the first data row
      src.unread();
      break;
    }
    if (d == Delimiter::kAuto) {
      d = t.find(';') != std::string_view::npos    ? Delimiter::kSemicolon
          : t.find(',') != std::string_view::npos  ? Delimiter::kComma
          : t.find('\t') != std::string_view::npos ? Delimiter::kTab
                                                   : Delimiter::kBlanks;
      sum.notes.push_back("delimiter " + std::string(to_string(d)) + ", from line " + std::to_string(src.line_no()));
    }
    delim = d == Delimiter::kComma ? ',' : d == Delimiter::kSemicolon ? ';' : d == Delimiter::kTab ? '\t' : 0;
    std::vector<std::string> f = split_all(line, delim);
    bool is_header = map.header == HeaderMode::kYes;
    if (map.header == HeaderMode::kAuto) {
      for (const auto& x : f) {
        double v;
        if (!x.empty() && parse_value(x, v) == Parse::kBad) is_header = true;
      }
    }
    have_header_decision = true;
    if (is_header) {
      header = std::move(f);
      header_line = src.line_no();
    } else {
      src.unread();  // the first data row: a units line must come before it
      break;
    }
  }
  if (!have_header_decision) {
    if (map.header == HeaderMode::kYes)
      throw InputError(quote(file) + ": has no header line (the file ends before it)");
    throw InputError(quote(file) + ": has no data rows");
  }
  if (d == Delimiter::kAuto) d = Delimiter::kComma;
  map.delimiter = d;
  if (header_line == 0) {
    for (int q = 0; q < 7; ++q) {
      const ColumnRef& r = q == 0 ? map.time : q < 4 ? map.gyro[static_cast<std::size_t>(q - 1)]
                                                     : map.accel[static_cast<std::size_t>(q - 4)];
      if (!r.name.empty())
        throw InputError(quote(file) + ": the column map names column '" + r.name + "' (" + kQuantity[q] +
                         ") but the file has no header line (line " + std::to_string(src.line_no() + 1) +
                         " holds numbers); give 0-based indices");
    }
    map.header = HeaderMode::kNo;
  } else {
    map.header = HeaderMode::kYes;
  }
  resolve_columns(header, header_line);
  resolve_units(sum, header, units, units_line_no);
  fields.resize(need);
  sum.map = map;
}

void TableReader::Impl::resolve_columns(const std::vector<std::string>& header, std::uint64_t header_line) {
  std::vector<HeaderName> names;
  for (const auto& h : header) names.push_back(header_name(h));
  for (int q = 0; q < 7; ++q) {
    const ColumnRef& r = q == 0 ? map.time : q < 4 ? map.gyro[static_cast<std::size_t>(q - 1)]
                                                   : map.accel[static_cast<std::size_t>(q - 4)];
    int c = r.index;
    if (!r.name.empty()) {
      c = -1;
      for (std::size_t i = 0; i < names.size(); ++i) {
        if (names[i].full != r.name && names[i].base != r.name) continue;
        if (c >= 0)
          fail_line(header_line, "the header names column '" + r.name + "' twice (columns " + std::to_string(c) +
                                     " and " + std::to_string(i) + "); give " + kQuantity[q] + " as a 0-based index");
        c = static_cast<int>(i);
      }
      if (c < 0) {
        std::string list, best;
        std::size_t best_d = 4;
        for (const auto& n : names) {
          if (n.full.empty()) continue;
          list += (list.empty() ? "" : ", ") + n.full;
          const std::size_t dist = io_detail::edit_distance(r.name, n.base);
          if (dist < best_d) best_d = dist, best = n.base;
        }
        fail_line(header_line, "no column '" + r.name + "' (" + kQuantity[q] + " in the column map) in the header; it has: " +
                                   list + (best.empty() ? "" : "; did you mean '" + best + "'?"));
      }
    }
    col[static_cast<std::size_t>(q)] = c;
    label[static_cast<std::size_t>(q)] =
        "column " + std::to_string(c) +
        (static_cast<std::size_t>(c) < header.size() && !header[static_cast<std::size_t>(c)].empty()
             ? " (" + header[static_cast<std::size_t>(c)] + ")"
             : std::string(" (") + kQuantity[q] + ")");
    if (static_cast<std::size_t>(c) + 1 > need) {
      need = static_cast<std::size_t>(c) + 1;
      last_col = q;
    }
  }
  std::sort(sensor_order.begin(), sensor_order.end(),
            [&](int a, int b) { return col[static_cast<std::size_t>(a)] < col[static_cast<std::size_t>(b)]; });
  for (int q = 0; q < 7; ++q)
    for (int p = 0; p < q; ++p)
      if (col[static_cast<std::size_t>(q)] == col[static_cast<std::size_t>(p)])
        throw InputError(quote(file) + ": the column map gives " + kQuantity[p] + " and " + kQuantity[q] +
                         " the same column, " + label[static_cast<std::size_t>(q)]);
}

void TableReader::Impl::resolve_units(TableSummary& sum, const std::vector<std::string>& header,
                                      const std::vector<std::string>& units_line, std::uint64_t units_line_no) {
  static const char* const kName[3] = {"time", "gyro", "accel"};
  static const char* const kAccepted[3] = {"s, ms, us or ns", "rad/s or deg/s", "m/s^2 or g"};
  static const char* const kDefault[3] = {"s", "rad/s", "m/s^2"};
  static const char* const kKey[3] = {"time_unit", "gyro_unit", "accel_unit"};
  for (int q = 0; q < 3; ++q) {
    const int first = q == 0 ? 0 : q == 1 ? 1 : 4;
    const int count = q == 0 ? 1 : 3;
    // What the file states: the units line, else the header names' brackets.
    std::string text, from;
    if (!units_line.empty()) {
      if (units_line.size() == 3) {
        text = units_line[static_cast<std::size_t>(q)];
      } else {
        for (int k = first; k < first + count; ++k) {
          const auto c = static_cast<std::size_t>(col[static_cast<std::size_t>(k)]);
          const std::string u = c < units_line.size() ? units_line[c] : "";
          if (u.empty() || u == "-") continue;
          if (!text.empty() && u != text)
            fail_line(units_line_no, std::string("the units line gives ") + kName[q] + " columns different units ('" +
                                         text + "' and '" + u + "')");
          text = u;
        }
      }
      from = "the units line (line " + std::to_string(units_line_no) + ")";
    }
    if (text.empty()) {
      for (int k = first; k < first + count; ++k) {
        const auto c = static_cast<std::size_t>(col[static_cast<std::size_t>(k)]);
        if (c >= header.size()) continue;
        const HeaderName h = header_name(header[c]);
        if (h.unit.empty()) continue;
        if (!text.empty() && h.unit != text)
          throw InputError(quote(file) + ": the header gives the " + kName[q] + " columns different units ('" + text +
                           "' and '" + h.unit + "')");
        if (text.empty()) from = "the header name '" + h.full + "'";
        text = h.unit;
      }
    }
    // The map's unit wins; the file's fills in; else the default.
    bool stated = false, parsed = false;
    std::string chosen;
    auto apply = [&](auto& field, auto parse) {
      stated = field.has_value();
      if (!text.empty()) {
        const auto u = parse(text);
        parsed = u.has_value();
        if (stated && parsed && *u != *field && opt.warn)
          opt.warn(quote(file) + ": " + from + " says " + kName[q] + " in " + text + ", the column map says " +
                   to_string(*field) + "; reading " + to_string(*field));
        if (!stated && !parsed)
          throw InputError(quote(file) + ": " + from + ": '" + text + "' is not a " + kName[q] + " unit (" +
                           kAccepted[q] + "); set " + kKey[q] + " in the column map");
        if (!stated) field = *u;
      }
      if (!field) field = *parse(kDefault[q]);
      chosen = to_string(*field);
    };
    if (q == 0) apply(map.time_unit, parse_time_unit);
    else if (q == 1) apply(map.gyro_unit, parse_gyro_unit);
    else apply(map.accel_unit, parse_accel_unit);
    sum.notes.push_back(std::string(kName[q]) + " in " + chosen +
                        (stated ? ", from the column map" : !text.empty() ? ", from " + from
                                                                           : " (the default: no unit stated)"));
  }
  static constexpr long double kTick[] = {1.0L, 1e-3L, 1e-6L, 1e-9L};
  seconds_per_tick = kTick[static_cast<int>(*map.time_unit)] * static_cast<long double>(map.time_scale);
  wrap = static_cast<long double>(map.time_wrap);
  gyro_factor = map.gyro_factor();
  accel_factor = map.accel_factor();
  gyro_limit = map.gyro_limit();
  accel_limit = map.accel_limit();
}

bool TableReader::next(ImuRow& out) {
  Impl& m = *impl_;
  if (m.done) return false;
  std::string_view line;
  while (m.src.next(line)) {
    std::size_t i = 0;
    while (i < line.size() && is_blank(line[i])) ++i;
    if (i == line.size() || line[i] == '#') continue;  // blank or comment
    const std::uint64_t r = summary_.rows_read++;
    if (m.row(line, r, out, summary_)) {
      ++summary_.rows_kept;
      return true;
    }
  }
  m.done = true;
  m.finish(summary_);
  return false;
}

bool TableReader::Impl::row(std::string_view line, std::uint64_t r, ImuRow& out, TableSummary& sum) {
  const std::size_t n = split(line, delim, need, fields);
  if (n < need) {
    fault(sum, RowFault::kColumns, r, [&] {
      return std::to_string(n) + " field" + (n == 1 ? "" : "s") + ", the column map needs " + std::to_string(need) +
             " (up to " + label[static_cast<std::size_t>(last_col)] + ")";
    });
    return false;
  }
  // Values: the worst problem decides the class (unparsable before non-finite before range).
  Parse worst = Parse::kOk;
  int worst_q = 0;
  long double raw = 0.0L;
  double v[6];
  const auto note = [&](Parse p, int q) {
    // The worst problem; of equal ones the first in the line (what a reader of the file sees).
    if (p > worst || (p == worst && p != Parse::kOk && col[static_cast<std::size_t>(q)] < col[static_cast<std::size_t>(worst_q)]))
      worst = p, worst_q = q;
  };
  note(parse_time(fields[static_cast<std::size_t>(col[kT])], raw), kT);
  bool counter_out = false;
  if (worst == Parse::kOk && wrap > 0.0L && (raw < 0.0L || raw >= wrap)) {
    counter_out = true;
    note(Parse::kBad, kT);
  }
  for (int q = 1; q < 7; ++q) note(parse_value(fields[static_cast<std::size_t>(col[static_cast<std::size_t>(q)])], v[q - 1]), q);
  if (worst == Parse::kBad) {
    fault(sum, RowFault::kUnparsable, r, [&] {
      const std::string_view f = fields[static_cast<std::size_t>(col[static_cast<std::size_t>(worst_q)])];
      const std::string& l = label[static_cast<std::size_t>(worst_q)];
      if (counter_out)
        return l + ": counter value " + std::string(f) + " is outside [0, " + std::to_string(map.time_wrap) +
               ") (time_wrap)";
      if (f.empty()) return l + " is empty";
      return l + ": cannot read '" + std::string(f.substr(0, 40)) + (f.size() > 40 ? "..." : "") + "' as a number";
    });
    return false;
  }
  if (worst == Parse::kNonFinite) {
    fault(sum, RowFault::kNonFinite, r, [&] {
      const double x = worst_q == kT ? static_cast<double>(raw) : v[worst_q - 1];
      return label[static_cast<std::size_t>(worst_q)] + (std::isnan(x) ? " is NaN" : " is infinite");
    });
    return false;
  }
  if (v[0] == 0.0 && v[1] == 0.0 && v[2] == 0.0 && v[3] == 0.0 && v[4] == 0.0 && v[5] == 0.0) {
    fault(sum, RowFault::kAllZero, r, [] { return std::string("the six gyro and accel values are all exactly 0"); });
    return false;
  }
  const Vec3 g = Vec3(v[0], v[1], v[2]) * gyro_factor;
  const Vec3 a = Vec3(v[3], v[4], v[5]) * accel_factor;
  if (worst == Parse::kOverflow || !(g.cwiseAbs().maxCoeff() <= gyro_limit) ||
      !(a.cwiseAbs().maxCoeff() <= accel_limit)) {
    fault(sum, RowFault::kBeyondRange, r, [&] {
      for (int q : sensor_order) {  // the first in the line
        const bool gy = q < 4;
        const double si = gy ? g[q - 1] : a[q - 4];
        const double lim = gy ? gyro_limit : accel_limit;
        if (std::abs(si) <= lim) continue;
        const std::string unit = gy ? to_string(*map.gyro_unit) : to_string(*map.accel_unit);
        const double range = gy ? map.gyro_range_dps : map.accel_range_m_s2;
        char limit[32];
        std::snprintf(limit, sizeof limit, "%.6g", lim / (gy ? gyro_factor : accel_factor));
        return label[static_cast<std::size_t>(q)] + " = " + format_double(v[q - 1]) + " " + unit +
               ", beyond the limit " + limit + " " + unit +
               (range > 0 ? std::string(" (the stated range + 5 %)") : std::string(" (no sensor reads more)"));
      }
      return std::string("a value beyond the sensor's range");
    });
    return false;
  }
  // Time: unwrap a counter against the last kept row, then it must increase.
  std::uint64_t wraps_now = wraps;
  if (have_prev && wrap > 0.0L) {
    if (raw < prev_raw && prev_raw - raw > wrap / 2) ++wraps_now;
    else if (raw > prev_raw && raw - prev_raw > wrap / 2) {
      fault(sum, RowFault::kTimeNotIncreasing, r, [&] {
        return label[kT] + ": counter " + io_detail::format_long_double(raw) +
               " is more than half a wrap after the previous kept row's " + io_detail::format_long_double(prev_raw) +
               ": it goes back across the wrap";
      });
      return false;
    }
  }
  const double t =
      static_cast<double>((raw + static_cast<long double>(wraps_now) * wrap) * seconds_per_tick);
  if (!std::isfinite(t)) {  // e.g. 1e300 ticks with time_scale 1e6
    fault(sum, RowFault::kUnparsable, r, [&] {
      return label[kT] + ": " + std::string(fields[static_cast<std::size_t>(col[kT])]) +
             " is beyond the seconds a double holds";
    });
    return false;
  }
  if (have_prev && !(t > prev_t)) {
    fault(sum, RowFault::kTimeNotIncreasing, r, [&] {
      return "time " + format_double(t) + " s " +
             (t == prev_t ? "repeats" : "goes back from") + " the time of the previous kept row (row " +
             std::to_string(prev_row) + ", " + format_double(prev_t) + " s)";
    });
    return false;
  }
  if (have_prev) stats.add(TableGap{r, src.line_no(), prev_t, t});
  else sum.timing.t_first = t;
  have_prev = true;
  prev_raw = raw;
  wraps = wraps_now;
  prev_t = t;
  prev_row = r;
  sum.timing.t_last = t;
  out.t = t;
  out.gyro = g;
  out.accel = a;
  return true;
}

void TableReader::Impl::finish(TableSummary& sum) {
  stats.finish(sum.timing);
  const std::uint64_t rows = sum.rows_read, bad = sum.faults.total();
  if (rows == 0) throw InputError(quote(file) + ": has no data rows");
  const std::string counts = sum.faults.summary(true);
  if (sum.rows_kept < 2)
    throw InputError(quote(file) + ": " + (sum.rows_kept == 0 ? "none" : "only 1") + " of its " +
                     std::to_string(rows) + " data rows is a valid sample (at least 2 are needed): " + counts +
                     (sum.faults[RowFault::kColumns] == rows ? " (is the delimiter or the column map right?)" : ""));
  if (static_cast<double>(bad) > opt.max_bad_fraction * static_cast<double>(rows)) {
    char pct[32], lim[32];
    std::snprintf(pct, sizeof pct, "%.3g", 100.0 * static_cast<double>(bad) / static_cast<double>(rows));
    std::snprintf(lim, sizeof lim, "%.3g", 100.0 * opt.max_bad_fraction);
    throw InputError(quote(file) + ": " + std::to_string(bad) + " of " + std::to_string(rows) + " data rows (" + pct +
                     " %) cannot be samples, more than the limit of " + lim +
                     " % (--max-bad-fraction): " + counts);
  }
}

std::uint64_t count_text_lines(const fs::path& file) {
  std::FILE* f = std::fopen(file.c_str(), "rb");
  if (!f) return 0;
  std::vector<char> buf(kBufferBytes);
  std::uint64_t n = 0;
  char last = '\n';
  std::size_t got;
  while ((got = std::fread(buf.data(), 1, buf.size(), f)) > 0) {
    n += static_cast<std::uint64_t>(std::count(buf.data(), buf.data() + got, '\n'));
    last = buf[got - 1];
  }
  std::fclose(f);
  return n + (last != '\n' ? 1 : 0);
}

}  // namespace wheelins
