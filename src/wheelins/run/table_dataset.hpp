// A dataset from the CSV/text tables IMU vendors write (`wheelins import TABLE... --preset`,
// docs/real-data.md): the tables converted (io/table_import.hpp), the modules surveyed
// (survey/dataset.hpp: kinds, axle axes and signs, clocks, sides, steering, the static
// period), an optional reference track converted and its clock fitted against the wheels
// (survey/reference_clock.hpp), and a manifest drafted from all of it (survey/draft.hpp).
// Everything appears together or nothing does: on an error after the tables were written,
// the files this import created are removed again.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "wheelins/io/column_map.hpp"
#include "wheelins/io/diagnostics.hpp"
#include "wheelins/io/manifest_draft.hpp"
#include "wheelins/io/table_import.hpp"
#include "wheelins/survey/reference_clock.hpp"

namespace wheelins {

struct TableDatasetOptions {
  std::vector<std::filesystem::path> inputs;  ///< tables, or directories of *.csv / *.txt tables
  std::filesystem::path out_dir;
  std::string preset;                         ///< column map preset (empty: csv)
  std::string columns;                        ///< a map file or string refining it (empty: none)
  double max_bad_fraction = 0.01;
  std::optional<std::filesystem::path> truth; ///< a reference track (GNSS CSV, TUM, Wheel-INS binary)
  std::string vehicle_type;                   ///< car | robot (empty: car, said so)
  std::optional<std::filesystem::path> vehicle;  ///< a calibrated manifest of the same vehicle
  bool overwrite = false;
  bool progress = false;
  WarningSink warn;
};

struct TableDatasetResult {
  std::vector<ImportedTable> tables;
  std::vector<std::string> skipped;          ///< directory entries that are not tables of the map
  std::optional<survey::ReferenceClockFit> truth_clock;
  std::filesystem::path truth_file;          ///< written (empty: none)
  std::size_t truth_records = 0;
  std::filesystem::path manifest_file;
  ManifestDraft draft;
  survey::DatasetSurvey survey;
};

TableDatasetResult import_table_dataset(const TableDatasetOptions& options);

/// True when `path` looks like vendor tables rather than a ROS recording: a .csv / .txt
/// file, or a directory holding such files and no ROS 2 bag (metadata.yaml, *.db3, *.mcap).
bool looks_like_tables(const std::filesystem::path& path);

}  // namespace wheelins
