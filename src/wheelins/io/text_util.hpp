// Number <-> text helpers shared by the I/O module: exact (shortest round-trip)
// formatting of doubles and strict parsing.
#pragma once

#include <cstdint>
#include <filesystem>
#include <istream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace wheelins::io_detail {

/// "'path'" as every I/O message names a file.
std::string quote(const std::filesystem::path& p);

/// `s` as a JSON string literal, quotes included (", \\ and control characters escaped).
std::string json_quote(std::string_view s);

/// Shortest decimal text that parses back to exactly `v` ("0.097", "200", "100000",
/// "0.000001"; scientific only outside [1e-5, 1e16)).
std::string format_double(double v);

/// Parses the whole of `s` (surrounding blanks allowed, a leading '+' allowed) as a
/// double; nullopt if anything else is there. Accepts "nan"/"inf" spellings so that
/// callers can report them as non-finite values rather than as unreadable text.
std::optional<double> parse_double(std::string_view s);
/// The same in long double precision (exact unit conversions in the manifest).
std::optional<long double> parse_long_double(std::string_view s);
/// Shortest text that parses back to exactly `v` as a long double.
std::string format_long_double(long double v);

/// Checks that `file` can be read as an input: it exists (a dangling symbolic link and a
/// loop of links are told apart from a missing file), is not a directory (`expected` names
/// what was wanted, e.g. "a binary data file"), and is a regular file (a FIFO, a device or a
/// socket has no size and may never end: refused). Returns its size in bytes. Every failure
/// is an InputError naming the file.
std::uint64_t check_input_file(const std::filesystem::path& file, const std::string& expected);

/// The longest line a text data file may have (a longer one is not a data file, e.g.
/// /dev/zero or a binary file read as text: refused before it fills the memory).
constexpr std::size_t kMaxTextLine = 1 << 16;
/// The largest YAML file (manifest, run configuration, simulator settings) read [bytes].
constexpr std::uint64_t kMaxYamlBytes = 4u << 20;
/// The deepest nesting of YAML collections accepted.
constexpr int kMaxYamlDepth = 32;
/// The most nodes that aliases (`*name`) of one YAML text may add by repeating what their
/// anchor (`&name`) stands for: a configuration repeats a block a few times; nested
/// aliases ("billion laughs") would make a walk of the tree take hours.
constexpr std::uint64_t kMaxYamlAliasNodes = 100000;
/// Warnings of one kind (unknown keys) printed per file; the rest are counted.
constexpr int kMaxKeyWarnings = 20;

/// std::getline with a bound: false at the end of the stream; a line longer than `max_len`
/// throws InputError "<where>: line longer than N characters: not a text file of this kind".
/// Every text reader reads its lines here, so this is where a UTF-8 byte-order mark (which
/// editors write at the start of a file, and which no error message would show) is dropped:
/// at the start of the stream's first line, the only place one belongs.
bool bounded_getline(std::istream& in, std::string& line, std::size_t max_len,
                     const std::string& where);

/// A temporary name beside `file` for writing it, unique to this process and call
/// (`file.partial-PID-N`): two writers of one file never share (and truncate) a temporary.
std::filesystem::path unique_partial(const std::filesystem::path& file);
/// Removes the temporaries of unique_partial() in `dir` (`NAME.partial-PID-N`) whose writer
/// (PID) is gone, e.g. a killed import: they are wheelins' own, never the user's. With
/// `names`, only those of these file names. Returns the names removed, for the caller to
/// say so.
std::vector<std::string> sweep_stale_partials(const std::filesystem::path& dir,
                                              const std::vector<std::string>& names = {});

/// The fields of a line separated by `sep`; ' ' means runs of blanks (spaces, tabs, CRs),
/// where empty fields do not arise. Views into `line`.
void split_fields(std::string_view line, char sep, std::vector<std::string_view>& out);

/// Levenshtein distance (for "did you mean" suggestions).
std::size_t edit_distance(std::string_view a, std::string_view b);

}  // namespace wheelins::io_detail
