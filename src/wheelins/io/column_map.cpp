// Column maps (column_map.hpp): the one table of keys that the presets, the YAML file,
// the command-line string, validate(), describe() and to_string() all go through.
#include "wheelins/io/column_map.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <functional>
#include <set>
#include <system_error>

#include "wheelins/io/text_util.hpp"
#include "wheelins/io/yaml_reader.hpp"
#include "wheelins/math/rotation.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins {
namespace fs = std::filesystem;
using io_detail::format_double;
using io_detail::quote;

// ----------------------------------------------------------------------------- units

std::optional<TimeUnit> parse_time_unit(std::string_view t) {
  if (t == "s") return TimeUnit::kSecond;
  if (t == "ms") return TimeUnit::kMillisecond;
  if (t == "us" || t == "\xC2\xB5s" || t == "\xCE\xBCs") return TimeUnit::kMicrosecond;
  if (t == "ns") return TimeUnit::kNanosecond;
  return std::nullopt;
}

std::optional<GyroUnit> parse_gyro_unit(std::string_view t) {
  if (t == "rad/s") return GyroUnit::kRadPerSecond;
  if (t == "deg/s" || t == "dps" || t == "\xC2\xB0/s") return GyroUnit::kDegPerSecond;
  return std::nullopt;
}

std::optional<AccelUnit> parse_accel_unit(std::string_view t) {
  if (t == "m/s^2" || t == "m/s2" || t == "m/s\xC2\xB2") return AccelUnit::kMeterPerSecond2;
  if (t == "g") return AccelUnit::kStandardGravity;
  return std::nullopt;
}

const char* to_string(TimeUnit u) {
  switch (u) {
    case TimeUnit::kSecond: return "s";
    case TimeUnit::kMillisecond: return "ms";
    case TimeUnit::kMicrosecond: return "us";
    case TimeUnit::kNanosecond: return "ns";
  }
  return "?";
}
const char* to_string(GyroUnit u) { return u == GyroUnit::kDegPerSecond ? "deg/s" : "rad/s"; }
const char* to_string(AccelUnit u) { return u == AccelUnit::kStandardGravity ? "g" : "m/s^2"; }
const char* to_string(Delimiter d) {
  switch (d) {
    case Delimiter::kAuto: return "auto";
    case Delimiter::kComma: return "comma";
    case Delimiter::kSemicolon: return "semicolon";
    case Delimiter::kTab: return "tab";
    case Delimiter::kBlanks: return "blanks";
  }
  return "?";
}
const char* to_string(HeaderMode h) {
  switch (h) {
    case HeaderMode::kAuto: return "auto";
    case HeaderMode::kYes: return "true";
    case HeaderMode::kNo: return "false";
  }
  return "?";
}

std::string ColumnRef::to_string() const { return name.empty() ? std::to_string(index) : name; }

double ColumnMap::seconds_per_tick() const {
  static constexpr double kFactor[] = {1.0, 1e-3, 1e-6, 1e-9};
  return kFactor[static_cast<int>(time_unit.value_or(TimeUnit::kSecond))] * time_scale;
}
double ColumnMap::gyro_factor() const {
  return gyro_unit.value_or(GyroUnit::kRadPerSecond) == GyroUnit::kDegPerSecond ? kDeg : 1.0;
}
double ColumnMap::accel_factor() const {
  return accel_unit.value_or(AccelUnit::kMeterPerSecond2) == AccelUnit::kStandardGravity
             ? kStandardGravity
             : 1.0;
}
double ColumnMap::gyro_limit() const {
  return (gyro_range_dps > 0.0 ? gyro_range_dps * kRangeMargin : kDefaultGyroLimitDps) * kDeg;
}
double ColumnMap::accel_limit() const {
  return accel_range_m_s2 > 0.0 ? accel_range_m_s2 * kRangeMargin : kDefaultAccelLimit;
}

// ----------------------------------------------------------------------------- the keys

namespace {

using Values = std::vector<std::string>;

/// The ranges of the numeric keys (docs/csv-import.md has the same table).
constexpr double kMinTimeScale = 1e-12, kMaxTimeScale = 1e6;
constexpr double kMinGyroRange = 10.0, kMaxGyroRange = 1e5;    // deg/s
constexpr double kMinAccelRange = 5.0, kMaxAccelRange = 1e5;   // m/s^2
constexpr int kMaxWrapBits = 62;

bool all_digits(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

std::string lower(std::string_view s) {
  std::string o(s);
  std::transform(o.begin(), o.end(), o.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return o;
}

std::string trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return std::string(s);
}

/// "" if `text` is a column (a name, or a 0-based index as digits), else why not.
std::string set_column(ColumnRef& ref, const std::string& text) {
  const std::string t = trim(text);
  if (t.empty()) return "a column needs a name or a 0-based index, got nothing";
  if (all_digits(t)) {
    int v = 0;
    const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    if (r.ec != std::errc() || v > kMaxColumnIndex)
      return "column index " + t + " is beyond the largest accepted, " + std::to_string(kMaxColumnIndex);
    ref = ColumnRef{"", v};
    return "";
  }
  ref = ColumnRef{t, -1};
  return "";
}

std::string set_columns(std::array<ColumnRef, 3>& refs, const Values& v) {
  if (v.size() != 3)
    return "expected 3 columns (x, y, z), got " + std::to_string(v.size());
  std::array<ColumnRef, 3> out;
  for (std::size_t i = 0; i < 3; ++i)
    if (std::string e = set_column(out[i], v[i]); !e.empty()) return e;
  refs = out;
  return "";
}

std::string one_value(const Values& v, std::string& out) {
  if (v.size() != 1) return "expected one value, got " + std::to_string(v.size());
  out = trim(v[0]);
  if (out.empty()) return "expected a value, got nothing";
  return "";
}

/// A number within [lo, hi], or 0 when `zero_ok` (the key's "not stated").
std::string set_number(double& field, const Values& v, double lo, double hi, bool zero_ok,
                       const char* unit) {
  std::string t;
  if (std::string e = one_value(v, t); !e.empty()) return e;
  const auto x = io_detail::parse_double(t);
  if (!x || !std::isfinite(*x)) return "expected a number, got '" + t + "'";
  if (zero_ok && *x == 0.0) {
    field = 0.0;
    return "";
  }
  if (!(*x >= lo && *x <= hi))
    return std::string("must be ") + (zero_ok ? "0 (not stated) or " : "") + "in [" + format_double(lo) +
           ", " + format_double(hi) + "] " + unit + ", got " + t;
  field = *x;
  return "";
}

template <class U>
std::string set_unit(std::optional<U>& field, const Values& v,
                     std::optional<U> (*parse)(std::string_view), const char* accepted) {
  std::string t;
  if (std::string e = one_value(v, t); !e.empty()) return e;
  if (t == "auto") {
    field.reset();
    return "";
  }
  const auto u = parse(t);
  if (!u) return "unknown unit '" + t + "'; expected " + accepted + " or auto (from the file)";
  field = *u;
  return "";
}

std::string wrap_text(std::uint64_t w) {
  if (w == 0) return "0";
  if ((w & (w - 1)) == 0) {
    int bits = 0;
    while ((std::uint64_t{1} << bits) != w) ++bits;
    return "2^" + std::to_string(bits);
  }
  return std::to_string(w);
}

std::string set_wrap(ColumnMap& m, const Values& v) {
  std::string t;
  if (std::string e = one_value(v, t); !e.empty()) return e;
  const std::string why = "expected a counter wrap in ticks: 0 (none), an integer up to 2^" +
                          std::to_string(kMaxWrapBits) + ", or 2^N, got '" + t + "'";
  if (t.size() > 2 && t.compare(0, 2, "2^") == 0) {
    int bits = 0;
    const auto r = std::from_chars(t.data() + 2, t.data() + t.size(), bits);
    if (r.ec != std::errc() || r.ptr != t.data() + t.size() || bits < 1 || bits > kMaxWrapBits) return why;
    m.time_wrap = std::uint64_t{1} << bits;
    return "";
  }
  std::uint64_t w = 0;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), w);
  if (r.ec != std::errc() || r.ptr != t.data() + t.size() || w > (std::uint64_t{1} << kMaxWrapBits))
    return why;
  m.time_wrap = w;
  return "";
}

std::string set_delimiter(ColumnMap& m, const Values& v) {
  if (v.size() == 1 && (v[0] == "\t" || v[0] == " ")) {  // the characters themselves (YAML "\t")
    m.delimiter = v[0] == "\t" ? Delimiter::kTab : Delimiter::kBlanks;
    return "";
  }
  std::string t;
  if (std::string e = one_value(v, t); !e.empty()) return e;
  const std::string l = lower(t);
  if (l == "auto") m.delimiter = Delimiter::kAuto;
  else if (l == "comma" || l == ",") m.delimiter = Delimiter::kComma;
  else if (l == "semicolon" || l == ";") m.delimiter = Delimiter::kSemicolon;
  else if (l == "tab" || l == "\\t") m.delimiter = Delimiter::kTab;
  else if (l == "blanks" || l == "space" || l == "spaces" || l == "whitespace") m.delimiter = Delimiter::kBlanks;
  else return "expected auto, comma, semicolon, tab or blanks, got '" + t + "'";
  return "";
}

std::string set_skip(ColumnMap& m, const Values& v) {
  std::string t;
  if (std::string e = one_value(v, t); !e.empty()) return e;
  if (t == "auto") {
    m.skip_lines = -1;
    return "";
  }
  int n = 0;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), n);
  if (r.ec != std::errc() || r.ptr != t.data() + t.size() || n < 0 || n > kMaxSkipLines)
    return "expected auto (skip a first 'sep=' line) or a number of lines in [0, " +
           std::to_string(kMaxSkipLines) + "], got '" + t + "'";
  m.skip_lines = n;
  return "";
}

std::string set_header(ColumnMap& m, const Values& v) {
  std::string t;
  if (std::string e = one_value(v, t); !e.empty()) return e;
  const std::string l = lower(t);
  if (l == "auto") m.header = HeaderMode::kAuto;
  else if (l == "true" || l == "yes" || l == "on") m.header = HeaderMode::kYes;
  else if (l == "false" || l == "no" || l == "off") m.header = HeaderMode::kNo;
  else return "expected auto, true or false, got '" + t + "'";
  return "";
}

std::string quoted_list(const std::array<ColumnRef, 3>& refs) {
  std::string s;
  for (const auto& r : refs) s += (s.empty() ? "" : ",") + r.to_string();
  return s;
}

/// One key of a column map: its spelling, how it is set from text and printed back.
struct Key {
  const char* name;
  const char* alias;     ///< another spelling (nullptr: none)
  bool list;             ///< takes three columns
  const char* unit_key;  ///< a column key: the key its `:UNIT` suffix sets (command line)
  std::string (*set)(ColumnMap&, const Values&);  ///< "" or why the value is wrong
  std::string (*get)(const ColumnMap&);
};

const Key kKeys[] = {
    {"preset", nullptr, false, nullptr, nullptr, [](const ColumnMap& m) { return m.preset; }},
    {"delimiter", nullptr, false, nullptr, set_delimiter,
     [](const ColumnMap& m) { return std::string(to_string(m.delimiter)); }},
    {"skip_lines", nullptr, false, nullptr, set_skip,
     [](const ColumnMap& m) { return m.skip_lines < 0 ? std::string("auto") : std::to_string(m.skip_lines); }},
    {"header", nullptr, false, nullptr, set_header,
     [](const ColumnMap& m) { return std::string(to_string(m.header)); }},
    {"time", "t", false, "time_unit",
     [](ColumnMap& m, const Values& v) {
       std::string t;
       if (std::string e = one_value(v, t); !e.empty()) return e;
       return set_column(m.time, t);
     },
     [](const ColumnMap& m) { return m.time.to_string(); }},
    {"time_unit", nullptr, false, nullptr,
     [](ColumnMap& m, const Values& v) { return set_unit(m.time_unit, v, parse_time_unit, "s, ms, us or ns"); },
     [](const ColumnMap& m) { return m.time_unit ? std::string(to_string(*m.time_unit)) : "auto"; }},
    {"time_wrap", nullptr, false, nullptr, set_wrap, [](const ColumnMap& m) { return wrap_text(m.time_wrap); }},
    {"time_scale", nullptr, false, nullptr,
     [](ColumnMap& m, const Values& v) {
       return set_number(m.time_scale, v, kMinTimeScale, kMaxTimeScale, false, "(a factor)");
     },
     [](const ColumnMap& m) { return format_double(m.time_scale); }},
    {"gyro", nullptr, true, "gyro_unit", [](ColumnMap& m, const Values& v) { return set_columns(m.gyro, v); },
     [](const ColumnMap& m) { return quoted_list(m.gyro); }},
    {"gyro_unit", nullptr, false, nullptr,
     [](ColumnMap& m, const Values& v) { return set_unit(m.gyro_unit, v, parse_gyro_unit, "rad/s or deg/s"); },
     [](const ColumnMap& m) { return m.gyro_unit ? std::string(to_string(*m.gyro_unit)) : "auto"; }},
    {"gyro_range_dps", nullptr, false, nullptr,
     [](ColumnMap& m, const Values& v) {
       return set_number(m.gyro_range_dps, v, kMinGyroRange, kMaxGyroRange, true, "deg/s");
     },
     [](const ColumnMap& m) { return format_double(m.gyro_range_dps); }},
    {"accel", nullptr, true, "accel_unit", [](ColumnMap& m, const Values& v) { return set_columns(m.accel, v); },
     [](const ColumnMap& m) { return quoted_list(m.accel); }},
    {"accel_unit", nullptr, false, nullptr,
     [](ColumnMap& m, const Values& v) { return set_unit(m.accel_unit, v, parse_accel_unit, "m/s^2 or g"); },
     [](const ColumnMap& m) { return m.accel_unit ? std::string(to_string(*m.accel_unit)) : "auto"; }},
    {"accel_range_m_s2", nullptr, false, nullptr,
     [](ColumnMap& m, const Values& v) {
       return set_number(m.accel_range_m_s2, v, kMinAccelRange, kMaxAccelRange, true, "m/s^2");
     },
     [](const ColumnMap& m) { return format_double(m.accel_range_m_s2); }},
};

const Key* find_key(std::string_view name) {
  for (const auto& k : kKeys)
    if (name == k.name || (k.alias && name == k.alias)) return &k;
  return nullptr;
}

std::vector<std::string> key_names(bool with_aliases) {
  std::vector<std::string> v;
  for (const auto& k : kKeys) {
    v.emplace_back(k.name);
    if (with_aliases && k.alias) v.emplace_back(k.alias);
  }
  return v;
}

/// "; did you mean 'x'?" for the known name closest to `name` ("" if none is close).
std::string closest_hint(std::string_view name, const std::vector<std::string>& known) {
  std::string best;
  std::size_t best_d = 4;
  for (const auto& k : known) {
    const std::size_t d = io_detail::edit_distance(name, k);
    if (d < best_d) best_d = d, best = k;
  }
  return best.empty() ? "" : "; did you mean '" + best + "'?";
}

/// One key as given in a map file or string, with what to name in a message.
struct Item {
  const Key* key;
  Values values;
  YAML::Node node;  ///< YAML only: the value, for the line
};
using Fail = std::function<void(const Item&, const std::string&)>;  ///< throws

/// `base` refined by `items`: a preset item first (it replaces the base; it must be
/// `forced_preset` when that is given), then the others in table order.
ColumnMap apply_items(const std::vector<Item>& items, ColumnMap base, std::string_view forced_preset,
                      const Fail& fail) {
  for (const auto& it : items) {
    if (std::string(it.key->name) != "preset") continue;
    std::string name;
    if (std::string e = one_value(it.values, name); !e.empty()) fail(it, e);
    if (!forced_preset.empty() && name != forced_preset)
      fail(it, "names preset '" + name + "' but --preset " + std::string(forced_preset) +
                   " was given; give one of them");
    try {
      base = column_map_preset(name);
    } catch (const InputError& e) {
      fail(it, e.what());
    }
  }
  for (const auto& k : kKeys)
    for (const auto& it : items)
      if (it.key == &k && k.set)
        if (std::string e = k.set(base, it.values); !e.empty()) fail(it, e);
  return base;
}

}  // namespace

// ----------------------------------------------------------------------------- checks, text

void ColumnMap::validate() const {
  const auto bad = [](const std::string& key, const std::string& what) {
    throw InputError("column map: " + key + ": " + what);
  };
  if (skip_lines < -1 || skip_lines > kMaxSkipLines)
    bad("skip_lines", "must be auto or in [0, " + std::to_string(kMaxSkipLines) + "], got " +
                          std::to_string(skip_lines));
  struct Named {
    std::string key;
    const ColumnRef* ref;
  };
  std::vector<Named> cols{{"time", &time}};
  for (int i = 0; i < 3; ++i) cols.push_back({"gyro[" + std::to_string(i) + "]", &gyro[static_cast<std::size_t>(i)]});
  for (int i = 0; i < 3; ++i) cols.push_back({"accel[" + std::to_string(i) + "]", &accel[static_cast<std::size_t>(i)]});
  for (const auto& c : cols) {
    if (c.ref->empty()) bad(c.key, "no column given (a header name or a 0-based index)");
    if (!c.ref->name.empty() && c.ref->index >= 0)
      bad(c.key, "gives both a name and an index; give one");
    if (c.ref->index > kMaxColumnIndex)
      bad(c.key, "column index " + std::to_string(c.ref->index) + " is beyond " + std::to_string(kMaxColumnIndex));
    if (!c.ref->name.empty() && header == HeaderMode::kNo)
      bad(c.key, "names column '" + c.ref->name + "' but the map says the table has no header line; "
                 "give a 0-based index, or header: true");
  }
  for (std::size_t i = 0; i < cols.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (*cols[i].ref == *cols[j].ref)
        bad(cols[i].key, "column " + cols[i].ref->to_string() + " is already " + cols[j].key +
                             "'s; each quantity needs its own column");
  if (!(time_scale >= kMinTimeScale && time_scale <= kMaxTimeScale))
    bad("time_scale", "must be in [" + format_double(kMinTimeScale) + ", " + format_double(kMaxTimeScale) +
                          "], got " + format_double(time_scale));
  if (time_wrap > (std::uint64_t{1} << kMaxWrapBits))
    bad("time_wrap", "must be at most 2^" + std::to_string(kMaxWrapBits) + " ticks");
  if (!(gyro_range_dps == 0.0 || (gyro_range_dps >= kMinGyroRange && gyro_range_dps <= kMaxGyroRange)))
    bad("gyro_range_dps", "must be 0 (not stated) or in [" + format_double(kMinGyroRange) + ", " +
                              format_double(kMaxGyroRange) + "] deg/s, got " + format_double(gyro_range_dps));
  if (!(accel_range_m_s2 == 0.0 ||
        (accel_range_m_s2 >= kMinAccelRange && accel_range_m_s2 <= kMaxAccelRange)))
    bad("accel_range_m_s2", "must be 0 (not stated) or in [" + format_double(kMinAccelRange) + ", " +
                                format_double(kMaxAccelRange) + "] m/s^2, got " + format_double(accel_range_m_s2));
}

namespace {
std::string ref_text(const ColumnRef& r) {
  return r.name.empty() ? "column " + std::to_string(r.index) : "'" + r.name + "'";
}
}  // namespace

std::string ColumnMap::describe() const {
  std::string s = "column map" + (preset.empty() ? std::string() : " (preset " + preset + ")") + "\n";
  s += "  delimiter   " + std::string(delimiter == Delimiter::kAuto ? "auto (from a 'sep=' line or the first line)"
                                                                    : wheelins::to_string(delimiter)) + "\n";
  s += "  skip_lines  " + (skip_lines < 0 ? std::string("auto (a first 'sep=' line)") : std::to_string(skip_lines)) + "\n";
  s += "  header      " + std::string(header == HeaderMode::kAuto ? "auto (a first line that is not numbers)"
                                      : header == HeaderMode::kYes ? "yes" : "no") + "\n";
  s += "  time        " + ref_text(time) + " [" +
       (time_unit ? std::string(wheelins::to_string(*time_unit)) : "unit from the file, else s") + "]";
  if (time_wrap) s += ", a counter wrapping at " + wrap_text(time_wrap) + " ticks";
  if (time_scale != 1.0) s += ", times " + format_double(time_scale);
  s += "\n  gyro        " + ref_text(gyro[0]) + ", " + ref_text(gyro[1]) + ", " + ref_text(gyro[2]) + " [" +
       (gyro_unit ? std::string(wheelins::to_string(*gyro_unit)) : "unit from the file, else rad/s") + "], range " +
       (gyro_range_dps > 0 ? "+-" + format_double(gyro_range_dps) + " deg/s" : std::string("not stated")) + "\n";
  s += "  accel       " + ref_text(accel[0]) + ", " + ref_text(accel[1]) + ", " + ref_text(accel[2]) + " [" +
       (accel_unit ? std::string(wheelins::to_string(*accel_unit)) : "unit from the file, else m/s^2") + "], range " +
       (accel_range_m_s2 > 0 ? "+-" + format_double(accel_range_m_s2) + " m/s^2 (" +
                                   format_double(std::round(accel_range_m_s2 / kStandardGravity * 100.0) / 100.0) + " g)"
                             : std::string("not stated")) + "\n";
  return s;
}

std::string ColumnMap::to_string() const {
  std::string s;
  for (const auto& k : kKeys) {
    if (std::string(k.name) == "preset" && preset.empty()) continue;
    s += (s.empty() ? "" : ",") + std::string(k.name) + "=" + k.get(*this);
  }
  return s;
}

// ----------------------------------------------------------------------------- presets

std::vector<std::string> column_map_preset_names() { return {"xsens-dot", "csv"}; }

ColumnMap column_map_preset(std::string_view name) {
  if (name == "csv") return ColumnMap{};
  if (name == "xsens-dot") {
    // The Xsens DOT app's CSV export: `sep=,`, a header, `, ` between fields and at the end.
    ColumnMap m;
    m.preset = "xsens-dot";
    m.delimiter = Delimiter::kComma;
    m.skip_lines = -1;
    m.header = HeaderMode::kYes;
    m.time = {"SampleTimeFine", -1};
    m.time_unit = TimeUnit::kMicrosecond;
    m.time_wrap = std::uint64_t{1} << 32;
    m.gyro = {ColumnRef{"Gyr_X", -1}, ColumnRef{"Gyr_Y", -1}, ColumnRef{"Gyr_Z", -1}};
    m.gyro_unit = GyroUnit::kDegPerSecond;
    m.gyro_range_dps = 2000.0;
    m.accel = {ColumnRef{"Acc_X", -1}, ColumnRef{"Acc_Y", -1}, ColumnRef{"Acc_Z", -1}};
    m.accel_unit = AccelUnit::kMeterPerSecond2;
    m.accel_range_m_s2 = 16.0 * kStandardGravity;
    return m;
  }
  std::string list;
  for (const auto& n : column_map_preset_names()) list += (list.empty() ? "" : ", ") + n;
  throw InputError("unknown column map preset '" + std::string(name) + "'; the presets are " + list +
                   closest_hint(name, column_map_preset_names()));
}

// ----------------------------------------------------------------------------- reading

namespace {

std::vector<Item> yaml_items(const YamlReader& r) {
  r.check_keys(r.root(), "", key_names(true));
  std::vector<Item> items;
  std::set<const Key*> seen;
  for (const auto& kv : r.root()) {
    const std::string name = kv.first.Scalar();
    const Key* k = find_key(name);
    if (!k) continue;  // warned about by check_keys
    if (!seen.insert(k).second)
      r.fail(name, std::string("given twice (as '") + k->name + "' and its other spelling)", &kv.first);
    Item it{k, {}, kv.second};
    const YAML::Node& v = kv.second;
    if (v.IsScalar()) {
      it.values.push_back(v.Scalar());
    } else if (v.IsSequence()) {
      for (std::size_t i = 0; i < v.size(); ++i) {
        const YAML::Node e = v[i];
        if (!e.IsScalar())
          r.fail(YamlReader::index_path(name, i), "expected a name or a number, got " + YamlReader::describe(e), &e);
        it.values.push_back(e.Scalar());
      }
    } else {
      r.fail(name, "expected a value or a list, got " + YamlReader::describe(v), &v);
    }
    if (k->list && v.IsScalar())
      r.fail(name, "expected a list of 3 columns [x, y, z], got " + YamlReader::describe(v), &v);
    items.push_back(std::move(it));
  }
  return items;
}

ColumnMap from_yaml(const fs::path& file, const ColumnMap& base, std::string_view forced_preset,
                    const WarningSink& warn) {
  YamlReader r(file, warn, "column map");
  const auto items = yaml_items(r);
  ColumnMap m = apply_items(items, base, forced_preset, [&](const Item& it, const std::string& what) {
    r.fail(it.key->name, what, &it.node);
  });
  try {
    m.validate();
  } catch (const InputError& e) {
    throw InputError(quote(file) + ": " + e.what());
  }
  return m;
}

std::vector<Item> string_items(std::string_view text) {
  const std::string where = "column map '" + std::string(text) + "'";
  std::vector<Item> items;
  std::set<const Key*> seen;
  std::size_t pos = 0;
  const auto known = key_names(true);
  while (pos <= text.size()) {
    std::size_t comma = text.find(',', pos);
    if (comma == std::string_view::npos) comma = text.size();
    const std::string token = trim(text.substr(pos, comma - pos));
    pos = comma + 1;
    if (token.empty()) {
      if (text.find_first_not_of(" \t") == std::string_view::npos) break;  // an empty map
      throw InputError(where + ": an empty item (two commas, or a comma at an end)");
    }
    const std::size_t eq = token.find('=');
    if (eq == std::string::npos) {
      if (items.empty() || !items.back().key->list)
        throw InputError(where + ": '" + token + "' is not key=value (keys: " +
                         [&] { std::string l; for (const auto& k : key_names(false)) l += (l.empty() ? "" : ", ") + k; return l; }() + ")");
      items.back().values.push_back(token);
      continue;
    }
    const std::string name = trim(token.substr(0, eq));
    const Key* k = find_key(name);
    if (!k) throw InputError(where + ": unknown key '" + name + "'" + closest_hint(name, known));
    if (!seen.insert(k).second) throw InputError(where + ": key '" + std::string(k->name) + "' given twice");
    items.push_back(Item{k, {token.substr(eq + 1)}, {}});
  }
  // A column key's `:UNIT` suffix (on its last column) sets its unit key.
  std::vector<Item> units;
  for (auto& it : items) {
    if (!it.key->unit_key || it.values.empty()) continue;
    std::string& last = it.values.back();
    const std::size_t colon = last.rfind(':');
    if (colon == std::string::npos) continue;
    const Key* uk = find_key(it.key->unit_key);
    if (seen.count(uk))
      throw InputError(where + ": " + std::string(it.key->name) + " has a unit suffix and " + uk->name +
                       " is given too; give one of them");
    units.push_back(Item{uk, {last.substr(colon + 1)}, {}});
    last = trim(last.substr(0, colon));
  }
  for (const auto& it : items)
    if (it.key->unit_key)
      for (const auto& v : it.values)
        if (v.find(':') != std::string::npos)
          throw InputError(where + ": " + it.key->name + ": column '" + v + "' has a ':' (a unit goes after the "
                           "last column only); a name with ':' or ',' needs a column map file");
  items.insert(items.end(), units.begin(), units.end());
  return items;
}

ColumnMap from_string(std::string_view text, const ColumnMap& base, std::string_view forced_preset) {
  const std::string where = "column map '" + std::string(text) + "'";
  const auto items = string_items(text);
  ColumnMap m = apply_items(items, base, forced_preset, [&](const Item& it, const std::string& what) {
    throw InputError(where + ": " + it.key->name + ": " + what);
  });
  try {
    m.validate();
  } catch (const InputError& e) {
    throw InputError(where + ": " + e.what());
  }
  return m;
}

bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

ColumnMap load_column_map(const fs::path& file, const ColumnMap& base, const WarningSink& warn) {
  return from_yaml(file, base, "", warn);
}

ColumnMap parse_column_map(std::string_view text, const ColumnMap& base) {
  return from_string(text, base, "");
}

bool is_column_map_file(std::string_view arg) {
  if (ends_with(arg, ".yaml") || ends_with(arg, ".yml")) return true;
  if (arg.find('=') != std::string_view::npos) return false;
  std::error_code ec;
  return !arg.empty() && fs::is_regular_file(fs::path(std::string(arg)), ec);
}

ColumnMap column_map_from_options(std::string_view preset, std::string_view columns, const WarningSink& warn) {
  const ColumnMap base = preset.empty() ? ColumnMap{} : column_map_preset(preset);
  ColumnMap m;
  if (columns.empty()) m = base;
  else if (is_column_map_file(columns)) m = from_yaml(fs::path(std::string(columns)), base, preset, warn);
  else m = from_string(columns, base, preset);
  m.validate();
  return m;
}

}  // namespace wheelins
