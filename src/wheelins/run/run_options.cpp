// The documentation's table of the run settings, from their declarations (run_options.hpp).
#include "wheelins/run/run_options.hpp"

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

/// One table row per setting: key, option, range, default, meaning.
class MarkdownRows {
 public:
  void number(const OptionInfo& i, double& x, const OptionRange& r, OptionScale s = {}, double* = nullptr) {
    row(i, interval(r), doc_number(x * s.div / s.mul));
  }
  void rate(const OptionInfo& i, double& interval_s, const OptionRange& r) {
    row(i, interval(r), doc_number(1.0 / interval_s));
  }
  void whole(const OptionInfo& i, int& n, int lo, int hi) {
    row(i, "whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]", std::to_string(n));
  }
  void vec3(const OptionInfo& i, Vec3& x, const OptionRange& r) {
    row(i, "each " + interval(r),
        "[" + doc_number(x.x()) + ", " + doc_number(x.y()) + ", " + doc_number(x.z()) + "]");
  }
  void flag(const OptionInfo& i, bool& b) { row(i, "true or false", b ? "true" : "false"); }
  void path(const OptionInfo& i, std::filesystem::path&, bool, const char* default_text) {
    row(i, "a path", default_text);
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
  void custom(const OptionInfo& i, const char* range_text, const char* default_text, F&&) {
    row(i, range_text, default_text);
  }
  template <class F>
  void section_check(const char*, F&&) {}

  std::string text() const { return out_.str(); }

 private:
  void row(const OptionInfo& i, const std::string& range, const std::string& dflt) {
    const std::string cli = i.cli, flag = cli.substr(0, cli.find(' ')), rest = cli.substr(flag.size());
    out_ << "| `" << i.key << "` | " << (cli.empty() ? std::string() : "`" + flag + "`" + rest) << " | "
         << cell(range) << " | " << cell(dflt) << " | " << cell(i.help) << " |\n";
  }
  std::ostringstream out_;
};

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
  void custom(const OptionInfo&, const char*, const char*, F&&) {}
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
  MarkdownRows rows;
  RunConfig defaults;
  declare_run_options(rows, defaults);
  return "| key | option | range | default | meaning |\n| --- | --- | --- | --- | --- |\n" + rows.text();
}

}  // namespace wheelins
