// Trajectory files (trajectory.hpp): the CSV, TUM and KML writers and the validating
// reader of CSV, TUM and the public Wheel-INS traj.txt.
#include "wheelins/io/trajectory.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <stdexcept>
#include <system_error>

#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins {
namespace {

constexpr double kDegPerHour = kDeg / 3600.0;  // 1 deg/h in rad/s
constexpr double kPpm = 1e-6;
constexpr int kStdDigits = 9;  // significant digits of std / IMU-error columns

std::string quote(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

std::string num(double v) {
  std::string s;
  append_double(s, v, 12);
  return s;
}

// ----------------------------------------------------------------- CSV layout
// One column: header name, how to get its value from a record (in file units)
// and how to put it back.
struct CsvColumn {
  const char* name;
  double (*get)(const TrajectoryRecord&);
  void (*set)(TrajectoryRecord&, double);
  bool full_precision;
};

#define WHEELINS_VEC_COLS(prefix, field, unit, scale, full)                                    \
  CsvColumn{prefix "_x" unit, [](const TrajectoryRecord& r) { return r.field.x() / (scale); }, \
            [](TrajectoryRecord& r, double v) { r.field.x() = v * (scale); }, full},           \
      CsvColumn{prefix "_y" unit,                                                              \
                [](const TrajectoryRecord& r) { return r.field.y() / (scale); },               \
                [](TrajectoryRecord& r, double v) { r.field.y() = v * (scale); }, full},       \
      CsvColumn{prefix "_z" unit,                                                              \
                [](const TrajectoryRecord& r) { return r.field.z() / (scale); },               \
                [](TrajectoryRecord& r, double v) { r.field.z() = v * (scale); }, full}

#define WHEELINS_COL(name, expr_get, lhs, scale, full)                              \
  CsvColumn{name, [](const TrajectoryRecord& r) { return (expr_get) / (scale); }, \
            [](TrajectoryRecord& r, double v) { lhs = v * (scale); }, full}

constexpr std::size_t kMaxCsvColumns = 64;  // room of CsvWriter's line buffer

const std::vector<CsvColumn>& csv_columns() {
  static const std::vector<CsvColumn> cols = {
      WHEELINS_COL("t_s", r.t, r.t, 1.0, true),
      WHEELINS_COL("north_m", r.p_inN.x(), r.p_inN.x(), 1.0, true),
      WHEELINS_COL("east_m", r.p_inN.y(), r.p_inN.y(), 1.0, true),
      WHEELINS_COL("down_m", r.p_inN.z(), r.p_inN.z(), 1.0, true),
      WHEELINS_COL("lat_deg", r.lla.lat, r.lla.lat, kDeg, true),
      WHEELINS_COL("lon_deg", r.lla.lon, r.lla.lon, kDeg, true),
      WHEELINS_COL("h_m", r.lla.h, r.lla.h, 1.0, true),
      WHEELINS_COL("vn_m_s", r.v_inN.x(), r.v_inN.x(), 1.0, true),
      WHEELINS_COL("ve_m_s", r.v_inN.y(), r.v_inN.y(), 1.0, true),
      WHEELINS_COL("vd_m_s", r.v_inN.z(), r.v_inN.z(), 1.0, true),
      WHEELINS_COL("roll_deg", r.rpy.x(), r.rpy.x(), kDeg, true),
      WHEELINS_COL("pitch_deg", r.rpy.y(), r.rpy.y(), kDeg, true),
      WHEELINS_COL("heading_deg", r.rpy.z(), r.rpy.z(), kDeg, true),
      WHEELINS_COL("north_std_m", r.p_std.x(), r.p_std.x(), 1.0, false),
      WHEELINS_COL("east_std_m", r.p_std.y(), r.p_std.y(), 1.0, false),
      WHEELINS_COL("down_std_m", r.p_std.z(), r.p_std.z(), 1.0, false),
      WHEELINS_COL("vn_std_m_s", r.v_std.x(), r.v_std.x(), 1.0, false),
      WHEELINS_COL("ve_std_m_s", r.v_std.y(), r.v_std.y(), 1.0, false),
      WHEELINS_COL("vd_std_m_s", r.v_std.z(), r.v_std.z(), 1.0, false),
      WHEELINS_COL("roll_std_deg", r.rpy_std.x(), r.rpy_std.x(), kDeg, false),
      WHEELINS_COL("pitch_std_deg", r.rpy_std.y(), r.rpy_std.y(), kDeg, false),
      WHEELINS_COL("heading_std_deg", r.rpy_std.z(), r.rpy_std.z(), kDeg, false),
      WHEELINS_VEC_COLS("bg", bg, "_deg_h", kDegPerHour, false),
      WHEELINS_VEC_COLS("ba", ba, "_m_s2", 1.0, false),
      WHEELINS_VEC_COLS("sg", sg, "_ppm", kPpm, false),
      WHEELINS_VEC_COLS("sa", sa, "_ppm", kPpm, false),
      WHEELINS_VEC_COLS("bg", bg_std, "_std_deg_h", kDegPerHour, false),
      WHEELINS_VEC_COLS("ba", ba_std, "_std_m_s2", 1.0, false),
      WHEELINS_VEC_COLS("sg", sg_std, "_std_ppm", kPpm, false),
      WHEELINS_VEC_COLS("sa", sa_std, "_std_ppm", kPpm, false),
  };
  if (cols.size() > kMaxCsvColumns) throw std::logic_error("CSV layout: raise kMaxCsvColumns");
  return cols;
}
#undef WHEELINS_VEC_COLS
#undef WHEELINS_COL

// ------------------------------------------------------------------- writers
class TimeOrder {
 public:
  void check(const std::filesystem::path& file, std::uint64_t index, double t) {
    if (!std::isfinite(t))
      throw InputError(quote(file) + ": record " + std::to_string(index) + ": time is " + num(t));
    if (index > 0 && !(t > last_))
      throw InputError(quote(file) + ": record " + std::to_string(index) + ": time " + num(t) +
                       " s does not increase (previous record: " + num(last_) + " s)");
    last_ = t;
  }

 private:
  double last_ = 0.0;
};

class CsvWriter final : public TrajectoryWriter {
 public:
  CsvWriter(const std::filesystem::path& file, bool overwrite) : out_(file, overwrite) {
    std::string header;
    for (const auto& c : csv_columns()) {
      if (!header.empty()) header += ',';
      header += c.name;
    }
    header += '\n';
    out_.write(header);
  }
  void write(const TrajectoryRecord& rec) override {
    order_.check(out_.file(), n_, rec.t);
    // The line is formatted into a local buffer and appended once.
    char line[kMaxCsvColumns * (kMaxDoubleChars + 1)];
    char* p = line;
    for (const auto& c : csv_columns()) {
      p = write_double(p, c.get(rec), c.full_precision ? 0 : kStdDigits);
      *p++ = ',';
    }
    if (p == line) *p++ = '\n';  // (no columns: cannot happen)
    else p[-1] = '\n';           // the last separator becomes the line end
    out_.buffer().append(line, p);
    out_.maybe_flush();
    ++n_;
  }
  void commit() override { out_.commit(); }
  std::uint64_t records() const override { return n_; }

 private:
  AtomicTextFile out_;
  TimeOrder order_;
  std::uint64_t n_ = 0;
};

class TumWriter final : public TrajectoryWriter {
 public:
  TumWriter(const std::filesystem::path& file, const TrajectoryWriterOptions& opt)
      : out_(file, opt.overwrite), frame_(opt.tum_frame) {
    // The three comment lines read_tum_header() understands (evo and other TUM readers skip them).
    out_.write(frame_ == TumFrame::kNed
                   ? "# frame: ned (x north, y east, z down; q: body x forward, y right, z down -> NED)\n"
                   : "# frame: enu (x east, y north, z up; q: body x forward, y left, z up -> ENU)\n");
    if (opt.origin) {
      std::string o = "# origin: ";
      append_double(o, opt.origin->lat / kDeg, 15);
      o += ' ';
      append_double(o, opt.origin->lon / kDeg, 15);
      o += ' ';
      append_double(o, opt.origin->h, 15);
      out_.write(o + "  (lat_deg lon_deg h_m of the local frame)\n");
    }
    out_.write("# t x y z qx qy qz qw\n");
  }
  void write(const TrajectoryRecord& rec) override {
    order_.check(out_.file(), n_, rec.t);
    Vec3 xyz = rec.p_inN;
    Quat q = quat_from_euler(rec.rpy);  // NED: as written before the frame line existed, to the bit
    if (frame_ == TumFrame::kEnu) {
      Mat3 C;
      tum_pose_from_ned(frame_, rec.p_inN, dcm_from_euler(rec.rpy), xyz, C);
      q = Quat(C);
    }
    std::string& b = out_.buffer();
    const double vals[8] = {rec.t, xyz.x(), xyz.y(), xyz.z(), q.x(), q.y(), q.z(), q.w()};
    for (int i = 0; i < 8; ++i) {
      if (i) b += ' ';
      append_double(b, vals[i]);
    }
    b += '\n';
    out_.maybe_flush();
    ++n_;
  }
  void commit() override { out_.commit(); }
  std::uint64_t records() const override { return n_; }

 private:
  AtomicTextFile out_;
  TumFrame frame_;
  TimeOrder order_;
  std::uint64_t n_ = 0;
};

std::string xml_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

// Keeps the decimated points in memory (bounded by max_points) and writes the
// file on commit(): when the cap is reached, every other point is dropped and
// the spacing doubles, so the whole run stays covered evenly.
class KmlWriter final : public TrajectoryWriter {
 public:
  KmlWriter(const std::filesystem::path& file, const TrajectoryWriterOptions& opt)
      : out_(file, opt.overwrite),
        interval_(opt.kml_min_interval),
        max_points_(std::max<std::size_t>(opt.kml_max_points, 2)),
        name_(opt.kml_name) {
    if (!(interval_ >= 0.0) || !std::isfinite(interval_))
      throw InputError(quote(file) + ": KML point interval must be a finite value >= 0");
    pts_.reserve(std::min<std::size_t>(max_points_, 4096));
  }
  void write(const TrajectoryRecord& rec) override {
    order_.check(out_.file(), n_, rec.t);
    ++n_;
    if (!std::isfinite(rec.lla.lat) || !std::isfinite(rec.lla.lon) || !std::isfinite(rec.lla.h))
      return;  // a diverged epoch has no place on a map
    last_ = Point{rec.t, rec.lla.lon / kDeg, rec.lla.lat / kDeg, rec.lla.h};
    have_last_ = true;
    // (1 us of slack so sample times like 0.005 * i do not miss a slot by rounding)
    if (pts_.empty() || rec.t - pts_.back().t >= interval_ - 1e-6) {
      if (pts_.size() + 1 >= max_points_) thin();  // keep one slot for the final point
      pts_.push_back(last_);
    }
  }
  void commit() override {
    if (have_last_ && (pts_.empty() || pts_.back().t != last_.t)) {
      if (pts_.size() + 1 > max_points_) thin();
      pts_.push_back(last_);
    }
    const std::string name = xml_escape(name_);
    std::string& b = out_.buffer();
    b += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<kml xmlns=\"http://www.opengis.net/kml/2.2\">\n<Document>\n<name>";
    b += name;
    b += "</name>\n<Style id=\"track\"><LineStyle><color>ff0000ff</color><width>3</width>"
         "</LineStyle></Style>\n<Placemark>\n<name>";
    b += name;
    b += "</name>\n<styleUrl>#track</styleUrl>\n<LineString>\n<tessellate>1</tessellate>\n"
         "<altitudeMode>clampToGround</altitudeMode>\n<coordinates>\n";
    for (const auto& p : pts_) {
      append_fixed(b, p.lon, 9);
      b += ',';
      append_fixed(b, p.lat, 9);
      b += ',';
      append_fixed(b, p.h, 3);
      b += '\n';
      out_.maybe_flush();
    }
    b += "</coordinates>\n</LineString>\n</Placemark>\n</Document>\n</kml>\n";
    out_.commit();
  }
  std::uint64_t records() const override { return n_; }

 private:
  struct Point {
    double t, lon, lat, h;
  };
  void thin() {
    std::size_t j = 0;
    for (std::size_t i = 0; i < pts_.size(); i += 2) pts_[j++] = pts_[i];
    pts_.resize(j);
    interval_ = std::max(2.0 * interval_, 1e-9);
  }
  AtomicTextFile out_;
  TimeOrder order_;
  double interval_;
  std::size_t max_points_;
  std::string name_;
  std::vector<Point> pts_;
  Point last_{};
  bool have_last_ = false;
  std::uint64_t n_ = 0;
};

// ------------------------------------------------------------------- readers
std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

bool parse_double(std::string_view s, double& v) {
  s = trim(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  const auto res = std::from_chars(s.data(), s.data() + s.size(), v);
  return res.ec == std::errc() && res.ptr == s.data() + s.size();
}

void split(std::string_view line, char sep, std::vector<std::string_view>& out) {
  io_detail::split_fields(line, sep, out);
}

bool is_comment_or_blank(std::string_view line) {
  line = trim(line);
  return line.empty() || line.front() == '#' || line.front() == '%';
}

std::string at_line(const std::filesystem::path& file, std::size_t line) {
  return quote(file) + ": line " + std::to_string(line) + ": ";
}

std::ifstream open_text(const std::filesystem::path& file) {
  io_detail::check_input_file(file, "a trajectory file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(quote(file) + ": cannot open");
  return in;
}

// Checks what every format needs: finite time and position, increasing time.
void check_record(const std::filesystem::path& file, std::size_t line, const TrajectoryRecord& r,
                  const TrajectoryRecord* prev, bool lla, bool ned) {
  if (!std::isfinite(r.t)) throw InputError(at_line(file, line) + "time is " + num(r.t));
  if (lla && !(std::isfinite(r.lla.lat) && std::isfinite(r.lla.lon) && std::isfinite(r.lla.h)))
    throw InputError(at_line(file, line) + "latitude/longitude/height not finite");
  if (lla && (std::abs(r.lla.lat) > kPi / 2 || std::abs(r.lla.lon) > kPi))
    throw InputError(at_line(file, line) + "latitude " + num(r.lla.lat / kDeg) + " / longitude " +
                     num(r.lla.lon / kDeg) + " deg out of range");
  if (ned && !r.p_inN.allFinite())
    throw InputError(at_line(file, line) + "position is not finite");
  if (prev && !(r.t > prev->t))
    throw InputError(at_line(file, line) + "time " + num(r.t) +
                     " s does not increase (previous record: " + num(prev->t) + " s)");
}

TrajectoryData read_csv(const std::filesystem::path& file) {
  std::ifstream in = open_text(file);
  TrajectoryData out;
  out.file = file;
  out.format = TrajectoryFormat::kCsv;
  std::string line;
  std::size_t lineno = 0;
  std::vector<std::string_view> fields;
  // Column index in the file -> setter (nullptr: ignored).
  std::vector<const CsvColumn*> setters;
  bool have_header = false;
  std::map<std::string, int> seen;
  while (io_detail::bounded_getline(in, line, io_detail::kMaxTextLine, quote(file))) {
    ++lineno;
    if (is_comment_or_blank(line)) continue;
    split(line, ',', fields);
    if (!have_header) {
      have_header = true;
      for (std::size_t i = 0; i < fields.size(); ++i) {
        const std::string name(trim(fields[i]));
        if (seen.count(name))
          throw InputError(at_line(file, lineno) + "column '" + name + "' appears twice");
        seen[name] = static_cast<int>(i);
        const CsvColumn* found = nullptr;
        for (const auto& c : csv_columns())
          if (name == c.name) found = &c;
        setters.push_back(found);
      }
      auto has = [&](std::initializer_list<const char*> names) {
        for (const char* n : names)
          if (!seen.count(n)) return false;
        return true;
      };
      if (!has({"t_s"}))
        throw InputError(at_line(file, lineno) +
                         "no 't_s' column in the header (is this a wheelins CSV trajectory?)");
      out.has_lla = has({"lat_deg", "lon_deg", "h_m"});
      out.has_ned = has({"north_m", "east_m", "down_m"});
      if (!out.has_lla && !out.has_ned)
        throw InputError(at_line(file, lineno) +
                         "the header has neither lat_deg,lon_deg,h_m nor north_m,east_m,down_m");
      out.has_velocity = has({"vn_m_s", "ve_m_s", "vd_m_s"});
      out.has_roll_pitch = has({"roll_deg", "pitch_deg"});
      out.has_heading = has({"heading_deg"});
      out.has_pos_std = has({"north_std_m", "east_std_m"});
      continue;
    }
    if (fields.size() != setters.size())
      throw InputError(at_line(file, lineno) + std::to_string(fields.size()) +
                       " fields, the header has " + std::to_string(setters.size()));
    TrajectoryRecord rec;
    for (std::size_t i = 0; i < fields.size(); ++i) {
      if (!setters[i]) continue;
      double v;
      if (!parse_double(fields[i], v))
        throw InputError(at_line(file, lineno) + "column '" + setters[i]->name +
                         "': not a number: '" + std::string(trim(fields[i])) + "'");
      setters[i]->set(rec, v);
    }
    check_record(file, lineno, rec, out.records.empty() ? nullptr : &out.records.back(),
                 out.has_lla, out.has_ned);
    out.records.push_back(rec);
  }
  if (!have_header) throw InputError(quote(file) + ": empty trajectory file (no header)");
  if (out.records.empty()) throw InputError(quote(file) + ": no trajectory records");
  return out;
}

// Reads whitespace-separated numeric rows of exactly `ncols` values.
template <typename Fn>
void read_numeric_rows(const std::filesystem::path& file, std::size_t ncols, const char* layout,
                       Fn&& fn) {
  std::ifstream in = open_text(file);
  std::string line;
  std::size_t lineno = 0;
  std::vector<std::string_view> fields;
  double vals[16];
  while (io_detail::bounded_getline(in, line, io_detail::kMaxTextLine, quote(file))) {
    ++lineno;
    if (is_comment_or_blank(line)) continue;
    split(line, ' ', fields);
    if (fields.size() != ncols)
      throw InputError(at_line(file, lineno) + std::to_string(fields.size()) +
                       " values, expected " + std::to_string(ncols) + " (" + layout + ")");
    for (std::size_t i = 0; i < ncols; ++i)
      if (!parse_double(fields[i], vals[i]))
        throw InputError(at_line(file, lineno) + "value " + std::to_string(i + 1) +
                         " is not a number: '" + std::string(fields[i]) + "'");
    fn(lineno, vals);
  }
}

TrajectoryData read_tum(const std::filesystem::path& file, const TrajectoryReadOptions& opt) {
  TrajectoryData out;
  out.file = file;
  out.format = TrajectoryFormat::kTum;
  out.has_ned = out.has_roll_pitch = out.has_heading = true;
  const TumHeader header = read_tum_header(file);
  if (header.frame && opt.tum_frame && *header.frame != *opt.tum_frame)
    throw InputError(at_line(file, header.frame_line) + "the file says its frame is " +
                     tum_frame_name(*header.frame) + ", but " + tum_frame_name(*opt.tum_frame) +
                     " was given; leave the frame out or give " + tum_frame_name(*header.frame));
  out.tum_frame = opt.tum_frame ? *opt.tum_frame : header.frame ? *header.frame : TumFrame::kNed;
  out.frame_assumed = !opt.tum_frame && !header.frame;
  out.origin = header.origin;
  read_numeric_rows(file, 8, "TUM: t x y z qx qy qz qw", [&](std::size_t lineno, const double* v) {
    TrajectoryRecord rec;
    rec.t = v[0];
    Quat q(v[7], v[4], v[5], v[6]);
    const double n = q.norm();
    if (!std::isfinite(n) || std::abs(n - 1.0) > 1e-3)
      throw InputError(at_line(file, lineno) + "quaternion norm " + num(n) +
                       " is not 1 (expected qx qy qz qw of a unit quaternion)");
    Mat3 C_vn;
    tum_pose_to_ned(out.tum_frame, Vec3(v[1], v[2], v[3]), q.normalized().toRotationMatrix(), rec.p_inN, C_vn);
    rec.rpy = euler_from_dcm(C_vn);
    check_record(file, lineno, rec, out.records.empty() ? nullptr : &out.records.back(), false,
                 true);
    out.records.push_back(rec);
  });
  if (out.records.empty()) throw InputError(quote(file) + ": no trajectory records");
  return out;
}

TrajectoryData read_wheelins_traj(const std::filesystem::path& file) {
  TrajectoryData out;
  out.file = file;
  out.format = TrajectoryFormat::kWheelInsTraj;
  out.has_ned = out.has_velocity = out.has_heading = true;
  read_numeric_rows(
      file, 10, "Wheel-INS traj.txt: t, pos x y z, vel x y z, roll pitch yaw [deg]",
      [&](std::size_t lineno, const double* v) {
        TrajectoryRecord rec;
        rec.t = v[0];
        rec.p_inN = Vec3(v[1], v[2], v[3]);
        rec.v_inN = Vec3(v[4], v[5], v[6]);
        if (!std::isfinite(v[9]))
          throw InputError(at_line(file, lineno) + "yaw is not finite");
        // The Wheel-IMU's yaw is the vehicle heading + 90 deg.
        rec.rpy = Vec3(0.0, 0.0, wrap_pi(v[9] * kDeg - kPi / 2));
        check_record(file, lineno, rec, out.records.empty() ? nullptr : &out.records.back(),
                     false, true);
        out.records.push_back(rec);
      });
  if (out.records.empty()) throw InputError(quote(file) + ": no trajectory records");
  return out;
}

std::string lower_ext(const std::filesystem::path& file) {
  std::string e = file.extension().string();
  for (auto& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

}  // namespace

TumFrame tum_frame_from_name(const std::string& name) {
  if (name == "enu" || name == "ENU") return TumFrame::kEnu;
  if (name == "ned" || name == "NED") return TumFrame::kNed;
  throw InputError("unknown TUM frame '" + name + "' (expected enu or ned)");
}

const char* tum_frame_name(TumFrame frame) { return frame == TumFrame::kNed ? "ned" : "enu"; }


void tum_pose_to_ned(TumFrame frame, const Vec3& xyz, const Mat3& C, Vec3& p_ned, Mat3& C_vn) {
  if (frame == TumFrame::kNed) {
    p_ned = xyz;
    C_vn = C;
    return;
  }
  const Mat3 S = enu_ned_swap();
  p_ned = S * xyz;
  C_vn = S * C * frd_flu_swap();
}

void tum_pose_from_ned(TumFrame frame, const Vec3& p_ned, const Mat3& C_vn, Vec3& xyz, Mat3& C) {
  // Both maps are their own inverses, so going back is the same product.
  tum_pose_to_ned(frame, p_ned, C_vn, xyz, C);
}

TumHeader read_tum_header(const std::filesystem::path& file) {
  TumHeader h;
  std::ifstream in = open_text(file);
  std::string line;
  std::size_t lineno = 0;
  while (io_detail::bounded_getline(in, line, io_detail::kMaxTextLine, quote(file))) {
    ++lineno;
    std::string_view l = trim(line);
    if (l.empty()) continue;
    if (l.front() != '#') break;  // the first record: the header is over
    l = trim(l.substr(1));
    const auto key = [&](std::string_view k) {
      if (l.substr(0, k.size()) != k) return false;
      l = trim(l.substr(k.size()));
      return true;
    };
    if (lineno == 1 && l.substr(0, 20) == "t x(north) y(east) z") {
      h.frame = TumFrame::kNed;
      h.frame_line = lineno;
    } else if (key("frame:")) {
      const std::string_view name = l.substr(0, l.find_first_of(" \t("));
      if (name != "ned" && name != "enu")
        throw InputError(at_line(file, lineno) + "frame '" + std::string(name) + "': expected ned or enu");
      h.frame = name == "ned" ? TumFrame::kNed : TumFrame::kEnu;
      h.frame_line = lineno;
    } else if (key("origin:")) {
      std::vector<std::string_view> f;
      split(l.substr(0, l.find('(')), ' ', f);
      double v[3];
      if (f.size() != 3 || !parse_double(f[0], v[0]) || !parse_double(f[1], v[1]) || !parse_double(f[2], v[2]) ||
          !(std::abs(v[0]) <= 90.0) || !(std::abs(v[1]) <= 180.0) || !std::isfinite(v[2]))
        throw InputError(at_line(file, lineno) + "origin: expected LAT_DEG LON_DEG H_M within range");
      h.origin = earth::Geodetic{v[0] * kDeg, v[1] * kDeg, v[2]};
    }
  }
  return h;
}

std::vector<std::string> trajectory_csv_header() {
  std::vector<std::string> names;
  for (const auto& c : csv_columns()) names.emplace_back(c.name);
  return names;
}

void trajectory_csv_values(const TrajectoryRecord& r, double* out) {
  for (const auto& c : csv_columns()) *out++ = c.get(r);
}

TrajectoryFormat trajectory_format_from_name(const std::string& name) {
  if (name == "auto") return TrajectoryFormat::kAuto;
  if (name == "csv") return TrajectoryFormat::kCsv;
  if (name == "tum") return TrajectoryFormat::kTum;
  if (name == "kml") return TrajectoryFormat::kKml;
  if (name == "wheelins-traj" || name == "wheel-ins") return TrajectoryFormat::kWheelInsTraj;
  throw InputError("unknown trajectory format '" + name +
                   "' (expected auto, csv, tum, kml or wheelins-traj)");
}

const char* trajectory_format_name(TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kAuto: return "auto";
    case TrajectoryFormat::kCsv: return "csv";
    case TrajectoryFormat::kTum: return "tum";
    case TrajectoryFormat::kKml: return "kml";
    case TrajectoryFormat::kWheelInsTraj: return "wheelins-traj";
  }
  return "?";
}

std::unique_ptr<TrajectoryWriter> make_trajectory_writer(TrajectoryFormat format,
                                                         const std::filesystem::path& file,
                                                         const TrajectoryWriterOptions& options) {
  switch (format) {
    case TrajectoryFormat::kCsv: return std::make_unique<CsvWriter>(file, options.overwrite);
    case TrajectoryFormat::kTum: return std::make_unique<TumWriter>(file, options);
    case TrajectoryFormat::kKml: return std::make_unique<KmlWriter>(file, options);
    default:
      throw InputError(quote(file) + ": cannot write trajectory format '" +
                       trajectory_format_name(format) + "' (writable: csv, tum, kml)");
  }
}

TrajectoryFormat detect_trajectory_format(const std::filesystem::path& file) {
  const std::string ext = lower_ext(file);
  if (ext == ".kml")
    throw InputError(quote(file) + ": KML trajectories are written for viewing only; evaluate "
                     "the CSV or TUM file instead");
  if (ext == ".csv") return TrajectoryFormat::kCsv;
  std::ifstream in = open_text(file);
  std::string line;
  std::size_t lineno = 0;
  while (io_detail::bounded_getline(in, line, io_detail::kMaxTextLine, quote(file))) {
    ++lineno;
    if (is_comment_or_blank(line)) continue;
    const bool letters = std::any_of(line.begin(), line.end(), [](char c) {
      return std::isalpha(static_cast<unsigned char>(c)) && c != 'e' && c != 'E';
    });
    if (letters && line.find(',') != std::string::npos) return TrajectoryFormat::kCsv;
    std::vector<std::string_view> fields;
    split(line, ' ', fields);
    if (fields.size() == 8) return TrajectoryFormat::kTum;
    if (fields.size() == 10) return TrajectoryFormat::kWheelInsTraj;
    throw InputError(at_line(file, lineno) + "cannot tell the trajectory format: " +
                     std::to_string(fields.size()) +
                     " whitespace-separated values (TUM has 8, Wheel-INS traj.txt 10) and no CSV "
                     "header; give the format explicitly");
  }
  throw InputError(quote(file) + ": empty trajectory file");
}

TrajectoryData read_trajectory(const std::filesystem::path& file, TrajectoryFormat format,
                               const TrajectoryReadOptions& options) {
  if (format == TrajectoryFormat::kAuto) format = detect_trajectory_format(file);
  if (options.tum_frame && format != TrajectoryFormat::kTum)
    throw InputError(quote(file) + ": a frame (" + tum_frame_name(*options.tum_frame) + ") is for a TUM trajectory; this is " +
                     trajectory_format_name(format) + " (its positions are lat/lon/h or its own format's)");
  switch (format) {
    case TrajectoryFormat::kCsv: return read_csv(file);
    case TrajectoryFormat::kTum: return read_tum(file, options);
    case TrajectoryFormat::kWheelInsTraj: return read_wheelins_traj(file);
    default:
      throw InputError(quote(file) + ": cannot read trajectory format '" +
                       trajectory_format_name(format) + "' (readable: csv, tum, wheelins-traj)");
  }
}

}  // namespace wheelins
