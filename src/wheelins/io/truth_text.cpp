// Text truth files (truth_text.hpp): detection of text against binary and of a GNSS track
// against TUM, the column search by header name, and the streaming readers of both.
#include "wheelins/io/truth_text.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <string_view>

#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins {
namespace {

constexpr std::size_t kProbeBytes = 4096;
constexpr const char* kRoles[4] = {"time", "lat", "lon", "height"};
enum Role { kTime = 0, kLat = 1, kLon = 2, kHeight = 3 };

std::string quote(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

std::string num(double v) {
  std::string s;
  append_double(s, v, 12);
  return s;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  if (s.size() >= 2 && ((s.front() == '"' && s.back() == '"') || (s.front() == '\'' && s.back() == '\'')))
    s = trim(s.substr(1, s.size() - 2));
  return s;
}

bool is_comment_or_blank(std::string_view line) {
  line = trim(line);
  return line.empty() || line.front() == '#';
}

// Splits at `delim` (' ': runs of blanks), each field trimmed.
void split_fields(std::string_view line, char delim, std::vector<std::string>& out) {
  thread_local std::vector<std::string_view> views;
  io_detail::split_fields(line, delim, views);
  out.clear();
  for (std::string_view v : views) out.emplace_back(trim(v));
}

char delimiter_of(std::string_view line) {
  if (line.find(',') != std::string_view::npos) return ',';
  if (line.find(';') != std::string_view::npos) return ';';
  if (line.find('\t') != std::string_view::npos) return '\t';
  return ' ';
}

bool is_number(std::string_view s) { return io_detail::parse_double(s).has_value(); }

// A header name as compared: lower case, a trailing "[unit]" or "(unit)" removed, blanks
// and '-' as '_'.
std::string normalised(std::string_view name) {
  std::string s(trim(name));
  for (char open : {'[', '('}) {
    const std::size_t k = s.find(open);
    if (k != std::string::npos && k > 0) s.erase(k);
  }
  while (!s.empty() && (s.back() == ' ' || s.back() == '_')) s.pop_back();
  for (char& c : s) {
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (c == ' ' || c == '-') c = '_';
  }
  return s;
}

bool starts_with(const std::string& s, std::string_view prefix) { return s.rfind(prefix, 0) == 0; }

bool matches_role(const std::string& n, int role) {
  switch (role) {
    case kTime:
      return n == "t" || n == "t_s" || n == "sec" || n == "seconds" || starts_with(n, "time") ||
             starts_with(n, "gps_time");
    case kLat: return starts_with(n, "lat");
    case kLon: return starts_with(n, "lon") || starts_with(n, "lng");
    default: return n == "h" || n == "h_m" || starts_with(n, "height") || starts_with(n, "alt");
  }
}

// The first line of `file` that is not blank or a comment; false when there is none.
bool first_data_line(const std::filesystem::path& file, std::string& out, std::uint64_t& line_no) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(quote(file) + ": cannot open");
  std::string line;
  line_no = 0;
  while (io_detail::bounded_getline(in, line, io_detail::kMaxTextLine, quote(file))) {
    ++line_no;
    if (is_comment_or_blank(line)) continue;
    out = line;
    return true;
  }
  return false;
}

}  // namespace

bool looks_like_text_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return false;
  char buf[kProbeBytes];
  in.read(buf, sizeof buf);
  const auto n = static_cast<std::size_t>(in.gcount());
  bool line_end = false;
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(buf[i]);
    if (c == '\n') line_end = true;
    else if (c == 0x7F || (c < 0x20 && c != '\t' && c != '\r')) return false;
  }
  return line_end;
}

TruthLayout detect_text_truth_layout(const std::filesystem::path& file) {
  std::string line;
  std::uint64_t line_no = 0;
  if (!first_data_line(file, line, line_no))
    throw InputError(quote(file) + ": a text truth file with no data (only blank or '#' lines)");
  std::vector<std::string> fields;
  split_fields(line, delimiter_of(line), fields);
  const bool header = !std::all_of(fields.begin(), fields.end(), [](const std::string& f) { return is_number(f); });
  if (!header) {
    if (fields.size() == 8) return TruthLayout::kTum;
    throw InputError(quote(file) + ": line " + std::to_string(line_no) + ": " +
                     std::to_string(fields.size()) +
                     " numbers and no header: neither a TUM file (8 values: t x y z qx qy qz qw) "
                     "nor a track with named columns; give the layout (text) and the columns "
                     "(time,lat,lon,height as 0-based indices)");
  }
  int q = 0;
  for (const auto& f : fields) {
    const std::string n = normalised(f);
    if (n == "qx" || n == "qy" || n == "qz" || n == "qw") ++q;
  }
  if (fields.size() == 8 && q == 4) return TruthLayout::kTum;
  return TruthLayout::kText;
}

void set_truth_columns(TruthReadOptions& options, const std::string& spec) {
  std::vector<std::string> parts;
  split_fields(spec, ',', parts);
  if (parts.size() != 4)
    throw InputError("truth columns '" + spec + "': expected 4 columns TIME,LAT,LON,HEIGHT (header " +
                     "names or 0-based indices), got " + std::to_string(parts.size()));
  TruthColumn* cols[4] = {&options.time_column, &options.lat_column, &options.lon_column,
                          &options.height_column};
  for (int k = 0; k < 4; ++k) {
    const std::string& p = parts[static_cast<std::size_t>(k)];
    if (p.empty())
      throw InputError("truth columns '" + spec + "': the " + kRoles[k] + " column is empty");
    *cols[k] = TruthColumn{};
    if (std::all_of(p.begin(), p.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      if (p.size() > 6) throw InputError("truth columns '" + spec + "': index " + p + " is too large");
      cols[k]->index = std::stoi(p);
    } else {
      cols[k]->name = p;
    }
  }
}

// ------------------------------------------------------------------ the reader

TextTruthReader::TextTruthReader(const std::filesystem::path& file, TruthLayout layout,
                                 const TruthReadOptions& options)
    : file_(file), layout_(layout), opt_(options) {
  if (layout != TruthLayout::kText && layout != TruthLayout::kTum)
    throw InputError(quote(file) + ": the text truth reader reads the text and TUM layouts, not " +
                     truth_layout_name(layout));
  if (!(std::isfinite(opt_.time_scale) && opt_.time_scale > 0.0))
    throw InputError(quote(file) + ": time scale " + num(opt_.time_scale) + " must be a positive number");
  if (!std::isfinite(opt_.time_offset))
    throw InputError(quote(file) + ": time offset " + num(opt_.time_offset) + " must be finite");
  io_detail::check_input_file(file, "a truth file");
  in_.open(file, std::ios::binary);
  if (!in_) throw InputError(quote(file) + ": cannot open");
  if (layout == TruthLayout::kTum) {
    // The frame and origin lines a wheelins TUM file starts with stand in for options not given;
    // a frame line contradicting the one given is an error.
    const TumHeader h = read_tum_header(file);
    if (h.frame && opt_.tum_frame && *h.frame != *opt_.tum_frame)
      throw InputError(quote(file) + ": line " + std::to_string(h.frame_line) + ": the file says its frame is " +
                       tum_frame_name(*h.frame) + ", but " + tum_frame_name(*opt_.tum_frame) +
                       " was given; leave the frame out or give " + tum_frame_name(*h.frame));
    if (!opt_.tum_frame) opt_.tum_frame = h.frame ? *h.frame : TumFrame::kEnu;
    if (!opt_.tum_origin) opt_.tum_origin = h.origin;
    if (!opt_.tum_origin)
      throw InputError(quote(file) + ": a TUM truth is in a local frame: give the geodetic origin "
                       "of that frame (lat_deg,lon_deg,h_m) and its axes (enu or ned)");
    const earth::Geodetic& o = *opt_.tum_origin;
    if (!(std::isfinite(o.lat) && std::isfinite(o.lon) && std::isfinite(o.h)) ||
        std::abs(o.lat) > kPi / 2 || std::abs(o.lon) > kPi)
      throw InputError(quote(file) + ": the TUM frame's origin is not a valid lat/lon/h");
    frame_ = earth::LocalFrame(o);
    return;
  }
  read_header();
}

TextTruthReader::~TextTruthReader() = default;

bool TextTruthReader::next_line(std::string& line) {
  if (have_pending_) {
    have_pending_ = false;
    line = pending_line_;
    line_no_ = pending_line_no_;
    return true;
  }
  while (io_detail::bounded_getline(in_, line, io_detail::kMaxTextLine, quote(file_))) {
    ++line_no_;
    if (!is_comment_or_blank(line)) return true;
  }
  return false;
}

void TextTruthReader::split(const std::string& line) { split_fields(line, delim_, fields_); }

void TextTruthReader::read_header() {
  std::string first;
  if (!next_line(first))
    throw InputError(quote(file_) + ": empty truth file (no header and no data lines)");
  delim_ = opt_.delimiter ? opt_.delimiter : delimiter_of(first);
  split(first);
  const bool header = !std::all_of(fields_.begin(), fields_.end(), [](const std::string& f) { return is_number(f); });
  const TruthColumn* given[4] = {&opt_.time_column, &opt_.lat_column, &opt_.lon_column, &opt_.height_column};
  const std::string at = quote(file_) + ": line " + std::to_string(line_no_) + ": ";
  for (int k = 0; k < 4; ++k) {
    const TruthColumn& c = *given[k];
    if (c.index >= 0) {
      col_[k] = c.index;
      if (header && static_cast<std::size_t>(c.index) < fields_.size())
        col_name_[k] = fields_[static_cast<std::size_t>(c.index)];
      else if (header)
        throw InputError(at + "the " + kRoles[k] + " column " + std::to_string(c.index) +
                         " (0-based) is beyond the header's " + std::to_string(fields_.size()) + " columns");
      continue;
    }
    if (!header)
      throw InputError(at + "no header (the first line is numbers): give the " + kRoles[k] +
                       " column as a 0-based index (all four: time,lat,lon,height)");
    if (!c.name.empty()) {
      const std::string want = normalised(c.name);
      for (std::size_t i = 0; i < fields_.size(); ++i)
        if (normalised(fields_[i]) == want) {
          if (col_[k] >= 0)
            throw InputError(at + "the header names column '" + c.name + "' twice");
          col_[k] = static_cast<int>(i);
          col_name_[k] = fields_[i];
        }
      if (col_[k] < 0)
        throw InputError(at + "no column '" + c.name + "' (the " + kRoles[k] + ") in the header");
      continue;
    }
    std::vector<std::size_t> hits;
    for (std::size_t i = 0; i < fields_.size(); ++i)
      if (matches_role(normalised(fields_[i]), k)) hits.push_back(i);
    if (hits.size() != 1) {
      std::string names;
      for (std::size_t i : hits) names += (names.empty() ? "'" : ", '") + fields_[i] + "' (" + std::to_string(i) + ")";
      throw InputError(at + (hits.empty() ? "no column looks like the " + std::string(kRoles[k])
                                          : "columns " + names + " all look like the " + kRoles[k]) +
                       " (time: t|time*|timestamp, lat: lat*, lon: lon*|long*, height: h|height*|alt*); "
                       "give the columns explicitly (names or 0-based indices)");
    }
    col_[k] = static_cast<int>(hits.front());
    col_name_[k] = fields_[hits.front()];
  }
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < k; ++j)
      if (col_[j] == col_[k])
        throw InputError(at + "the " + kRoles[j] + " and the " + kRoles[k] + " are the same column " +
                         std::to_string(col_[k]));
  needed_fields_ = 1 + *std::max_element(col_, col_ + 4);
  if (!header) {  // the first line is data: read it again as such
    have_pending_ = true;
    pending_line_ = first;
    pending_line_no_ = line_no_;
  }
}

std::string TextTruthReader::where(std::uint64_t record, int col) const {
  std::string s = quote(file_) + ": record " + std::to_string(record) + " (0-based, line " +
                  std::to_string(line_no_) + ")";
  if (col >= 0) {
    s += ", column " + std::to_string(col_[col]);
    if (!col_name_[col].empty()) s += " (" + col_name_[col] + ")";
    else s += std::string(" (") + kRoles[col] + ")";
  }
  return s + ": ";
}

std::string TextTruthReader::describe() const {
  std::string time_map;
  if (opt_.time_scale != 1.0) time_map += " x " + num(opt_.time_scale);
  if (opt_.time_offset != 0.0) time_map += (opt_.time_offset > 0 ? " + " : " - ") + num(std::abs(opt_.time_offset)) + " s";
  if (layout_ == TruthLayout::kTum) {
    const earth::Geodetic& o = *opt_.tum_origin;
    return std::string("TUM in ") + (*opt_.tum_frame == TumFrame::kNed ? "NED (body FRD)" : "ENU (body FLU)") +
           " about lat " + num(o.lat / kDeg) + " deg, lon " + num(o.lon / kDeg) + " deg, h " + num(o.h) +
           " m; time" + (time_map.empty() ? " as written" : time_map);
  }
  std::string s = "columns:";
  for (int k = 0; k < 4; ++k) {
    s += std::string(k ? ", " : " ") + (k == kTime ? "time" : k == kLat ? "lat" : k == kLon ? "lon" : "h");
    if (!col_name_[k].empty()) s += " '" + col_name_[k] + "'";
    s += " (" + std::to_string(col_[k]) + ")";
    if (k == kTime && !time_map.empty()) s += time_map;
  }
  s += opt_.collapse_repeated ? "; repeated fixes collapsed" : "; repeated fixes kept";
  return s;
}

bool TextTruthReader::next(TruthRecord& out) {
  const bool got = layout_ == TruthLayout::kTum ? next_tum(out) : next_text(out);
  if (!got && records_ == 0)
    throw InputError(quote(file_) + ": empty truth file (no data lines" +
                     (layout_ == TruthLayout::kText ? std::string(" after the header)") : std::string(")")));
  if (got) ++records_;
  return got;
}

bool TextTruthReader::next_text(TruthRecord& out) {
  std::string line;
  while (next_line(line)) {
    const std::uint64_t record = rows_++;
    split(line);
    if (fields_.size() < static_cast<std::size_t>(needed_fields_))
      throw InputError(where(record, -1) + std::to_string(fields_.size()) + " fields, the columns used need " +
                       std::to_string(needed_fields_));
    double v[4];
    for (int k = 0; k < 4; ++k) {
      const std::string& f = fields_[static_cast<std::size_t>(col_[k])];
      const auto x = io_detail::parse_double(f);
      if (!x) throw InputError(where(record, k) + "not a number: '" + f + "'");
      if (!std::isfinite(*x)) throw InputError(where(record, k) + "is " + num(*x) + "; values must be finite");
      v[k] = *x;
    }
    if (std::abs(v[kLat]) > 90.0 || std::abs(v[kLon]) > 180.0)
      throw InputError(where(record, std::abs(v[kLat]) > 90.0 ? kLat : kLon) + "latitude " + num(v[kLat]) +
                       " / longitude " + num(v[kLon]) + " deg out of range (|lat| <= 90, |lon| <= 180)");
    const double t = opt_.time_scale * v[kTime] + opt_.time_offset;
    if (!std::isfinite(t)) throw InputError(where(record, kTime) + "time " + num(t) + " s is not finite after scaling");
    if (opt_.collapse_repeated && have_prev_ && v[kLat] == prev_lat_ && v[kLon] == prev_lon_ && v[kHeight] == prev_h_) {
      ++collapsed_;
      continue;
    }
    if (have_prev_ && !(t > prev_t_))
      throw InputError(where(record, kTime) + "time " + num(t) + " s does not increase (previous fix: " +
                       num(prev_t_) + " s at line " + std::to_string(prev_line_) + ")" +
                       (opt_.collapse_repeated ? "" : "; repeated fixes are kept"));
    have_prev_ = true;
    prev_t_ = t;
    prev_lat_ = v[kLat];
    prev_lon_ = v[kLon];
    prev_h_ = v[kHeight];
    prev_line_ = line_no_;
    out = TruthRecord{};
    out.t = t;
    out.lla = {v[kLat] * kDeg, v[kLon] * kDeg, v[kHeight]};
    return true;
  }
  return false;
}

bool TextTruthReader::next_tum(TruthRecord& out) {
  std::string line;
  if (!next_line(line)) return false;
  const std::uint64_t record = rows_++;
  split_fields(line, line.find(',') != std::string::npos ? ',' : ' ', fields_);
  const std::string at = quote(file_) + ": record " + std::to_string(record) + " (0-based, line " +
                         std::to_string(line_no_) + "): ";
  if (fields_.size() != 8)
    throw InputError(at + std::to_string(fields_.size()) + " values, expected 8 (TUM: t x y z qx qy qz qw)");
  static const char* const kNames[8] = {"t", "x", "y", "z", "qx", "qy", "qz", "qw"};
  double v[8];
  for (int k = 0; k < 8; ++k) {
    const auto x = io_detail::parse_double(fields_[static_cast<std::size_t>(k)]);
    if (!x) throw InputError(at + kNames[k] + " is not a number: '" + fields_[static_cast<std::size_t>(k)] + "'");
    if (!std::isfinite(*x)) throw InputError(at + kNames[k] + " is " + num(*x) + "; values must be finite");
    v[k] = *x;
  }
  const Quat q(v[7], v[4], v[5], v[6]);
  const double n = q.norm();
  if (std::abs(n - 1.0) > 1e-3)
    throw InputError(at + "quaternion norm " + num(n) + " is not 1 (expected qx qy qz qw of a unit quaternion)");
  Vec3 p_ned;
  Mat3 C_VtoN;
  tum_pose_to_ned(*opt_.tum_frame, Vec3(v[1], v[2], v[3]), q.normalized().toRotationMatrix(), p_ned, C_VtoN);
  const double t = opt_.time_scale * v[0] + opt_.time_offset;
  if (records_ > 0 && !(t > prev_t_))
    throw InputError(at + "time " + num(t) + " s does not increase (previous record: " + num(prev_t_) + " s)");
  prev_t_ = t;
  out = TruthRecord{};
  out.t = t;
  out.lla = frame_.geodetic_from_ned(p_ned);
  out.rpy = euler_from_dcm(C_VtoN);
  if (!(std::isfinite(out.lla.lat) && std::isfinite(out.lla.lon) && std::isfinite(out.lla.h)))
    throw InputError(at + "the position is not a finite lat/lon/h");
  return true;
}

}  // namespace wheelins
