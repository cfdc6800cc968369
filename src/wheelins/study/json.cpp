// The JSON writer of the study's files (json.hpp): quoting, nesting, shortest round-trip
// numbers.
#include "wheelins/study/json.hpp"

#include <cmath>

#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/text_util.hpp"

namespace wheelins::study {

std::string json_quote(const std::string& s) { return io_detail::json_quote(s); }

void JsonWriter::item(const char* key) {
  if (first_.empty()) return;
  if (!first_.back()) out_ += ",";
  first_.back() = false;
  out_ += "\n";
  out_.append(2 * first_.size(), ' ');
  if (key) out_ += json_quote(key) + ": ";
}

JsonWriter& JsonWriter::begin_object(const char* key) {
  item(key);
  out_ += "{";
  first_.push_back(true);
  return *this;
}

JsonWriter& JsonWriter::close(char bracket) {
  const bool empty = first_.back();
  first_.pop_back();
  if (!empty) {
    out_ += "\n";
    out_.append(2 * first_.size(), ' ');
  }
  out_ += bracket;
  if (first_.empty()) out_ += "\n";
  return *this;
}

JsonWriter& JsonWriter::end_object() { return close('}'); }

JsonWriter& JsonWriter::begin_array(const char* key) {
  item(key);
  out_ += "[";
  first_.push_back(true);
  return *this;
}

JsonWriter& JsonWriter::end_array() { return close(']'); }

JsonWriter& JsonWriter::num(const char* key, double v) {
  item(key);
  if (std::isfinite(v))
    append_double(out_, v);
  else
    out_ += "null";
  return *this;
}

JsonWriter& JsonWriter::integer(const char* key, std::int64_t v) {
  item(key);
  out_ += std::to_string(v);
  return *this;
}

JsonWriter& JsonWriter::boolean(const char* key, bool v) {
  item(key);
  out_ += v ? "true" : "false";
  return *this;
}

JsonWriter& JsonWriter::str(const char* key, const std::string& v) {
  item(key);
  out_ += json_quote(v);
  return *this;
}

JsonWriter& JsonWriter::raw(const char* key, const std::string& json) {
  item(key);
  std::string j = json;
  while (!j.empty() && (j.back() == '\n' || j.back() == ' ')) j.pop_back();
  const std::string pad(2 * first_.size(), ' ');
  for (char c : j) {
    out_ += c;
    if (c == '\n') out_ += pad;
  }
  return *this;
}

JsonWriter& JsonWriter::strings(const char* key, const std::vector<std::string>& v) {
  item(key);
  out_ += "[";
  for (std::size_t i = 0; i < v.size(); ++i) out_ += (i ? ", " : "") + json_quote(v[i]);
  out_ += "]";
  return *this;
}

JsonWriter& JsonWriter::numbers(const char* key, const std::vector<double>& v) {
  item(key);
  out_ += "[";
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i) out_ += ", ";
    if (std::isfinite(v[i]))
      append_double(out_, v[i]);
    else
      out_ += "null";
  }
  out_ += "]";
  return *this;
}

}  // namespace wheelins::study
