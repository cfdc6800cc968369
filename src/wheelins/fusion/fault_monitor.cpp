// The fault bookkeeping of fault_monitor.hpp: options and their checks, the health
// state machine, the detector window, and the fault report (CSV and text).
#include "wheelins/fusion/fault_monitor.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "wheelins/nav/types.hpp"

namespace wheelins {

void FaultOptions::validate() const {
  auto positive = [](double v, const char* key) {
    if (!(v > 0.0) || !std::isfinite(v))
      throw InputError(std::string("faults.") + key + ": must be > 0, got " + std::to_string(v));
  };
  positive(stale_after, "stale_after_s");
  positive(max_gap, "max_gap_s");
  positive(realign_time, "realign_s");
  positive(probation, "probation_s");
  positive(retry_after, "retry_after_s");
  positive(speed_gate, "speed_gate_sigma");
  positive(wheel_mismatch, "wheel_mismatch_m_s");
  positive(test_ratio, "test_ratio");
  positive(saturation_hold, "saturation_hold_s");
  positive(heading_gate, "heading_gate_deg");
  positive(max_outage, "max_outage_s");
  positive(reverse_speed, "reverse_speed_m_s");
  positive(reverse_time, "reverse_time_s");
  if (heading_epochs < 1)
    throw InputError("faults.heading_epochs: must be >= 1, got " + std::to_string(heading_epochs));
  if (!(saturation_margin > 0.0 && saturation_margin <= 1.0))
    throw InputError("faults.saturation_margin: must be in (0, 1], got " +
                     std::to_string(saturation_margin));
  if (window < 1 || window > FaultMonitor::kMaxWindow)
    throw InputError("faults.window: must be 1.." + std::to_string(FaultMonitor::kMaxWindow) +
                     ", got " + std::to_string(window));
  if (max_failed < 1 || max_failed > window)
    throw InputError("faults.max_failed: must be 1..window (" + std::to_string(window) +
                     "), got " + std::to_string(max_failed));
}

const char* to_string(Health h) {
  switch (h) {
    case Health::kOk: return "ok";
    case Health::kOut: return "out";
    case Health::kRealign: return "realigning";
    case Health::kProbation: return "probation";
    case Health::kIsolated: return "isolated";
  }
  return "?";
}

FaultMonitor::FaultMonitor(std::vector<std::string> names, const FaultOptions& options)
    : opt_(options) {
  opt_.validate();
  modules_.resize(names.size());
  for (std::size_t i = 0; i < names.size(); ++i) modules_[i].name = std::move(names[i]);
}

int FaultMonitor::count_ok() const {
  int n = 0;
  for (const auto& m : modules_) n += m.health == Health::kOk;
  return n;
}

void FaultMonitor::note(int i, double t, const std::string& what, const std::string& action) {
  if (events_.size() >= kMaxEvents) {
    ++dropped_;
    return;
  }
  events_.push_back({t, modules_[i].name, what, action});
}

void FaultMonitor::warn(int i, double t, const std::string& what, const std::string& action) {
  note(i, t, what, action);
  warnings_.push_back("module '" + modules_[i].name + "': " + what + ": " + action);
}

void FaultMonitor::transition(int i, Health h, double t, const std::string& what,
                              const std::string& action) {
  Module& m = modules_[i];
  if (m.health == Health::kOk && h != Health::kOk) m.unused_since = t;
  if (m.health != Health::kOk && h == Health::kOk) m.stats.seconds_unused += t - m.unused_since;
  m.since = t;
  if (h == Health::kIsolated) ++m.stats.isolations;
  m.health = h;
  if (!what.empty()) note(i, t, what, action);
}

bool FaultMonitor::velocity_test(int i, double test_ratio) {
  Module& m = modules_[i];
  ++m.stats.velocity_tests;
  const bool fail = test_ratio > opt_.test_ratio;
  if (fail) ++m.stats.velocity_failed;
  if (m.filled == opt_.window) m.failures -= m.failed[m.pos];
  else ++m.filled;
  m.failed[m.pos] = fail;
  m.failures += fail;
  m.pos = (m.pos + 1) % opt_.window;
  return m.failures >= opt_.max_failed;
}

void FaultMonitor::clear_tests(int i) {
  Module& m = modules_[i];
  m.failed.fill(false);
  m.pos = m.filled = m.failures = 0;
}

void FaultMonitor::finish(double t) {
  for (auto& m : modules_)
    if (m.health != Health::kOk) {
      m.stats.seconds_unused += t - m.unused_since;
      m.unused_since = t;
    }
}

namespace {
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}
}  // namespace

std::string fault_report_csv(const FaultMonitor& m) {
  std::ostringstream o;
  o << "# wheelins fault report: every detection and what was done\n"
    << "t_s,module,detected,action\n";
  char t[32];
  for (const FaultEvent& e : m.events()) {
    std::snprintf(t, sizeof t, "%.3f", e.t);
    o << t << ',' << csv_field(e.module) << ',' << csv_field(e.what) << ','
      << csv_field(e.action) << '\n';
  }
  if (m.events_dropped())
    o << "# " << m.events_dropped() << " further events not listed\n";
  o << "# per module: module,gaps,saturated_samples,speed_rejected,velocity_tests,"
       "velocity_failed,velocity_rejected,isolations,restarts,seconds_unused\n";
  for (int i = 0; i < m.size(); ++i) {
    const ModuleFaultStats& s = m.stats(i);
    o << "# " << m.name(i) << ',' << s.gaps << ',' << s.saturated_samples << ','
      << s.speed_rejected << ',' << s.velocity_tests << ',' << s.velocity_failed << ','
      << s.velocity_rejected << ',' << s.isolations << ',' << s.restarts << ','
      << s.seconds_unused << '\n';
  }
  return o.str();
}

std::string fault_report_text(const FaultMonitor& m) {
  std::ostringstream o;
  char buf[256];
  const auto& ev = m.events();
  if (ev.empty()) {
    o << "faults: none detected\n";
  } else {
    o << "faults: " << ev.size() << " event" << (ev.size() == 1 ? "" : "s") << '\n';
    const std::size_t shown = ev.size() <= 20 ? ev.size() : 20;
    for (std::size_t k = 0; k < shown; ++k) {
      // (The texts may be longer than any buffer: only the time and the name are formatted.)
      std::snprintf(buf, sizeof buf, "  t=%.2f %-10s ", ev[k].t, ev[k].module.c_str());
      o << buf << ev[k].what << " -> " << ev[k].action << '\n';
    }
    if (shown < ev.size()) o << "  ... " << ev.size() - shown << " more in faults.csv\n";
  }
  for (int i = 0; i < m.size(); ++i) {
    const ModuleFaultStats& s = m.stats(i);
    if (!s.gaps && !s.saturated_samples && !s.speed_rejected && !s.isolations && !s.restarts &&
        !s.velocity_rejected && !(s.seconds_unused > 0.0))
      continue;
    std::snprintf(buf, sizeof buf,
                  "  %-10s gaps %llu, saturated samples %llu, speeds unused %llu, velocity "
                  "updates rejected %llu, isolated %llu x, restarted %llu x, unused %.1f s\n",
                  m.name(i).c_str(), static_cast<unsigned long long>(s.gaps),
                  static_cast<unsigned long long>(s.saturated_samples),
                  static_cast<unsigned long long>(s.speed_rejected),
                  static_cast<unsigned long long>(s.velocity_rejected),
                  static_cast<unsigned long long>(s.isolations),
                  static_cast<unsigned long long>(s.restarts), s.seconds_unused);
    o << buf;
  }
  return o.str();
}

}  // namespace wheelins
