// Vendor tables into a dataset with a drafted manifest (table_dataset.hpp).
#include "wheelins/run/table_dataset.hpp"

#include <algorithm>
#include <cctype>
#include <set>

#include "wheelins/io/text_util.hpp"
#include "wheelins/survey/draft.hpp"
#include "wheelins/util/interrupt.hpp"
#include "wheelins/util/progress.hpp"

namespace wheelins {
namespace fs = std::filesystem;
using io_detail::quote;

namespace {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool table_extension(const fs::path& p) {
  const std::string e = lower(p.extension().string());
  return e == ".csv" || e == ".txt";
}

/// The tables of the inputs: files as given, directories' *.csv / *.txt in name order
/// (the truth left out); directory entries the map cannot read are skipped and named.
std::vector<TableInput> collect(const TableDatasetOptions& o, const ColumnMap& map, std::vector<std::string>* skipped) {
  std::vector<TableInput> out;
  std::set<std::string> names;
  std::error_code ec;
  const fs::path truth = o.truth ? fs::weakly_canonical(*o.truth, ec) : fs::path();
  auto add = [&](const fs::path& f) {
    TableInput in{module_name_from_file(f), f, map};
    if (!names.insert(in.module).second)
      throw InputError(quote(f) + ": a second table for module '" + in.module + "' (module names come from the file names)");
    out.push_back(std::move(in));
  };
  for (const fs::path& p : o.inputs) {
    if (fs::is_directory(p, ec)) {
      std::vector<fs::path> files;
      for (const auto& e : fs::directory_iterator(p))
        if (e.is_regular_file() && table_extension(e.path())) files.push_back(e.path());
      std::sort(files.begin(), files.end());
      for (const fs::path& f : files) {
        if (!truth.empty() && fs::weakly_canonical(f, ec) == truth) continue;
        try {
          TableReader probe(f, map);  // reads the header: a table of another kind fails here
          ImuRow row;
          probe.next(row);
          add(f);
        } catch (const InputError& e) {
          skipped->push_back(f.filename().string() + ": " + e.what());
        }
      }
    } else {
      add(p);
    }
  }
  if (out.empty()) throw InputError("no IMU table to import (give .csv/.txt files or a directory of them)");
  return out;
}

}  // namespace

bool looks_like_tables(const fs::path& path) {
  std::error_code ec;
  if (fs::is_regular_file(path, ec)) return table_extension(path);
  if (!fs::is_directory(path, ec)) return false;
  bool tables = false;
  for (const auto& e : fs::directory_iterator(path, ec)) {
    const std::string ext = lower(e.path().extension().string());
    if (ext == ".db3" || ext == ".mcap" || e.path().filename() == "metadata.yaml") return false;
    tables = tables || table_extension(e.path());
  }
  return tables;
}

TableDatasetResult import_table_dataset(const TableDatasetOptions& o) {
  TableDatasetResult r;
  const ColumnMap map = column_map_from_options(o.preset, o.columns, o.warn);
  const std::vector<TableInput> inputs = collect(o, map, &r.skipped);
  TableImportOptions io;
  io.overwrite = o.overwrite;
  io.max_bad_fraction = o.max_bad_fraction;
  io.warn = o.warn;
  std::unique_ptr<Progress> bar;
  io.progress = [&](std::uint64_t done, std::uint64_t total) {
    if (!bar) bar = std::make_unique<Progress>("importing", total, o.progress);
    bar->update(done);
    check_interrupt();
  };
  // Files that exist before: kept if a later step fails (only what this import created goes).
  std::set<fs::path> existed;
  std::error_code ec;
  for (const auto& in : inputs)
    if (fs::exists(o.out_dir / (in.module + "_imu.bin"), ec)) existed.insert(o.out_dir / (in.module + "_imu.bin"));
  const fs::path manifest_file = o.out_dir / "manifest.yaml";
  if (fs::exists(manifest_file, ec) && !o.overwrite)
    throw InputError(quote(manifest_file) + ": exists; --force replaces it");
  r.tables = import_tables(inputs, o.out_dir, io);
  if (bar) bar->finish();
  std::vector<fs::path> created;
  for (const auto& t : r.tables)
    if (!existed.count(t.output)) created.push_back(t.output);
  try {
    // Survey the written files.
    std::vector<survey::ModuleInput> mods;
    std::vector<survey::DraftModule> drafts;
    for (const auto& t : r.tables) {
      survey::ModuleInput m;
      m.name = t.module;
      m.file = t.output;
      m.read.rate_hz = t.timing.rate_hz() > 0.0 ? t.timing.rate_hz() : 100.0;
      if (t.map.gyro_range_dps > 0.0) m.gyro_limit = t.map.gyro_limit();
      if (t.map.accel_range_m_s2 > 0.0) m.accel_limit = t.map.accel_limit();
      mods.push_back(m);
      survey::DraftModule d;
      d.name = t.module;
      d.file = t.output.filename();
      d.rate_hz = std::round(m.read.rate_hz * 1000.0) / 1000.0;
      d.gyro_range = t.map.gyro_range_dps > 0.0 ? t.map.gyro_range_dps * kDeg : 0.0;
      d.accel_range = t.map.accel_range_m_s2;
      d.source = t.source.string();
      drafts.push_back(d);
    }
    std::vector<survey::Series> series;
    for (const auto& m : mods) {
      survey::SeriesOptions so;
      if (m.gyro_limit > 0.0) so.gyro_limit = m.gyro_limit;
      if (m.accel_limit > 0.0) so.accel_limit = m.accel_limit;
      series.push_back(survey::read_series(m.name, m.file, m.read, so));
    }
    r.survey = survey::survey_series(series);
    const survey::DatasetSurvey& sv = r.survey;

    survey::DraftOptions dopt;
    if (!o.vehicle_type.empty()) {
      dopt.vehicle = survey::vehicle_type(o.vehicle_type);
      dopt.vehicle_type_given = true;
    }
    if (o.vehicle) dopt.vehicle_from = load_manifest(*o.vehicle, o.warn);
    dopt.name = o.out_dir.filename().string();
    dopt.source = std::to_string(r.tables.size()) + " table(s), preset " + map.preset;
    r.draft = survey::draft_from_survey(sv, drafts, dopt);
    save_manifest(r.draft.manifest, manifest_file, r.draft.notes);
    r.manifest_file = manifest_file;
  } catch (...) {
    for (const auto& f : created) fs::remove(f, ec);
    throw;
  }
  return r;
}

}  // namespace wheelins
