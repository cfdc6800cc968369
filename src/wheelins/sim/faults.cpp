// Sensor-fault events (faults.hpp): the --fault spec and YAML forms, parsed and written.
#include "wheelins/sim/faults.hpp"

#include "wheelins/io/text_util.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <vector>

#include "wheelins/nav/types.hpp"

namespace wheelins::sim {
namespace {

constexpr FaultKind kKinds[] = {FaultKind::kDropout, FaultKind::kGyroBiasJump, FaultKind::kAccelBiasJump,
                                FaultKind::kStuck, FaultKind::kSlip};
const char* const kAxes = "xyz";

/// Shortest decimal text that reads back as exactly x (so specs and YAML round-trip).
std::string num(double x) { return io_detail::format_double(x); }

/// A strict number: the whole text, finite.
std::optional<double> parse_number(const std::string& s) {
  if (s.empty()) return std::nullopt;
  char* endp = nullptr;
  errno = 0;
  const double v = std::strtod(s.c_str(), &endp);
  if (endp != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v)) return std::nullopt;
  return v;
}

/// The wheel groups (the front ones: preset car-steered; the simulation checks that the
/// vehicle has the target).
bool is_wheel_group(const std::string& t) {
  return t == "left-wheel" || t == "right-wheel" || t == "front-left-wheel" || t == "front-right-wheel";
}
bool is_group(const std::string& t) { return is_wheel_group(t) || t == "body"; }

/// "left-C1".."left-C16", "right-C..", "body-C..", "front-left-C..", "front-right-C.." (the chip
/// count is checked by the simulation).
bool is_chip(const std::string& t) {
  for (const char* g : {"left-C", "right-C", "body-C", "front-left-C", "front-right-C"}) {
    const std::string p = g;
    if (t.rfind(p, 0) != 0) continue;
    const std::string n = t.substr(p.size());
    if (n.empty() || n.size() > 2 || n[0] == '0') return false;
    for (char c : n)
      if (c < '0' || c > '9') return false;
    const int i = std::stoi(n);
    return i >= 1 && i <= 16;
  }
  return false;
}

/// One key of an event as written: its name in the messages (the CLI and YAML spell the
/// times and the bias value differently) and its text.
struct Field {
  std::string label, text;
  bool present = false;
};

/// An event as text, before validation.
struct RawFault {
  Field kind, target, start, end;
  Field axis, sensor, value, ratio;
  std::vector<std::string> unknown;  ///< keys this kind does not know, as written
};

/// Makes the InputError for a key (label) and a message; the caller throws it.
using Fail = std::function<InputError(const std::string& label, const std::string& message)>;

/// Validates a RawFault into an event. Throws what `fail` makes; every message names the key and
/// says what was expected.
FaultEvent build(const RawFault& r, const Fail& fail) {
  FaultEvent e;
  // Kind.
  bool known = false;
  for (FaultKind k : kKinds)
    if (r.kind.text == fault_kind_name(k)) e.kind = k, known = true;
  if (!known)
    throw fail(r.kind.label, "unknown kind '" + r.kind.text +
                           "' (expected dropout, gyro-bias-jump, accel-bias-jump, stuck or slip)");
  // Target.
  e.target = r.target.text;
  if (!is_group(e.target) && !is_chip(e.target))
    throw fail(r.target.label, "unknown target '" + e.target +
                             "' (expected a chip such as left-C1, right-C2, body-C4, or a module group "
                             "left-wheel, right-wheel or body; preset car-steered also front-left-wheel, "
                             "front-right-wheel and their chips front-left-C1, ...)");
  if (e.kind == FaultKind::kSlip && !is_wheel_group(e.target))
    throw fail(r.target.label, "slip acts on a wheel: expected left-wheel or right-wheel (or a front wheel "
                               "of preset car-steered), got '" + e.target + "'");
  // Times, in seconds since the start of the data.
  const auto t0 = parse_number(r.start.text);
  if (!t0 || *t0 < 0.0)
    throw fail(r.start.label, "expected the start in seconds since the start of the data (a number >= 0), got '" +
                            r.start.text + "'");
  e.start = *t0;
  if (r.end.present && r.end.text != "end" && !r.end.text.empty() && r.end.text != "null" &&
      r.end.text != "~") {
    const auto t1 = parse_number(r.end.text);
    if (!t1) throw fail(r.end.label, "expected the end in seconds since the start of the data or 'end', got '" +
                                   r.end.text + "'");
    if (!(*t1 > e.start))
      throw fail(r.end.label, "the end (" + r.end.text + " s) must be after the start (" + r.start.text + " s)");
    e.end = *t1;
  }
  // Keys of each kind.
  std::vector<const Field*> takes;
  switch (e.kind) {
    case FaultKind::kDropout: break;
    case FaultKind::kGyroBiasJump:
    case FaultKind::kAccelBiasJump: takes = {&r.axis, &r.value}; break;
    case FaultKind::kStuck: takes = {&r.sensor, &r.axis}; break;
    case FaultKind::kSlip: takes = {&r.ratio}; break;
  }
  std::string list;
  for (const Field* f : takes) list += (list.empty() ? "" : ", ") + f->label;
  const std::string takes_text = list.empty() ? "takes none" : "takes " + list;
  for (const auto& k : r.unknown)
    throw fail(k, "unknown key for " + std::string(fault_kind_name(e.kind)) + " (" + takes_text + ")");
  for (const Field* f : {&r.axis, &r.sensor, &r.value, &r.ratio}) {
    const bool wanted = std::find(takes.begin(), takes.end(), f) != takes.end();
    if (f->present && !wanted)
      throw fail(f->label, "not a key of " + std::string(fault_kind_name(e.kind)) + " (" + takes_text + ")");
    if (!f->present && wanted) throw fail(f->label, "missing (" + std::string(fault_kind_name(e.kind)) + " " + takes_text + ")");
  }
  if (r.axis.present) {
    const auto& a = r.axis.text;
    if (a.size() != 1 || a[0] < 'x' || a[0] > 'z')
      throw fail(r.axis.label, "expected the sensor axis x, y or z, got '" + a + "'");
    e.axis = a[0] - 'x';
  }
  e.gyro = e.kind != FaultKind::kAccelBiasJump;
  if (r.sensor.present) {
    if (r.sensor.text != "gyro" && r.sensor.text != "accel")
      throw fail(r.sensor.label, "expected gyro or accel, got '" + r.sensor.text + "'");
    e.gyro = r.sensor.text == "gyro";
  }
  if (r.value.present) {
    const auto v = parse_number(r.value.text);
    if (!v) throw fail(r.value.label, std::string("expected the bias step in ") +
                                    (e.gyro ? "deg/s" : "m/s^2") + " (a number), got '" + r.value.text + "'");
    e.value = *v;
  }
  if (r.ratio.present) {
    const auto v = parse_number(r.ratio.text);
    if (!v || *v < -1.0 || *v > 10.0)
      throw fail(r.ratio.label, "expected the slip ratio s in [-1, 10] (the wheel turns at (1 + s) x its rolling "
                          "rate; -1: it stops), got '" + r.ratio.text + "'");
    e.ratio = *v;
  }
  return e;
}

FaultEvent parse_spec(const std::string& spec, const std::string& prefix) {
  const Fail fail = [&](const std::string& label, const std::string& msg) {
    return InputError(prefix + (label.empty() ? "" : label + ": ") + msg);
  };
  std::vector<std::string> parts;
  std::size_t pos = 0;
  while (true) {
    const auto c = spec.find(':', pos);
    parts.push_back(spec.substr(pos, c == std::string::npos ? std::string::npos : c - pos));
    if (c == std::string::npos) break;
    pos = c + 1;
  }
  static const char* kFormat = "expected KIND:TARGET:T0[:T1|end][:key=value,...]";
  if (parts.size() < 3) throw fail("", std::string(kFormat) + " (at least kind, target and start)");
  if (parts.size() > 5) throw fail("", std::string(kFormat) + " (too many ':' fields)");
  RawFault r;
  r.kind = {"kind", parts[0], true};
  r.target = {"target", parts[1], true};
  r.start = {"T0", parts[2], true};
  r.end = {"T1", "", false};
  r.axis = {"axis", "", false};
  r.sensor = {"sensor", "", false};
  r.value = {"value", "", false};
  r.ratio = {"ratio", "", false};
  std::size_t next = 3;
  if (parts.size() > next && parts[next].find('=') == std::string::npos) {
    r.end = {"T1", parts[next], true};
    if (parts[next].empty()) throw fail("T1", "empty (give a time or 'end', or leave out the ':')");
    ++next;
  }
  if (parts.size() > next) {
    const std::string& kv = parts[next];
    pos = 0;
    while (pos <= kv.size()) {
      const auto c = kv.find(',', pos);
      const std::string item = kv.substr(pos, c == std::string::npos ? std::string::npos : c - pos);
      const auto eq = item.find('=');
      if (eq == std::string::npos || eq == 0)
        throw fail("", "'" + item + "': expected key=value (keys axis, sensor, value, ratio)");
      const std::string k = item.substr(0, eq), v = item.substr(eq + 1);
      Field* f = k == "axis" ? &r.axis : k == "sensor" ? &r.sensor : k == "value" ? &r.value
                 : k == "ratio" ? &r.ratio : nullptr;
      if (!f) {
        r.unknown.push_back(k);
      } else {
        if (f->present) throw fail(k, "given twice");
        f->text = v;
        f->present = true;
      }
      if (c == std::string::npos) break;
      pos = c + 1;
    }
    ++next;
  }
  if (parts.size() > next) throw fail("", std::string(kFormat) + " (too many ':' fields)");
  return build(r, fail);
}

}  // namespace

const char* fault_kind_name(FaultKind k) {
  switch (k) {
    case FaultKind::kDropout: return "dropout";
    case FaultKind::kGyroBiasJump: return "gyro-bias-jump";
    case FaultKind::kAccelBiasJump: return "accel-bias-jump";
    case FaultKind::kStuck: return "stuck";
    case FaultKind::kSlip: return "slip";
  }
  return "?";
}

double FaultEvent::value_si() const { return gyro ? value * kDeg : value; }

std::string FaultEvent::spec() const {
  std::string s = std::string(fault_kind_name(kind)) + ":" + target + ":" + num(start) + ":" +
                  (end ? num(*end) : std::string("end"));
  switch (kind) {
    case FaultKind::kDropout: break;
    case FaultKind::kGyroBiasJump:
    case FaultKind::kAccelBiasJump:
      s += std::string(":axis=") + kAxes[axis] + ",value=" + num(value);
      break;
    case FaultKind::kStuck:
      s += std::string(":sensor=") + (gyro ? "gyro" : "accel") + ",axis=" + kAxes[axis];
      break;
    case FaultKind::kSlip: s += ":ratio=" + num(ratio); break;
  }
  return s;
}

std::string FaultEvent::yaml() const {
  std::string s = std::string("{kind: ") + fault_kind_name(kind) + ", target: " + target +
                  ", start_s: " + num(start) + ", end_s: " + (end ? num(*end) : std::string("end"));
  switch (kind) {
    case FaultKind::kDropout: break;
    case FaultKind::kGyroBiasJump: s += std::string(", axis: ") + kAxes[axis] + ", value_deg_s: " + num(value); break;
    case FaultKind::kAccelBiasJump: s += std::string(", axis: ") + kAxes[axis] + ", value_m_s2: " + num(value); break;
    case FaultKind::kStuck:
      s += std::string(", sensor: ") + (gyro ? "gyro" : "accel") + ", axis: " + kAxes[axis];
      break;
    case FaultKind::kSlip: s += ", ratio: " + num(ratio); break;
  }
  return s + "}";
}

FaultEvent parse_fault_spec(const std::string& spec) { return parse_spec(spec, "--fault '" + spec + "': "); }

FaultEvent fault_from_yaml(const YAML::Node& node, const std::string& where) {
  if (node.IsScalar()) {
    const std::string spec = node.as<std::string>();
    return parse_spec(spec, where + ": '" + spec + "': ");
  }
  if (!node.IsMap())
    throw InputError(where + ": expected a map {kind: ..., target: ..., start_s: ..., ...} or a spec string");
  const Fail fail = [&](const std::string& label, const std::string& msg) {
    return InputError(where + (label.empty() ? "" : "." + label) + ": " + msg);
  };
  RawFault r;
  r.kind = {"kind", "", false};
  r.target = {"target", "", false};
  r.start = {"start_s", "", false};
  r.end = {"end_s", "", false};
  r.axis = {"axis", "", false};
  r.sensor = {"sensor", "", false};
  r.ratio = {"ratio", "", false};
  // The bias step's key carries its unit, which depends on the kind.
  const std::string kind = node["kind"] && node["kind"].IsScalar() ? node["kind"].as<std::string>() : "";
  r.value = {kind == "accel-bias-jump" ? "value_m_s2" : "value_deg_s", "", false};
  for (const auto& kv : node) {
    const std::string k = kv.first.as<std::string>();
    Field* f = k == "kind" ? &r.kind : k == "target" ? &r.target : k == "start_s" ? &r.start
               : k == "end_s" ? &r.end : k == "axis" ? &r.axis : k == "sensor" ? &r.sensor
               : k == r.value.label ? &r.value : k == "ratio" ? &r.ratio : nullptr;
    if (!f) {
      r.unknown.push_back(k);
      continue;
    }
    if (kv.second.IsNull()) {  // end_s: null = until the end; elsewhere "missing"
      if (f == &r.end) r.end.present = true;
      continue;
    }
    if (!kv.second.IsScalar()) throw fail(k, "expected a single value");
    f->text = kv.second.as<std::string>();
    f->present = true;
  }
  for (const Field* f : {&r.kind, &r.target, &r.start})
    if (!f->present) throw fail(f->label, "missing");
  return build(r, fail);
}

}  // namespace wheelins::sim
