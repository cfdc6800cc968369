// Number <-> text helpers shared by the I/O module: exact (shortest round-trip)
// formatting of doubles and strict parsing.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace wheelins::io_detail {

/// "'path'" as every I/O message names a file.
std::string quote(const std::filesystem::path& p);

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

/// Levenshtein distance (for "did you mean" suggestions).
std::size_t edit_distance(std::string_view a, std::string_view b);

}  // namespace wheelins::io_detail
