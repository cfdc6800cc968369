// A small JSON writer for the study's files (job results, the report): pretty-printed,
// keys in the order written, numbers as the shortest text that reads back to the same
// double (NaN and infinities as null), so equal values always give equal bytes.
// Reading goes through yaml-cpp (JSON is YAML).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace wheelins::study {

class JsonWriter {
 public:
  JsonWriter& begin_object(const char* key = nullptr);
  JsonWriter& end_object();
  JsonWriter& begin_array(const char* key = nullptr);
  JsonWriter& end_array();
  JsonWriter& num(const char* key, double v);
  JsonWriter& num(double v) { return num(nullptr, v); }
  JsonWriter& integer(const char* key, std::int64_t v);
  JsonWriter& boolean(const char* key, bool v);
  JsonWriter& str(const char* key, const std::string& v);
  JsonWriter& str(const std::string& v) { return str(nullptr, v); }
  /// Inserts already formatted JSON as the value (re-indented).
  JsonWriter& raw(const char* key, const std::string& json);
  JsonWriter& strings(const char* key, const std::vector<std::string>& v);
  JsonWriter& numbers(const char* key, const std::vector<double>& v);
  /// The text (with a final newline once the outermost value is closed).
  const std::string& text() const { return out_; }

 private:
  void item(const char* key);
  JsonWriter& close(char bracket);
  std::string out_;
  std::vector<bool> first_;  ///< per open container: no item yet
};

/// `s` as a JSON string literal.
std::string json_quote(const std::string& s);

}  // namespace wheelins::study
