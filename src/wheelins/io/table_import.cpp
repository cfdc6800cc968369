// The import of vendor tables (table_import.hpp): module names, the output checks, the
// all-or-nothing writing of the `<module>_imu.bin` files, and the text report.
#include "wheelins/io/table_import.hpp"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <set>
#include <system_error>

#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins {
namespace fs = std::filesystem;
using io_detail::quote;

namespace {

constexpr std::size_t kMaxModuleName = 200;

bool module_char(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '.' ||
         c == '-';
}

std::string output_name(const std::string& module) { return module + "_imu.bin"; }

/// A bad name made printable in a message about the files it would name.
std::string name_for_files(const std::string& name) {
  std::string out;
  for (char c : name) out += module_char(c) ? c : '_';
  return out;
}

}  // namespace

void check_module_name(const std::string& name) {
  const std::string q = "module name '" + name + "'";
  if (name.empty()) throw InputError("a module name is empty; it names the file <module>_imu.bin");
  if (name.size() > kMaxModuleName)
    throw InputError(q + ": longer than " + std::to_string(kMaxModuleName) + " characters");
  for (char c : name)
    if (!module_char(c))
      throw InputError(q + ": only letters, digits, '_', '.' and '-' may be used (no path separators, "
                           "commas or blanks); it names files such as " + name_for_files(name) + ".csv and " +
                           output_name(name_for_files(name)));
  if (name.front() == '.') throw InputError(q + ": must not start with '.' (a hidden file)");
  if (name.find("..") != std::string::npos) throw InputError(q + ": must not contain '..'");
}

std::string module_name_from_file(const fs::path& file) {
  const std::string stem = file.stem().string();
  std::string out;
  for (std::size_t i = 0; i < stem.size(); ++i) {
    if (stem[i] != '.') {
      out += module_char(stem[i]) ? stem[i] : '_';
      continue;
    }
    std::size_t j = i;
    while (j < stem.size() && stem[j] == '.') ++j;
    out += j - i > 1 ? '_' : '.';  // ".." is not allowed
    i = j - 1;
  }
  while (!out.empty() && out.front() == '.') out.erase(out.begin());
  if (out.size() > kMaxModuleName) out.resize(kMaxModuleName);
  return out.empty() ? "imu" : out;
}

std::vector<ImportedTable> import_tables(const std::vector<TableInput>& inputs, const fs::path& out_dir,
                                         const TableImportOptions& options) {
  if (inputs.empty()) throw InputError("no tables to import");
  std::set<std::string> modules;
  std::vector<std::string> names;
  for (const auto& in : inputs) {
    check_module_name(in.module);
    if (!modules.insert(in.module).second)
      throw InputError("module name '" + in.module + "' is given to two tables; each module needs its own name");
    names.push_back(output_name(in.module));
  }
  std::error_code ec;
  if (fs::exists(out_dir, ec) && !fs::is_directory(out_dir, ec))
    throw InputError(quote(out_dir) + ": is a file, expected the output directory");
  std::vector<fs::path> outputs;
  std::vector<bool> existed;
  for (const auto& name : names) {
    const fs::path out = out_dir / name;
    const bool exists = fs::exists(fs::symlink_status(out, ec));
    for (const auto& in : inputs)
      if (exists && fs::equivalent(out, in.file, ec))
        throw InputError(quote(out) + ": is an input of this import (" + quote(in.file) +
                         "); refusing to write over it, even with overwrite (choose another output directory)");
    check_output_target(out, options.overwrite);
    outputs.push_back(out);
    existed.push_back(exists);
  }
  const bool created = !fs::exists(out_dir, ec);
  fs::create_directories(out_dir, ec);
  if (ec) throw InputError(quote(out_dir) + ": cannot create: " + ec.message());
  for (const auto& n : io_detail::sweep_stale_partials(out_dir, names))
    if (options.warn) options.warn(quote(out_dir / n) + ": removed, the temporary file of an import that was killed");

  std::uint64_t total = 0, done = 0;
  if (options.progress)
    for (const auto& in : inputs) total += count_text_lines(in.file);

  std::vector<ImportedTable> result;
  std::vector<std::unique_ptr<ImuFileWriter>> writers;
  std::size_t committed = 0;
  try {
    TableReadOptions ro;
    ro.max_bad_fraction = options.max_bad_fraction;
    ro.warn = options.warn;
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      const TableInput& in = inputs[i];
      TableReader reader(in.file, in.map, ro);
      writers.push_back(std::make_unique<ImuFileWriter>(outputs[i], SampleFormat::kRate, FileLayout::kBinary,
                                                        options.overwrite));
      ImuFileWriter& w = *writers.back();
      ImuRow row;
      std::uint64_t n = 0;
      while (reader.next(row)) {
        w.write_row(row);
        if (options.progress && (++n & 4095) == 0) {
          const std::uint64_t now = done + reader.lines_read();
          options.progress(total ? std::min(now, total) : now, total);
        }
      }
      done += reader.lines_read();
      const TableSummary& s = reader.summary();
      ImportedTable t;
      t.module = in.module;
      t.source = in.file;
      t.output = outputs[i];
      t.rows_read = s.rows_read;
      t.rows_kept = s.rows_kept;
      t.faults = s.faults;
      t.timing = s.timing;
      t.map = s.map;
      t.notes = s.notes;
      result.push_back(std::move(t));
    }
    if (options.progress) options.progress(total ? total : done, total);
    // Everything read and valid: the files appear.
    for (auto& w : writers) {
      w->commit();
      ++committed;
    }
  } catch (...) {
    writers.clear();  // removes the temporaries not moved into place
    for (std::size_t i = 0; i < committed; ++i)
      if (!existed[i]) fs::remove(outputs[i], ec);  // a file this import created
    if (created) fs::remove(out_dir, ec);            // only if still empty
    throw;
  }
  return result;
}

std::string table_import_report(const std::vector<ImportedTable>& tables) {
  std::size_t wf = 4, wm = 6;
  for (const auto& t : tables) {
    wf = std::max(wf, t.source.filename().string().size());
    wm = std::max(wm, t.module.size());
  }
  const int fw = static_cast<int>(wf), mw = static_cast<int>(wm);
  std::string s;
  char buf[512];
  std::snprintf(buf, sizeof buf, "%-*s  %-*s  %9s  %9s  %9s  %9s  %9s  %5s  %s\n", fw, "file", mw, "module", "rows",
                "kept", "rate Hz", "jitter ms", "span s", "gaps", "left out");
  s += buf;
  for (const auto& t : tables) {
    std::snprintf(buf, sizeof buf, "%-*s  %-*s  %9llu  %9llu  %9.3f  %9.4f  %9.2f  %5llu  ", fw,
                  t.source.filename().string().c_str(), mw, t.module.c_str(),
                  static_cast<unsigned long long>(t.rows_read), static_cast<unsigned long long>(t.rows_kept),
                  t.timing.rate_hz(), t.timing.jitter() * 1e3, t.timing.span(),
                  static_cast<unsigned long long>(t.timing.gap_count));
    s += buf;
    s += t.faults.summary() + "\n";
  }
  for (const auto& t : tables)
    if (t.faults.total()) {
      s += "(row: the first row left out of each class, 0-based, the header not counted)\n";
      break;
    }
  return s;
}

}  // namespace wheelins
