// The dataset cache of a study (dataset.hpp): manifest edits by dotted key, and simulated
// datasets generated once under a lock into a temporary directory renamed into place.
#include "wheelins/study/dataset.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdlib>

#include "wheelins/io/file_lock.hpp"
#include "wheelins/io/yaml_reader.hpp"
#include "wheelins/nav/types.hpp"
#include "wheelins/sim/simulator.hpp"
#include "wheelins/study/files.hpp"

namespace wheelins::study {
namespace fs = std::filesystem;

namespace {

bool whole_number(const std::string& s) {
  return !s.empty() && s.size() < 9 &&
         std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); });
}

/// Applies one edit below `node`; counts the places it changed.
void apply_edit(YAML::Node node, const std::vector<std::string>& parts, std::size_t i,
                const YAML::Node& value, int& matched) {
  const std::string& part = parts[i];
  const bool last = i + 1 == parts.size();
  if (node.IsSequence()) {
    for (std::size_t k = 0; k < node.size(); ++k) {
      YAML::Node el = node[k];
      // By position, by name, or by a field's value (kind=wheel).
      const auto eq = part.find('=');
      const std::string field = eq == std::string::npos ? "name" : part.substr(0, eq);
      const std::string want = eq == std::string::npos ? part : part.substr(eq + 1);
      const bool hit =
          part == "*" || (whole_number(part) && std::stoul(part) == k) ||
          (el.IsMap() && el[field] && el[field].IsScalar() && el[field].Scalar() == want);
      if (!hit) continue;
      if (last) {
        if (value.IsNull()) continue;  // removing list elements is not an edit we offer
        node[k] = YAML::Clone(value);
        ++matched;
      } else {
        apply_edit(el, parts, i + 1, value, matched);
      }
    }
    return;
  }
  if (!node.IsMap()) return;
  if (part == "*") {
    std::vector<std::string> keys;
    for (const auto& kv : node) keys.push_back(kv.first.as<std::string>());
    for (const auto& k : keys) {
      std::vector<std::string> p = parts;
      p[i] = k;
      apply_edit(node, p, i, value, matched);
    }
    return;
  }
  if (last) {
    if (value.IsNull()) {
      if (node[part]) {
        node.remove(part);
        ++matched;
      }
    } else {
      node[part] = YAML::Clone(value);
      ++matched;
    }
    return;
  }
  if (!node[part] || node[part].IsNull()) {
    if (value.IsNull()) return;  // nothing to remove below a missing key
    node[part] = YAML::Node(YAML::NodeType::Map);
  }
  apply_edit(node[part], parts, i + 1, value, matched);
}

void absolutize(YAML::Node node, const char* key, const fs::path& base) {
  if (!node.IsMap() || !node[key] || !node[key].IsScalar()) return;
  const fs::path p = node[key].Scalar();
  if (!p.is_absolute()) node[key] = (base / p).lexically_normal().string();
}

}  // namespace

std::string edit_manifest(const std::string& text, const std::string& edits,
                          const fs::path& base_dir, const std::string& where) {
  const YAML::Node root = parse_yaml(text, where, "manifest");
  const YAML::Node list = parse_yaml(edits, where + ": the manifest edits", "list of edits");
  if (!root.IsMap()) throw InputError(where + ": the manifest is not a mapping");
  for (const auto& item : list) {
    for (const auto& kv : item) {
      const std::string key = kv.first.as<std::string>();
      int matched = 0;
      apply_edit(root, split_dotted(key), 0, kv.second, matched);
      if (matched == 0 && !kv.second.IsNull())
        throw InputError(where + ": manifest." + key + " matches nothing in the manifest");
    }
  }
  if (!base_dir.empty()) {
    absolutize(root, "truth", base_dir);
    absolutize(root, "odometer", base_dir);
    if (root["modules"] && root["modules"].IsSequence())
      for (std::size_t k = 0; k < root["modules"].size(); ++k)
        absolutize(root["modules"][k], "file", base_dir);
  }
  YAML::Emitter e;
  e << root;
  return "# edited by a wheelins study (manifest edits of the study file)\n" +
         std::string(e.c_str()) + "\n";
}

namespace {

bool complete(const fs::path& dir, const std::string& canonical) {
  std::string text;
  std::error_code ec;
  return read_file(dir / "settings.txt", text) && text == canonical &&
         fs::exists(dir / "manifest.yaml", ec);
}

fs::path simulated(const DatasetSpec& d, const fs::path& cache, bool& generated) {
  const fs::path dir = cache / d.cache_name;
  if (complete(dir, d.canonical)) return dir;
  std::error_code ec;
  fs::create_directories(cache, ec);
  if (ec)
    throw InputError("'" + cache.string() + "': cannot create the dataset cache: " + ec.message());
  const FileLock lock(cache / (d.cache_name + ".lock"), FileLock::Wait::kUntilFree);
  if (complete(dir, d.canonical)) return dir;  // made by another process while this one waited
  if (fs::exists(dir, ec)) {
    std::string text;
    if (read_file(dir / "settings.txt", text) && text != d.canonical)
      throw InputError("'" + dir.string() +
                       "': holds a dataset of other settings under the same name "
                       "(settings.txt differs): remove it");
    fs::remove_all(dir, ec);  // not ours to trust: no settings.txt or no manifest
  }
  const std::string prefix = ".tmp." + d.cache_name + ".";
  if (lock.locked())
    for (const auto& e : fs::directory_iterator(cache, ec))
      if (e.path().filename().string().rfind(prefix, 0) == 0)
        fs::remove_all(e.path(), ec);  // killed runs'
  const fs::path tmp = cache / (prefix + unique_suffix());
  try {
    const sim::Simulation simulation(*d.sim);
    simulation.write(tmp, false, false);
    write_file_atomic(tmp / "settings.txt", d.canonical, shared_file(tmp / "settings.txt"));
    fs::rename(tmp, dir, ec);
    if (ec) {
      if (!complete(dir, d.canonical))
        throw InputError("'" + dir.string() +
                         "': cannot move the new dataset into place: " + ec.message());
      fs::remove_all(tmp, ec);  // another process (no locks here) was first
      return dir;
    }
  } catch (...) {
    fs::remove_all(tmp, ec);
    throw;
  }
  generated = true;
  return dir;
}

}  // namespace

PreparedDataset prepare_dataset(const DatasetSpec& d, const fs::path& cache) {
  const auto t0 = std::chrono::steady_clock::now();
  PreparedDataset out;
  fs::path base_manifest;
  fs::path edited;
  if (d.sim) {
    const fs::path dir = simulated(d, cache, out.generated);
    base_manifest = dir / "manifest.yaml";
    if (!d.manifest_edits.empty())
      edited = dir / ("manifest-" + hash_text(d.manifest_edits) + ".yaml");
  } else if (d.manifest) {
    base_manifest = *d.manifest;
    if (!d.manifest_edits.empty()) edited = cache / d.cache_name / "manifest.yaml";
  } else {
    throw InputError("a study job without data");
  }
  out.manifest = base_manifest;
  if (!edited.empty()) {
    std::error_code ec;
    if (!fs::exists(edited, ec)) {
      std::string text;
      if (!read_file(base_manifest, text))
        throw InputError("'" + base_manifest.string() + "': manifest not found or unreadable");
      // The same edits give the same text, so writers racing here write identical files.
      const std::string out_text =
          edit_manifest(text, d.manifest_edits, d.sim ? fs::path() : base_manifest.parent_path(),
                        "'" + base_manifest.string() + "'");
      fs::create_directories(edited.parent_path(), ec);
      write_file_atomic(edited, out_text, shared_file(edited));
    }
    out.manifest = edited;
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace wheelins::study
