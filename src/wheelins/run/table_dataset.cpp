// Vendor tables into a dataset with a drafted manifest (table_dataset.hpp).
#include "wheelins/run/table_dataset.hpp"

#include <algorithm>
#include <cctype>
#include <set>

#include "wheelins/eval/truth_quality.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/io/truth.hpp"
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

/// The import's options for the tables; its progress bar (in `bar`) starts with the first report.
TableImportOptions import_options(const TableDatasetOptions& o, std::unique_ptr<Progress>& bar) {
  TableImportOptions io;
  io.overwrite = o.overwrite;
  io.max_bad_fraction = o.max_bad_fraction;
  io.warn = o.warn;
  io.progress = [&o, &bar](std::uint64_t done, std::uint64_t total) {
    if (!bar) bar = std::make_unique<Progress>("importing", total, o.progress);
    bar->update(done);
    check_interrupt();
  };
  return io;
}

/// The files an import writes besides the tables.
struct DatasetFiles {
  fs::path manifest, truth;
};

/// The tables' outputs that exist already.
std::set<fs::path> existing_tables(const TableDatasetOptions& o, const std::vector<TableInput>& inputs) {
  std::set<fs::path> existed;
  std::error_code ec;
  for (const auto& in : inputs)
    if (fs::exists(o.out_dir / (in.module + "_imu.bin"), ec)) existed.insert(o.out_dir / (in.module + "_imu.bin"));
  return existed;
}

/// InputError for a manifest (or, with a reference, a truth file) that exists, without --force.
void refuse_overwrite(const TableDatasetOptions& o, const DatasetFiles& files) {
  std::error_code ec;
  for (const fs::path& f : {files.manifest, files.truth})
    if ((f == files.manifest || o.truth) && fs::exists(f, ec) && !o.overwrite)
      throw InputError(quote(f) + ": exists; --force replaces it");
}

/// The reference track, if one is given; InputError for one too short.
std::optional<TruthData> read_reference(const TableDatasetOptions& o) {
  std::optional<TruthData> truth;
  if (o.truth) {
    truth = read_truth(*o.truth);
    if (truth->records.size() < 10) throw InputError(quote(*o.truth) + ": fewer than 10 records: too short a reference");
  }
  return truth;
}

/// How the survey reads each written table, and each module's draft.
struct SurveyInputs {
  std::vector<survey::ModuleInput> mods;
  std::vector<survey::DraftModule> drafts;
};

SurveyInputs survey_inputs(const std::vector<ImportedTable>& tables) {
  SurveyInputs si;
  for (const auto& t : tables) {
    survey::ModuleInput m;
    m.name = t.module;
    m.file = t.output;
    m.read.rate_hz = t.timing.rate_hz() > 0.0 ? t.timing.rate_hz() : 100.0;
    if (t.map.gyro_range_dps > 0.0) m.gyro_limit = t.map.gyro_limit();
    if (t.map.accel_range_m_s2 > 0.0) m.accel_limit = t.map.accel_limit();
    si.mods.push_back(m);
    survey::DraftModule d;
    d.name = t.module;
    d.file = t.output.filename();
    d.rate_hz = std::round(m.read.rate_hz * 1000.0) / 1000.0;
    d.gyro_range = t.map.gyro_range_dps > 0.0 ? t.map.gyro_range_dps * kDeg : 0.0;
    d.accel_range = t.map.accel_range_m_s2;
    d.source = t.source.string();
    si.drafts.push_back(d);
  }
  return si;
}

std::vector<survey::Series> read_all_series(const std::vector<survey::ModuleInput>& mods) {
  std::vector<survey::Series> series;
  for (const auto& m : mods) {
    survey::SeriesOptions so;
    if (m.gyro_limit > 0.0) so.gyro_limit = m.gyro_limit;
    if (m.accel_limit > 0.0) so.accel_limit = m.accel_limit;
    series.push_back(survey::read_series(m.name, m.file, m.read, so));
  }
  return series;
}

/// The draft's vehicle: its type and a calibrated manifest of it, as given.
survey::DraftOptions vehicle_options(const TableDatasetOptions& o) {
  survey::DraftOptions dopt;
  if (!o.vehicle_type.empty()) {
    dopt.vehicle = survey::vehicle_type(o.vehicle_type);
    dopt.vehicle_type_given = true;
  }
  if (o.vehicle) dopt.vehicle_from = load_manifest(*o.vehicle, o.warn);
  return dopt;
}

/// The reference's records with the unit of its clock `c` applied (as read, with a warning,
/// when no clock was found).
std::vector<TruthRecord> clocked_records(const TableDatasetOptions& o, const TruthData& truth,
                                         const survey::ReferenceClockFit& c) {
  std::vector<TruthRecord> recs = truth.records;
  if (c.found)
    for (TruthRecord& x : recs) x.t *= c.scale;
  else if (o.warn)
    o.warn(quote(*o.truth) + ": its clock could not be matched to the wheels' (no speed correlation); "
           "written as read, truth_time_offset_s to be set");
  return recs;
}

/// Writes the reference to `truth_file` and notes it in `r`; returns the manifest's origin.
earth::Geodetic import_reference(const TableDatasetOptions& o, const TruthData& truth,
                                 const std::vector<survey::Series>& series,
                                 const fs::path& truth_file, TableDatasetResult& r) {
  const survey::DatasetSurvey& sv = r.survey;
  // Its clock (time unit and offset) against the wheels', its quality, and its records
  // with the unit applied (the offset goes into the manifest).
  r.truth_clock = survey::fit_reference_clock(truth.records, series, sv);
  const survey::ReferenceClockFit& c = *r.truth_clock;
  const std::vector<TruthRecord> recs = clocked_records(o, truth, c);
  TruthData scaled = truth;
  scaled.records = recs;
  const std::string quality = eval::describe_truth_quality(eval::check_truth_quality(scaled));
  if (!quality.empty()) r.draft.facts.push_back("reference: " + quality);
  write_truth(truth_file, recs, truth.has_attitude ? TruthLayout::kGins11 : TruthLayout::kPos5, o.overwrite);
  r.truth_file = truth_file;
  r.truth_records = recs.size();
  // The origin: the reference where the static period ends (the vehicle stands there).
  const double t0 = (sv.static_period ? sv.static_period->end : series.front().t_first) - (c.found ? c.offset : 0.0);
  const TruthRecord* at = &recs.front();
  for (const TruthRecord& x : recs)
    if (std::abs(x.t - t0) < std::abs(at->t - t0)) at = &x;
  return at->lla;
}

/// Surveys the written tables, imports the reference (if any) and writes the drafted manifest.
void draft_dataset(const TableDatasetOptions& o, const ColumnMap& map, const std::optional<TruthData>& truth,
                   const DatasetFiles& files, TableDatasetResult& r) {
  // Survey the written files.
  const SurveyInputs si = survey_inputs(r.tables);
  const std::vector<survey::Series> series = read_all_series(si.mods);
  r.survey = survey::survey_series(series);

  survey::DraftOptions dopt = vehicle_options(o);
  if (truth) {
    dopt.origin = import_reference(o, *truth, series, files.truth, r);
    dopt.truth_file = files.truth.filename();
    dopt.truth_clock = *r.truth_clock;
  }
  dopt.name = o.out_dir.filename().string();
  dopt.source = std::to_string(r.tables.size()) + " table(s), preset " + map.preset;
  std::vector<std::string> facts = std::move(r.draft.facts);
  r.draft = survey::draft_from_survey(r.survey, si.drafts, dopt);
  r.draft.facts.insert(r.draft.facts.end(), facts.begin(), facts.end());
  save_manifest(r.draft.manifest, files.manifest, r.draft.notes);
  r.manifest_file = files.manifest;
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
  std::unique_ptr<Progress> bar;
  const TableImportOptions io = import_options(o, bar);
  // Files that exist before: kept if a later step fails (only what this import created goes).
  const std::set<fs::path> existed = existing_tables(o, inputs);
  DatasetFiles files;
  files.manifest = o.out_dir / "manifest.yaml";
  files.truth = o.out_dir / "truth.bin";
  refuse_overwrite(o, files);
  // The reference is read (and refused) before anything is written.
  const std::optional<TruthData> truth = read_reference(o);
  std::error_code ec;
  const bool truth_existed = fs::exists(files.truth, ec);
  r.tables = import_tables(inputs, o.out_dir, io);
  if (bar) bar->finish();
  std::vector<fs::path> created;
  for (const auto& t : r.tables)
    if (!existed.count(t.output)) created.push_back(t.output);
  if (truth && !truth_existed) created.push_back(files.truth);
  try {
    draft_dataset(o, map, truth, files, r);
  } catch (...) {
    for (const auto& f : created) fs::remove(f, ec);
    throw;
  }
  return r;
}

}  // namespace wheelins
