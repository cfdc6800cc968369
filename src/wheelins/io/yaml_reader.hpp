// Reading YAML configuration with messages a user can act on: every error names
// the file, the key path (e.g. `filter.velocity_std_m_s[1]`) and the line; unknown
// keys are warnings naming the closest known key. Values are converted to SI by
// the caller's factor at the one place they are read.
#pragma once

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "wheelins/io/diagnostics.hpp"
#include "wheelins/math/rotation.hpp"

namespace wheelins {

/// The one way wheelins parses YAML (files, --set values, a study's settings, its records):
/// at most io_detail::kMaxYamlBytes, no NUL bytes, nested at most io_detail::kMaxYamlDepth
/// deep, and aliases (`*name`) that repeat at most io_detail::kMaxYamlAliasNodes values and
/// never the node they are in, so that no walk of the tree runs away. Every failure is an
/// InputError starting with `where` (a quoted file name, an option) and naming the line;
/// `kind` says what the text is ("manifest", "study").
YAML::Node parse_yaml(const std::string& text, const std::string& where, const std::string& kind);

/// "filter.initial_std.heading_deg" -> {filter, initial_std, heading_deg} (empty parts kept).
std::vector<std::string> dotted_key_parts(const std::string& key);

/// Puts `value` at the dotted `key` of the map `root`, making the maps on its way: {a: {b: value}}
/// for "a.b". InputError naming `where` for an empty part in the key, a key set twice, or one set
/// as a value and as a section.
void set_dotted_key(YAML::Node root, const std::string& key, const YAML::Node& value, const std::string& where);

/// `KEY=VALUE` settings (`--set filter.speed_window_s=0.1`: a dotted key, a YAML value read by
/// parse_yaml) as one document: {filter: {speed_window_s: 0.1}, ...}. InputError naming the
/// setting for one without '=' (saying `expected`, e.g. "a key of docs/run-config.md"), without
/// a value, with an empty part in its key, set twice, or set as a value and as a section.
YAML::Node settings_document(const std::vector<std::string>& settings, const std::string& expected);

/// Reads and parses a YAML file with parse_yaml's checks, and first those of every input
/// file (io_detail::check_input_file: a regular file). `kind` names the file in messages.
YAML::Node load_yaml_file(const std::filesystem::path& file, const std::string& kind,
                          const std::string& directory_hint = "");

class YamlReader {
 public:
  /// Parses `file` (InputError if missing, a directory, unreadable, malformed or empty).
  /// `kind` names the file in messages ("manifest", "run configuration"); `directory_hint`
  /// is appended when a directory was given instead.
  YamlReader(const std::filesystem::path& file, WarningSink warn, std::string kind = "YAML",
             std::string directory_hint = "");

  /// Reads a YAML document already parsed (e.g. settings a study file carries); `where` names it
  /// in messages in place of a quoted file name ("'study.yaml': run settings of job 3").
  /// `with_lines`: the messages give the line of a value (false where the lines mean nothing,
  /// as for values given one by one on a command line).
  YamlReader(YAML::Node root, std::string where, WarningSink warn, bool with_lines = true);

  /// Reports how many unknown-key warnings were held back (past io_detail::kMaxKeyWarnings).
  ~YamlReader();
  YamlReader(const YamlReader&) = delete;
  YamlReader& operator=(const YamlReader&) = delete;

  const YAML::Node& root() const { return root_; }
  const std::filesystem::path& file() const { return file_; }

  [[noreturn]] void fail(const std::string& key, const std::string& what,
                         const YAML::Node* at = nullptr) const;
  void require_map(const YAML::Node& n, const std::string& path) const;
  /// Warns about keys not in `known` (naming the closest: a known key that extends the
  /// unknown one, i.e. a forgotten unit suffix, first, then by edit distance) and
  /// rejects duplicates.
  void check_keys(const YAML::Node& map, const std::string& path,
                  const std::vector<std::string>& known) const;
  /// The value at `key`, or an undefined node if absent or empty.
  static YAML::Node get(const YAML::Node& map, const std::string& key);
  YAML::Node required(const YAML::Node& map, const std::string& path, const std::string& key) const;

  double number(const YAML::Node& v, const std::string& path) const;
  std::string text(const YAML::Node& v, const std::string& path) const;
  bool boolean(const YAML::Node& v, const std::string& path) const;
  Vec3 vec3(const YAML::Node& v, const std::string& path, double factor = 1.0) const;
  std::vector<std::string> text_list(const YAML::Node& v, const std::string& path) const;
  std::vector<double> number_list(const YAML::Node& v, const std::string& path) const;
  void positive(double x, const std::string& path, const YAML::Node& at) const;
  /// Fails unless lo <= x <= hi (the key's physical range; `unit` for the message, e.g. "m").
  void range(double x, double lo, double hi, const std::string& path, const YAML::Node& at,
             const std::string& unit) const;
  /// A number read and checked against its range in one step.
  double number_in(const YAML::Node& v, const std::string& path, double lo, double hi,
                   const std::string& unit) const;

  template <class E>
  E choice(const YAML::Node& v, const std::string& path,
           const std::vector<std::pair<std::string, E>>& options) const {
    if (v.IsScalar())
      for (const auto& [name, value] : options)
        if (v.Scalar() == name) return value;
    std::string list;
    for (const auto& o : options) list += (list.empty() ? "" : " or ") + o.first;
    fail(path, "expected " + list + ", got " + describe(v), &v);
  }

  static std::string join(const std::string& path, const std::string& key);
  static std::string index_path(const std::string& path, std::size_t i);
  static std::string describe(const YAML::Node& n);

 private:
  std::filesystem::path file_;
  std::string where_;  ///< the file quoted, or what the document is
  bool with_lines_ = true;
  WarningSink warn_;
  YAML::Node root_;
  mutable int key_warnings_ = 0;  ///< unknown keys seen (check_keys is const)
};

}  // namespace wheelins
