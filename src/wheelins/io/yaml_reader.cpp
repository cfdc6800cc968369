// The YAML reader of yaml_reader.hpp: typed values with ranges, key checks with the
// closest known key, and errors naming the file, key path and line.
#include "wheelins/io/yaml_reader.hpp"

#include <yaml-cpp/eventhandler.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>

#include "wheelins/io/text_util.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins {
namespace fs = std::filesystem;

std::string YamlReader::join(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}
std::string YamlReader::index_path(const std::string& path, std::size_t i) {
  return path + "[" + std::to_string(i) + "]";
}
std::string YamlReader::describe(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Scalar: return "'" + n.Scalar() + "'";
    case YAML::NodeType::Sequence: return "a list";
    case YAML::NodeType::Map: return "a mapping";
    case YAML::NodeType::Null: return "nothing (empty value)";
    default: return "nothing";
  }
}

namespace {

/// The deepest nesting of flow collections ([ and {) in `text`, outside quotes and comments,
/// and the line where it first passes `limit` (0 if it does not): checked before parsing, so
/// that a file nested thousands deep is refused before the parser recurses into it.
std::size_t flow_depth_violation(const std::string& text, int limit) {
  int depth = 0;
  std::size_t line = 1;
  char quote_char = 0;
  bool comment = false;
  char prev = '\n';
  for (char c : text) {
    if (c == '\n') {
      ++line;
      comment = false;
      if (quote_char == '\'') quote_char = 0;  // a plain scalar's apostrophe, not a quote
    } else if (comment) {
    } else if (quote_char) {
      if (c == quote_char) quote_char = 0;
    } else if (c == '#' && (prev == ' ' || prev == '\t' || prev == '\n')) {
      comment = true;
    } else if ((c == '"' || c == '\'') && (prev == ' ' || prev == '[' || prev == '{' || prev == ',' ||
                                          prev == ':' || prev == '\n' || prev == '-')) {
      quote_char = c;
    } else if (c == '[' || c == '{') {
      if (++depth > limit) return line;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
    prev = c;
  }
  return 0;
}

/// The deepest nesting of block collections (by indentation levels) in `text`, and the line
/// where it first passes `limit` (0 if it does not).
std::size_t block_depth_violation(const std::string& text, int limit) {
  std::vector<std::size_t> levels;
  std::size_t line = 0, pos = 0;
  while (pos < text.size()) {
    ++line;
    std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    std::size_t indent = pos;
    while (indent < end && text[indent] == ' ') ++indent;
    if (indent < end && text[indent] != '#' && text[indent] != '\r') {
      const std::size_t col = indent - pos;
      while (!levels.empty() && levels.back() > col) levels.pop_back();
      if (levels.empty() || levels.back() < col) levels.push_back(col);
      if (levels.size() > static_cast<std::size_t>(limit)) return line;
    }
    pos = end + 1;
  }
  return 0;
}

/// The nesting depth of a parsed tree, stopping once past `limit`.
int tree_depth(const YAML::Node& n, int limit, int depth = 1) {
  if (depth > limit || !(n.IsMap() || n.IsSequence())) return depth;
  int deepest = depth;
  for (const auto& kv : n) {
    const YAML::Node child = n.IsMap() ? kv.second : YAML::Node(kv);
    deepest = std::max(deepest, tree_depth(child, limit, depth + 1));
    if (deepest > limit) break;
  }
  return deepest;
}

/// Follows the parser's events and counts the nodes the tree has once every alias stands
/// for its anchor's node, before the tree is built: yaml-cpp shares an aliased node instead
/// of copying it, so nested aliases cost nothing to parse but a walk of the tree (every
/// reader's) visits each repetition. Throws InputError at the alias that passes
/// kMaxYamlAliasNodes, or that refers to a node it is inside (a cycle).
class AliasBudget : public YAML::EventHandler {
 public:
  AliasBudget(std::string where, std::string kind) : where_(std::move(where)), kind_(std::move(kind)) {}

  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t anchor) override { leaf(anchor); }
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t anchor, const std::string&) override {
    leaf(anchor);
  }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t anchor) override {
    const std::string at = "line " + std::to_string(mark.line + 1) + ": ";
    if (anchor >= size_.size() || open_[anchor])
      throw InputError(where_ + ": " + at + "an alias (*name) inside the node it refers to (a cycle); a " +
                       kind_ + " cannot be infinite");
    added_ += size_[anchor];
    if (added_ > io_detail::kMaxYamlAliasNodes)
      throw InputError(where_ + ": " + at + "aliases (*name) repeat more than " +
                       std::to_string(io_detail::kMaxYamlAliasNodes) + " values (nested aliases?); write the " +
                       kind_ + " out or use fewer aliases");
    add(size_[anchor]);
  }
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value) override {
    open(anchor);
  }
  void OnSequenceEnd() override { close(); }
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t anchor, YAML::EmitterStyle::value) override {
    open(anchor);
  }
  void OnMapEnd() override { close(); }

 private:
  void reserve(YAML::anchor_t anchor) {
    if (anchor >= size_.size()) {
      size_.resize(anchor + 1, 0);
      open_.resize(anchor + 1, false);
    }
  }
  void add(std::uint64_t n) {
    if (!stack_.empty()) stack_.back().second += n;
  }
  void leaf(YAML::anchor_t anchor) {
    reserve(anchor);
    if (anchor) size_[anchor] = 1;
    add(1);
  }
  void open(YAML::anchor_t anchor) {
    reserve(anchor);
    if (anchor) open_[anchor] = true;
    stack_.emplace_back(anchor, 1);
  }
  void close() {
    if (stack_.empty()) return;
    const auto [anchor, n] = stack_.back();
    stack_.pop_back();
    if (anchor) {
      size_[anchor] = n;
      open_[anchor] = false;
    }
    add(n);
  }

  std::string where_, kind_;
  std::vector<std::uint64_t> size_;  ///< nodes under each anchor, aliases expanded
  std::vector<bool> open_;           ///< an anchor whose collection is still being read
  std::vector<std::pair<YAML::anchor_t, std::uint64_t>> stack_;
  std::uint64_t added_ = 0;  ///< nodes the aliases add (each <= the budget, so no overflow)
};

}  // namespace

std::vector<std::string> dotted_key_parts(const std::string& key) {
  std::vector<std::string> parts;
  for (std::size_t from = 0;;) {
    const std::size_t dot = key.find('.', from);
    parts.push_back(key.substr(from, dot == std::string::npos ? std::string::npos : dot - from));
    if (dot == std::string::npos) return parts;
    from = dot + 1;
  }
}

void set_dotted_key(YAML::Node root, const std::string& key, const YAML::Node& value, const std::string& where) {
  const std::vector<std::string> parts = dotted_key_parts(key);
  YAML::Node map = root;
  std::string path;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const std::string& name = parts[k];
    if (name.empty()) throw InputError(where + ": an empty part in the key '" + key + "'");
    path += (path.empty() ? "" : ".") + name;
    if (k + 1 == parts.size()) {
      if (map[name].IsDefined() && !map[name].IsNull()) throw InputError(where + ": " + key + " is set twice");
      map[name] = value;
      return;
    }
    if (!map[name].IsDefined() || map[name].IsNull()) map[name] = YAML::Node(YAML::NodeType::Map);
    if (!map[name].IsMap()) throw InputError(where + ": " + path + " is set as a value and as a section");
    map.reset(map[name]);
  }
}

YAML::Node settings_document(const std::vector<std::string>& settings, const std::string& expected) {
  YAML::Node root(YAML::NodeType::Map);
  for (const std::string& s : settings) {
    const std::string where = "--set '" + s + "'";
    const std::size_t eq = s.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError(where + ": expected KEY=VALUE, " + expected);
    const YAML::Node value = parse_yaml(s.substr(eq + 1), where, "value");
    if (!value.IsDefined() || value.IsNull()) throw InputError(where + ": no value after '='");
    set_dotted_key(root, s.substr(0, eq), value, where);
  }
  return root;
}

YAML::Node parse_yaml(const std::string& text, const std::string& where, const std::string& kind) {
  if (text.size() > io_detail::kMaxYamlBytes)
    throw InputError(where + ": " + std::to_string(text.size()) + " bytes; a " + kind + " has at most " +
                     std::to_string(io_detail::kMaxYamlBytes >> 20) + " MiB (is this the right file?)");
  if (text.find('\0') != std::string::npos)
    throw InputError(where + ": contains NUL bytes: a binary file, not a " + kind + " (YAML text)");
  std::size_t line = flow_depth_violation(text, io_detail::kMaxYamlDepth);
  if (!line) line = block_depth_violation(text, io_detail::kMaxYamlDepth);
  if (line)
    throw InputError(where + ": line " + std::to_string(line) + ": lists or mappings nested deeper than " +
                     std::to_string(io_detail::kMaxYamlDepth) + " levels; a " + kind + " needs a few");
  YAML::Node root;
  try {
    {
      std::istringstream in(text);
      YAML::Parser parser(in);
      AliasBudget budget(where, kind);
      parser.HandleNextDocument(budget);
    }
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    std::string at;
    if (!e.mark.is_null())
      at = "line " + std::to_string(e.mark.line + 1) + ", column " + std::to_string(e.mark.column + 1) + ": ";
    throw InputError(where + ": " + at + "malformed YAML: " + e.msg);
  }
  if (tree_depth(root, io_detail::kMaxYamlDepth) > io_detail::kMaxYamlDepth)
    throw InputError(where + ": lists or mappings nested deeper than " +
                     std::to_string(io_detail::kMaxYamlDepth) + " levels; a " + kind + " needs a few");
  return root;
}

YAML::Node load_yaml_file(const fs::path& file, const std::string& kind,
                          const std::string& directory_hint) {
  const std::string where = io_detail::quote(file);
  std::uint64_t bytes = 0;
  try {
    bytes = io_detail::check_input_file(file, "a " + kind + " file" + directory_hint);
  } catch (const InputError& e) {
    if (std::string(e.what()) == where + ": file not found") throw InputError(where + ": " + kind + " file not found");
    throw;
  }
  if (bytes > io_detail::kMaxYamlBytes)
    throw InputError(where + ": " + std::to_string(bytes) + " bytes; a " + kind +
                     " file has at most " + std::to_string(io_detail::kMaxYamlBytes >> 20) +
                     " MiB (is this the right file?)");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(where + ": cannot open: " + std::strerror(errno));
  std::string text(static_cast<std::size_t>(bytes), '\0');
  in.read(text.data(), static_cast<std::streamsize>(bytes));
  text.resize(static_cast<std::size_t>(in.gcount()));
  return parse_yaml(text, where, kind);
}

YamlReader::YamlReader(const fs::path& file, WarningSink warn, std::string kind,
                       std::string directory_hint)
    : file_(file), where_(io_detail::quote(file)), warn_(std::move(warn)) {
  root_ = load_yaml_file(file_, kind, directory_hint);
  if (!root_.IsDefined() || root_.IsNull()) fail("", "the " + kind + " is empty");
  require_map(root_, "");
}

YamlReader::YamlReader(YAML::Node root, std::string where, WarningSink warn, bool with_lines)
    : where_(std::move(where)), with_lines_(with_lines), warn_(std::move(warn)), root_(std::move(root)) {
  require_map(root_, "");
}

YamlReader::~YamlReader() {
  if (warn_ && key_warnings_ > io_detail::kMaxKeyWarnings)
    warn_(where_ + ": " + std::to_string(key_warnings_ - io_detail::kMaxKeyWarnings) +
          " more unknown keys ignored (not reported one by one)");
}

void YamlReader::fail(const std::string& key, const std::string& what, const YAML::Node* at) const {
  std::string msg = where_ + ": " + (key.empty() ? "" : key + ": ") + what;
  if (with_lines_ && at && at->IsDefined() && !at->Mark().is_null())
    msg += " (line " + std::to_string(at->Mark().line + 1) + ")";
  throw InputError(msg);
}

void YamlReader::require_map(const YAML::Node& n, const std::string& path) const {
  if (!n.IsMap()) fail(path, "expected a mapping (key: value lines), got " + describe(n), &n);
}

void YamlReader::check_keys(const YAML::Node& map, const std::string& path,
                            const std::vector<std::string>& known) const {
  std::set<std::string> seen;
  for (const auto& kv : map) {
    if (!kv.first.IsScalar()) fail(path, "keys must be plain names, got " + describe(kv.first), &kv.first);
    const std::string key = kv.first.Scalar();
    if (!seen.insert(key).second) fail(join(path, key), "duplicate key", &kv.first);
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;
    std::string best;
    std::pair<int, std::size_t> best_score{2, 0};
    for (const auto& k : known) {
      const bool extends = k.size() > key.size() && k.compare(0, key.size(), key) == 0;
      const std::pair<int, std::size_t> score{extends ? 0 : 1, io_detail::edit_distance(key, k)};
      if (score < best_score) best_score = score, best = k;
    }
    if (warn_ && ++key_warnings_ <= io_detail::kMaxKeyWarnings) {
      std::string msg = where_ + ": " + join(path, key) + ": unknown key ignored";
      if (!kv.first.Mark().is_null()) msg += " (line " + std::to_string(kv.first.Mark().line + 1) + ")";
      if (!best.empty()) msg += "; did you mean '" + best + "'?";
      warn_(msg);
    }
  }
}

YAML::Node YamlReader::get(const YAML::Node& map, const std::string& key) {
  const YAML::Node& cmap = map;
  YAML::Node v = cmap[key];
  if (!v.IsDefined() || v.IsNull()) return YAML::Node(YAML::NodeType::Undefined);
  return v;
}

YAML::Node YamlReader::required(const YAML::Node& map, const std::string& path,
                                const std::string& key) const {
  YAML::Node v = get(map, key);
  if (!v.IsDefined()) {
    const YAML::Node& cmap = map;
    if (cmap[key].IsDefined()) fail(join(path, key), "required value is empty", &map);
    fail(path, "missing required key '" + key + "'", &map);
  }
  return v;
}

double YamlReader::number(const YAML::Node& v, const std::string& path) const {
  if (!v.IsScalar()) fail(path, "expected a number, got " + describe(v), &v);
  const auto x = io_detail::parse_double(v.Scalar());
  if (!x) fail(path, "expected a number, got " + describe(v), &v);
  if (!std::isfinite(*x)) fail(path, "expected a finite number, got " + describe(v), &v);
  return *x;
}

std::string YamlReader::text(const YAML::Node& v, const std::string& path) const {
  if (!v.IsScalar()) fail(path, "expected a text value, got " + describe(v), &v);
  if (v.Scalar().empty()) fail(path, "expected a non-empty text value", &v);
  return v.Scalar();
}

bool YamlReader::boolean(const YAML::Node& v, const std::string& path) const {
  if (v.IsScalar()) {
    std::string s = v.Scalar();
    std::transform(s.begin(), s.end(), s.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (s == "true" || s == "yes" || s == "on") return true;
    if (s == "false" || s == "no" || s == "off") return false;
  }
  fail(path, "expected true or false, got " + describe(v), &v);
}

Vec3 YamlReader::vec3(const YAML::Node& v, const std::string& path, double factor) const {
  if (!v.IsSequence() || v.size() != 3)
    fail(path, "expected a list of 3 numbers [x, y, z], got " +
                   (v.IsSequence() ? "a list of " + std::to_string(v.size()) : describe(v)),
         &v);
  Vec3 out;
  for (std::size_t i = 0; i < 3; ++i) out[static_cast<int>(i)] = number(v[i], index_path(path, i)) * factor;
  return out;
}

std::vector<std::string> YamlReader::text_list(const YAML::Node& v, const std::string& path) const {
  std::vector<std::string> out;
  if (v.IsScalar()) {
    out.push_back(text(v, path));
    return out;
  }
  if (!v.IsSequence()) fail(path, "expected a list of names, got " + describe(v), &v);
  for (std::size_t i = 0; i < v.size(); ++i) out.push_back(text(v[i], index_path(path, i)));
  return out;
}

std::vector<double> YamlReader::number_list(const YAML::Node& v, const std::string& path) const {
  if (!v.IsSequence()) fail(path, "expected a list of numbers, got " + describe(v), &v);
  std::vector<double> out;
  for (std::size_t i = 0; i < v.size(); ++i) out.push_back(number(v[i], index_path(path, i)));
  return out;
}

void YamlReader::positive(double x, const std::string& path, const YAML::Node& at) const {
  if (!(x > 0.0)) fail(path, "must be > 0, got " + io_detail::format_double(x), &at);
}

}  // namespace wheelins

namespace wheelins {

void YamlReader::range(double x, double lo, double hi, const std::string& path, const YAML::Node& at,
                       const std::string& unit) const {
  if (!(x >= lo && x <= hi))
    fail(path, "must be in [" + io_detail::format_double(lo) + ", " + io_detail::format_double(hi) +
                   "]" + (unit.empty() ? "" : " " + unit) + ", got " + io_detail::format_double(x),
         &at);
}

double YamlReader::number_in(const YAML::Node& v, const std::string& path, double lo, double hi,
                             const std::string& unit) const {
  const double x = number(v, path);
  range(x, lo, hi, path, v, unit);
  return x;
}

}  // namespace wheelins
