// The plain live stream (live_stream.hpp).
#include "wheelins/run/live_stream.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>

#include "wheelins/io/text_util.hpp"
#include "wheelins/io/trajectory.hpp"

namespace wheelins {
using io_detail::format_double;

namespace {
constexpr const char* kFieldNames[8] = {"module", "t", "gx", "gy", "gz", "ax", "ay", "az"};
// The warm-up's kept samples (tens of thousands: ~65 ms of navigation for five IMUs after a
// 20 s warm-up) are navigated this many per arriving sample, so that no arrival waits for all
// of them: a source that reads its inputs on the same thread (the ROS node reads every topic on
// one) would otherwise read one input's backlog first and find the others late.
constexpr std::size_t kCatchUpPerSample = 256;

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r' || s.back() == '\n')) s.remove_suffix(1);
  return s;
}

// The next field: up to a comma, or (in a line without commas) up to white space.
std::string_view next_field(std::string_view& rest, bool commas) {
  rest = trim(rest);
  const std::size_t end = commas ? rest.find(',') : rest.find_first_of(" \t");
  std::string_view f = trim(rest.substr(0, end));
  rest = end == std::string_view::npos ? std::string_view() : rest.substr(end + 1);
  return f;
}

// Heap order: the smallest key on top; ties by module, then by arrival.
bool later(const ReorderWindow::Item& a, const ReorderWindow::Item& b) {
  if (a.key != b.key) return a.key > b.key;
  if (a.module != b.module) return a.module > b.module;
  return a.seq > b.seq;
}

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

bool parse_stream_line(std::string_view line, StreamLine& out) {
  line = trim(line);
  if (line.empty() || line.front() == '#') return false;
  const bool commas = line.find(',') != std::string_view::npos;
  std::string_view rest = line;
  double v[7];
  for (int k = 0; k < 8; ++k) {
    const std::string_view f = next_field(rest, commas);
    if (f.empty())
      throw InputError(std::string("field ") + std::to_string(k + 1) + " (" + kFieldNames[k] +
                       ") is missing: a line is `module, t, gx, gy, gz, ax, ay, az`");
    if (k == 0) {
      out.module = f;
      continue;
    }
    double x = 0.0;
    const auto [p, ec] = std::from_chars(f.data(), f.data() + f.size(), x);
    if (ec != std::errc() || p != f.data() + f.size())
      throw InputError(std::string("field ") + std::to_string(k + 1) + " (" + kFieldNames[k] + ") '" +
                       std::string(f) + "' is not a number");
    if (!std::isfinite(x))
      throw InputError(std::string("field ") + std::to_string(k + 1) + " (" + kFieldNames[k] + ") is " +
                       (std::isnan(x) ? "NaN" : "infinite"));
    v[k - 1] = x;
  }
  if (!trim(rest).empty())
    throw InputError("more than 8 fields ('" + std::string(trim(rest)) +
                     "' after az): a line is `module, t, gx, gy, gz, ax, ay, az`");
  out.row.t = v[0];
  out.row.gyro = Vec3(v[1], v[2], v[3]);
  out.row.accel = Vec3(v[4], v[5], v[6]);
  return true;
}

// ---------------------------------------------------------------------- ReorderWindow

ReorderWindow::ReorderWindow(double window, std::size_t capacity) : window_(window) {
  if (!(window >= 0.0 && window <= 60.0))
    throw InputError("the reorder window must be in [0, 60] s (given " + format_double(window) + ")");
  heap_.reserve(capacity);
}

bool ReorderWindow::offer(double key, int module, std::uint64_t line, const ImuRow& row) {
  if (any_released_ && key < released_) return false;
  heap_.push_back(Item{key, module, seq_++, line, row});
  std::push_heap(heap_.begin(), heap_.end(), later);
  if (!any_ || key > newest_) newest_ = key;
  any_ = true;
  return true;
}

bool ReorderWindow::pop_any(Item& out) {
  if (heap_.empty()) return false;
  std::pop_heap(heap_.begin(), heap_.end(), later);
  out = heap_.back();
  heap_.pop_back();
  released_ = out.key;
  any_released_ = true;
  return true;
}

bool ReorderWindow::pop_due(Item& out) {
  if (heap_.empty() || heap_.front().key > newest_ - window_) return false;
  return pop_any(out);
}

// ---------------------------------------------------------------------- LiveStream

LiveStream::LiveStream(PushSession& session, const LiveStreamOptions& options, std::FILE* out, std::FILE* diag)
    : session_(session), options_(options), out_(out), diag_(diag), window_(options.window) {
  session_.set_catch_up(kCatchUpPerSample);
  if (!(options.publish_interval >= 0.0 && options.publish_interval <= 60.0))
    throw InputError("the publish interval must be in [0, 60] s (given " + format_double(options.publish_interval) +
                     ")");
  const RunRequest& r = session.request();
  for (const auto& name : r.modules) {
    names_.push_back(name);
    offsets_.push_back(imu_read_options(*r.manifest.find(name)).time_offset);
  }
  header_ = trajectory_csv_header();
  values_.assign(header_.size(), 0.0);
  text_.reserve(64 * header_.size());
  stats_.latency.reserve(1u << 16);  // 6.5 h of states at 10 Hz before it grows
  if (options_.csv && !options_.on_state) {
    std::string h;
    for (std::size_t k = 0; k < header_.size(); ++k) h += (k ? "," : "") + header_[k];
    std::fprintf(out_, "%s\n", h.c_str());
    std::fflush(out_);
  }
}

int LiveStream::module_index(std::string_view name) const {
  for (std::size_t i = 0; i < names_.size(); ++i)
    if (names_[i] == name) return static_cast<int>(i);
  // A number names the module by its index.
  int i = -1;
  const auto [p, ec] = std::from_chars(name.data(), name.data() + name.size(), i);
  if (ec == std::errc() && p == name.data() + name.size() && i >= 0 && i < static_cast<int>(names_.size()))
    return i;
  return -1;
}

void LiveStream::report(Kind kind, const std::string& message) {
  if (reported_[kind] >= options_.reports_per_kind) {
    ++stats_.unreported;
    return;
  }
  ++reported_[kind];
  std::fprintf(diag_, "wheelins live: %s%s\n", message.c_str(),
               reported_[kind] == options_.reports_per_kind ? " (further ones of this kind are counted only)" : "");
}

bool LiveStream::line(std::string_view text, double arrival) {
  const std::uint64_t number = ++stats_.lines;
  if (stopped_) return false;
  StreamLine l;
  try {
    if (!parse_stream_line(text, l)) return true;
  } catch (const InputError& e) {
    ++stats_.bad_lines;
    report(kBadLine, where(number) + ": " + e.what());
    return true;
  }
  const int m = module_index(l.module);
  if (m < 0) {
    ++stats_.bad_lines;
    std::string list;
    for (const auto& n : names_) list += (list.empty() ? "" : ", ") + n;
    report(kBadLine, where(number) + ": module '" + std::string(l.module) +
                         "' is not navigated (modules: " + list + ", or their index 0.." +
                         std::to_string(names_.size() - 1) + ")");
    return true;
  }
  return offer(m, l.row, arrival, number);
}

bool LiveStream::sample(int module, const ImuRow& row, double arrival) {
  const std::uint64_t number = ++stats_.lines;
  if (stopped_) return false;
  if (module < 0 || module >= static_cast<int>(names_.size()))
    throw InputError("LiveStream::sample: module index " + std::to_string(module) + " out of range");
  return offer(module, row, arrival, number);
}

bool LiveStream::offer(int m, const ImuRow& row, double arrival, std::uint64_t number) {
  const double key = row.t + offsets_[static_cast<std::size_t>(m)];
  if (!window_.offer(key, m, number, row)) {
    ++stats_.late;
    report(kLate, where(number) + ": module '" + names_[static_cast<std::size_t>(m)] + "' at t = " +
                      format_double(row.t) + " s arrived after the reorder window (" + format_double(window_.window()) +
                      " s) had passed it: dropped");
    return true;
  }
  const std::uint64_t before = stats_.published;
  ReorderWindow::Item item;
  while (!stopped_ && window_.pop_due(item)) stopped_ = !navigate(item);
  if (stats_.published > before) stats_.latency.push_back(now_seconds() - arrival);
  return !stopped_;
}

void LiveStream::refuse(const std::string& what) {
  const std::uint64_t number = ++stats_.lines;
  ++stats_.bad_lines;
  report(kBadLine, where(number) + ": " + what);
}

std::string LiveStream::where(std::uint64_t number) const {
  return options_.source + " " + options_.unit + " " + std::to_string(number);
}

void LiveStream::end() {
  ReorderWindow::Item item;
  while (!stopped_ && window_.pop_any(item)) stopped_ = !navigate(item);
}

// One released sample navigated; a refusal of the input checks is reported and the stream
// goes on (the session is unchanged by a refused sample).
bool LiveStream::navigate(const ReorderWindow::Item& item) {
  bool more = true;
  try {
    more = session_.push(item.module, item.row);
    ++stats_.samples;
  } catch (const RejectedSample& e) {
    ++stats_.rejected;
    report(kRejected, where(item.line) + ": " + e.what() + ": dropped");
    return true;
  }
  // In the warm-up, and while its kept samples are navigated (a slice per sample), no state.
  if (session_.in_warmup() || session_.behind()) {
    if (!said_warmup_)
      std::fprintf(diag_, "wheelins live: calibration warm-up: estimating the installation until t = %s s; "
                          "no state until then\n", format_double(session_.warmup_end()).c_str());
    said_warmup_ = true;
    return more;
  }
  if (!session_.navigator().navigating()) {
    if (!said_waiting_)
      std::fprintf(diag_, "wheelins live: waiting for the static period (the vehicle standing still) to "
                          "align; no state until then\n");
    said_waiting_ = true;
    return more;
  }
  // On a grid of publish_interval from the first state (first + n * interval, not a sum that
  // drifts; 1 us of slack for the stamps' rounding); after a gap, the grid starts again.
  if (!published_any_ || item.key + 1e-6 >= next_publish_) {
    publish();
    if (!published_any_ || item.key >= next_publish_ + options_.publish_interval) {
      grid_start_ = item.key;
      grid_steps_ = 0;
    }
    next_publish_ = grid_start_ + static_cast<double>(++grid_steps_) * options_.publish_interval;
    published_any_ = true;
  }
  return more;
}

// The vehicle's state now, as a JSON object or a CSV row (the trajectory CSV's columns), or
// given to options_.on_state.
void LiveStream::publish() {
  if (options_.on_state) {
    options_.on_state(session_.navigator().vehicle_record());
    ++stats_.published;
    return;
  }
  trajectory_csv_values(session_.navigator().vehicle_record(), values_.data());
  text_.clear();
  char buf[64];
  if (!options_.csv) text_ += '{';
  for (std::size_t k = 0; k < values_.size(); ++k) {
    if (k) text_ += ',';
    if (!options_.csv) {
      text_ += '"';
      text_ += header_[k];
      text_ += "\":";
    }
    const int n = std::isfinite(values_[k]) ? std::snprintf(buf, sizeof buf, "%.12g", values_[k])
                                            : std::snprintf(buf, sizeof buf, options_.csv ? "nan" : "null");
    text_.append(buf, static_cast<std::size_t>(n));
  }
  if (!options_.csv) text_ += '}';
  text_ += '\n';
  std::fwrite(text_.data(), 1, text_.size(), out_);
  std::fflush(out_);
  ++stats_.published;
}

void latency_percentiles(std::vector<double> latency, double& median, double& p99) {
  median = p99 = 0.0;
  if (latency.empty()) return;
  auto at = [&](double q) {
    const std::size_t k = std::min(latency.size() - 1, static_cast<std::size_t>(q * static_cast<double>(latency.size())));
    std::nth_element(latency.begin(), latency.begin() + static_cast<std::ptrdiff_t>(k), latency.end());
    return latency[k];
  };
  median = at(0.5);
  p99 = at(0.99);
}

}  // namespace wheelins
