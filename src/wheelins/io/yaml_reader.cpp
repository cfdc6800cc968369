#include "wheelins/io/yaml_reader.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
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

YamlReader::YamlReader(const fs::path& file, WarningSink warn, std::string kind,
                       std::string directory_hint)
    : file_(file), warn_(std::move(warn)) {
  std::error_code ec;
  const auto st = fs::status(file_, ec);
  if (ec || !fs::exists(st)) fail("", kind + " file not found");
  if (fs::is_directory(st)) fail("", "is a directory, expected a " + kind + " file" + directory_hint);
  std::ifstream in(file_, std::ios::binary);
  if (!in) fail("", std::string("cannot open: ") + std::strerror(errno));
  std::stringstream buf;
  buf << in.rdbuf();
  try {
    root_ = YAML::Load(buf.str());
  } catch (const YAML::Exception& e) {
    std::string where;
    if (!e.mark.is_null())
      where = "line " + std::to_string(e.mark.line + 1) + ", column " +
              std::to_string(e.mark.column + 1) + ": ";
    fail("", where + "malformed YAML: " + e.msg);
  }
  if (!root_.IsDefined() || root_.IsNull()) fail("", "the " + kind + " is empty");
  require_map(root_, "");
}

void YamlReader::fail(const std::string& key, const std::string& what, const YAML::Node* at) const {
  std::string msg = io_detail::quote(file_) + ": " + (key.empty() ? "" : key + ": ") + what;
  if (at && at->IsDefined() && !at->Mark().is_null())
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
    if (warn_) {
      std::string msg = io_detail::quote(file_) + ": " + join(path, key) + ": unknown key ignored";
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
