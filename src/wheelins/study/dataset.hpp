// The dataset cache of a study: simulated datasets generated once, in-process (sim::Simulation),
// into CACHE/<name>/ keyed by every setting (DatasetSpec::canonical), and edited manifests.
//
// Safe when several processes (threads, machines over a shared directory) want the same
// dataset at once: one holds CACHE/<name>.lock and generates into a temporary directory
// that is renamed into place when complete (with settings.txt, the canonical text, inside);
// the others wait for the lock and then find it. Without locks on the file system the
// rename alone keeps it right (a second generator's copy is discarded). A process killed
// while generating leaves only its temporary directory, removed by the next generator.
#pragma once

#include <filesystem>
#include <string>

#include "wheelins/study/spec.hpp"

namespace wheelins::study {

struct PreparedDataset {
  std::filesystem::path manifest;  ///< the manifest to navigate (the edited one if edits)
  bool generated = false;          ///< this call simulated it
  double seconds = 0.0;            ///< wall time of this call
};

/// Finds or makes the data of `d` under `cache_dir`. InputError for bad settings (e.g. a
/// missing scenario file) or edits that match nothing.
PreparedDataset prepare_dataset(const DatasetSpec& d, const std::filesystem::path& cache_dir);

/// Applies manifest edits (the YAML list of `DOTTED.KEY: value` of DatasetSpec) to the text
/// of a manifest: `*` matches every element of a list or key of a map, a list element is also
/// matched by its position, its name (modules.left-C1.noise) or a field's value
/// (modules.kind=wheel.noise), and null removes a key. Relative file paths
/// are made absolute against `base_dir` when it is given. Returns the new YAML text.
std::string edit_manifest(const std::string& manifest_text, const std::string& edits,
                          const std::filesystem::path& base_dir, const std::string& where);

}  // namespace wheelins::study
