// From the run settings' declarations (run_options.hpp): the documentation's table, the listing of
// `wheelins run -v`, and the front ends' named options (the command line's and Python's keywords).
#include "wheelins/run/run_options.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace wheelins {
namespace {

/// A number as the documentation writes it: 10⁻⁴, 10⁶, or as printf's %g with 6 digits.
std::string doc_number(double x) {
  if (x > 0.0 && (x >= 1e4 || x < 1e-3)) {
    const double e = std::round(std::log10(x));
    if (std::fabs(x - std::pow(10.0, e)) <= 1e-9 * x) {
      static const char* const kSuper[] = {"⁰", "¹", "²", "³", "⁴", "⁵", "⁶", "⁷", "⁸", "⁹"};
      std::string s = "10";
      if (e < 0) s += "⁻";
      for (const char d : std::to_string(static_cast<int>(std::fabs(e)))) s += kSuper[d - '0'];
      return s;
    }
  }
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", x);
  return b;
}

/// A table cell's text: a '|' of the text escaped.
std::string cell(const std::string& text) {
  std::string out;
  for (const char ch : text) out += ch == '|' ? std::string("\\|") : std::string(1, ch);
  return out;
}

std::string with_unit(const std::string& text, const char* unit) {
  return *unit ? text + " " + unit : text;
}

std::string interval(const OptionRange& r) {
  return with_unit("[" + doc_number(r.lo) + ", " + doc_number(r.hi) + "]", r.unit);
}

/// What the documentation's table, the listing and the front ends' options say of one setting.
struct OptionRow {
  OptionInfo info;
  std::string range, value;  ///< value: the configuration's (the defaults': the documentation's default)
  std::string unit;          ///< a number's
  bool flag = false, path = false;
};

/// One row per setting of a configuration: its range and value as text.
class OptionRows {
 public:
  explicit OptionRows(const RunConfig& c) : config_(c) {}

  void number(const OptionInfo& i, double& x, const OptionRange& r, OptionScale s = {}, double* = nullptr) {
    row(i, interval(r), doc_number(x * s.div / s.mul)).unit = r.unit;
  }
  void rate(const OptionInfo& i, double& interval_s, const OptionRange& r) {
    row(i, interval(r), doc_number(1.0 / interval_s)).unit = r.unit;
  }
  void whole(const OptionInfo& i, int& n, int lo, int hi) {
    row(i, "whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]", std::to_string(n));
  }
  void vec3(const OptionInfo& i, Vec3& x, const OptionRange& r) {
    row(i, "each " + interval(r), "[" + doc_number(x.x()) + ", " + doc_number(x.y()) + ", " + doc_number(x.z()) + "]")
        .unit = r.unit;
  }
  void flag(const OptionInfo& i, bool& b) { row(i, "true or false", b ? "true" : "false").flag = true; }
  void path(const OptionInfo& i, std::filesystem::path& p, bool, const char* default_text) {
    row(i, "a path", p.empty() ? std::string(default_text) : p.string()).path = true;
  }
  template <class E>
  void choice(const OptionInfo& i, E& e, const OptionChoices<E>& names) {
    std::string list, now;
    for (const auto& [name, value] : names) {
      list += (list.empty() ? "" : ", ") + ("`" + name + "`");
      if (value == e) now = name;
    }
    row(i, list, "`" + now + "`");
  }
  template <class F>
  void custom(const OptionInfo& i, const char* range_text, OptionShow show, F&&) {
    row(i, range_text, show(config_));
  }
  template <class F>
  void section_check(const char*, F&&) {}

  std::vector<OptionRow> rows;

 private:
  OptionRow& row(const OptionInfo& i, const std::string& range, const std::string& value) {
    rows.push_back(OptionRow{i, range, value, "", false, false});
    return rows.back();
  }
  const RunConfig& config_;
};

/// The rows of `c` (the declarations take the fields to set; the copy is only read).
std::vector<OptionRow> option_rows(const RunConfig& c = RunConfig{}) {
  RunConfig copy = c;
  OptionRows rows(copy);
  declare_run_options(rows, copy);
  return std::move(rows.rows);
}

/// Without the documentation's backticks.
std::string plain(const std::string& t) {
  std::string out;
  for (const char ch : t) out += ch == '`' ? std::string() : std::string(1, ch);
  return out;
}

/// The front end's option of a row with a `cli` text ("--names [(off) | (= VALUE)]").
NamedOption named_option(const OptionRow& r) {
  NamedOption o;
  const std::string cli = r.info.cli;
  o.names = cli.substr(0, cli.find(' '));
  o.option = o.names.substr(0, o.names.find(','));
  const std::string mark = cli.size() > o.names.size() ? cli.substr(o.names.size() + 1) : "";
  if (mark == "(off)")
    o.sets = "false";
  else if (mark.rfind("(= ", 0) == 0 && mark.back() == ')')
    o.sets = mark.substr(3, mark.size() - 4);
  else if (!mark.empty() || o.option.rfind("--", 0) != 0)
    throw std::logic_error("run option " + std::string(r.info.key) + ": cli text '" + cli + "' not understood");
  else if (r.flag)
    o.sets = "true";
  std::string name = o.option.substr(2);
  if (o.sets == "false" && name.rfind("no-", 0) == 0) name = name.substr(3);
  for (char& ch : name) ch = ch == '-' ? '_' : ch;
  o.keyword = name;
  o.key = r.info.key;
  o.help = r.info.help;
  if (const auto at = o.help.find(" (relative to this file)"); at != std::string::npos)
    o.help.erase(at, 24);  // on the command line: to the working directory
  o.help[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(o.help[0])));
  if (o.sets.empty())
    o.help += " (" + plain(r.range) + "; default " + plain(r.value) + "; " + o.key + ")";
  else
    o.help += ": " + o.key + " = " + o.sets + " (default " + plain(r.value) + ")";
  o.path = r.path;
  return o;
}

/// Finds one number setting's range (copied: the declarations' ranges are temporaries).
struct RangeFinder {
  std::string key;
  std::optional<OptionRange> range;
  void number(const OptionInfo& i, double&, const OptionRange& r, OptionScale = {}, double* = nullptr) {
    if (key == i.key) range = r;
  }
  void rate(const OptionInfo& i, double&, const OptionRange& r) {
    if (key == i.key) range = r;
  }
  void whole(const OptionInfo&, int&, int, int) {}
  void vec3(const OptionInfo&, Vec3&, const OptionRange&) {}
  void flag(const OptionInfo&, bool&) {}
  void path(const OptionInfo&, std::filesystem::path&, bool, const char*) {}
  template <class E>
  void choice(const OptionInfo&, E&, const OptionChoices<E>&) {}
  template <class F>
  void custom(const OptionInfo&, const char*, OptionShow, F&&) {}
  template <class F>
  void section_check(const char*, F&&) {}
};

}  // namespace

OptionRange run_option_range(const std::string& key) {
  RangeFinder finder;
  finder.key = key;
  RunConfig c;
  declare_run_options(finder, c);
  if (!finder.range) throw std::logic_error("run_option_range: '" + key + "' is not a declared number");
  return *finder.range;
}

std::string run_options_markdown() {
  std::ostringstream out;
  out << "| key | option | range | default | meaning |\n| --- | --- | --- | --- | --- |\n";
  for (const OptionRow& r : option_rows()) {
    const std::string cli = r.info.cli, flag = cli.substr(0, cli.find(' ')), rest = cli.substr(flag.size());
    out << "| `" << r.info.key << "` | " << (cli.empty() ? std::string() : "`" + flag + "`" + rest) << " | "
        << cell(r.range) << " | " << cell(r.value) << " | " << cell(r.info.help) << " |\n";
  }
  return out.str();
}

std::string run_options_listing(const RunConfig& c) {
  const std::vector<OptionRow> now = option_rows(c), defaults = option_rows();
  std::string out = "settings (docs/run-config.md; * where not the default):\n";
  for (std::size_t k = 0; k < now.size(); ++k) {
    const OptionRow& r = now[k];
    std::string line = "  " + std::string(r.info.key);
    line.resize(std::max<std::size_t>(line.size() + 1, 44), ' ');
    line += plain(r.value) + (r.unit.empty() ? "" : " " + r.unit);
    if (r.value != defaults[k].value) line = "* " + line.substr(2) + "   (default " + plain(defaults[k].value) + ")";
    out += line + "\n";
  }
  return out;
}

std::string option_number(double x) { return doc_number(x); }

std::string option_list(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& i : items) out += (out.empty() ? "" : ", ") + i;
  return out;
}

std::optional<std::string> NamedOption::keyword_value(bool given) const {
  if (sets.empty()) throw std::logic_error("keyword_value: " + keyword + " takes a value");
  if (sets == "true") return given ? "true" : "false";
  if (sets == "false") return option.rfind("--no-", 0) == 0 ? (given ? "true" : "false") : (given ? "false" : "true");
  if (given) return sets;
  return std::nullopt;
}

const std::vector<NamedOption>& run_named_options() {
  static const std::vector<NamedOption> options = [] {
    std::vector<NamedOption> v;
    for (const OptionRow& r : option_rows())
      if (*r.info.cli) v.push_back(named_option(r));
    return v;
  }();
  return options;
}

const NamedOption* find_named_option(const std::string& name) {
  for (const NamedOption& o : run_named_options())
    if (o.option == name || o.keyword == name) return &o;
  return nullptr;
}

}  // namespace wheelins
