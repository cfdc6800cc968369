// Sensor-fault events for the simulator (docs/simulator.md, "Sensor faults").
//
// A fault event acts on one chip ("left-C1") or on every chip of a module group
// ("left-wheel", "right-wheel", "body") over an interval of time counted in
// seconds since the start of the data (the scenario start, i.e. the start of the
// static period: the sample stamped start + k/rate is at k/rate). Kinds:
//   dropout         no samples written for stamps in [start, end)
//   gyro-bias-jump  a step (deg/s) added to one gyro axis' bias over [start, end)
//   accel-bias-jump a step (m/s^2) added to one accelerometer axis' bias
//   stuck           one axis of one sensor repeats its last value before `start`
//   slip            (wheel groups only) the wheel turns at (1 + ratio) times its rolling
//                   rate, switched on and off by a C-infinity window (physics: the wheel
//                   angle, hence gyro_x and the gravity projection, of every chip and the
//                   error-free stream)
// Sensor faults (all but slip) touch the chip files only; they consume no random draws,
// so every other byte of the dataset is unchanged.
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "wheelins/sim/jet.hpp"

namespace YAML {
class Node;
}

namespace wheelins::sim {

enum class FaultKind { kDropout, kGyroBiasJump, kAccelBiasJump, kStuck, kSlip };

/// "dropout", "gyro-bias-jump", "accel-bias-jump", "stuck", "slip".
const char* fault_kind_name(FaultKind k);

struct FaultEvent {
  FaultKind kind = FaultKind::kDropout;
  std::string target;          ///< a chip ("left-C1") or a group ("left-wheel", "right-wheel", "body")
  double start = 0.0;          ///< [s] since the start of the data
  std::optional<double> end;   ///< [s] since the start of the data; none: until the end of the data
  int axis = -1;               ///< sensor axis 0..2 (x, y, z): bias jumps and stuck
  bool gyro = true;            ///< the sensor: gyro (true) or accelerometer (bias jumps: from the kind)
  double value = 0.0;          ///< bias jump in the user's unit: gyro deg/s, accel m/s^2
  double ratio = 0.0;          ///< slip: the wheel turns at (1 + ratio) x its rolling rate

  /// The canonical `--fault` text, e.g. "gyro-bias-jump:right-C1:400:end:axis=z,value=0.5".
  std::string spec() const;
  /// The flow-map form written to scenario.yaml (read back by fault_from_yaml).
  std::string yaml() const;
  /// The bias step in SI units (rad/s or m/s^2).
  double value_si() const;
  /// True if the event acts on chip `chip` (e.g. "left-C2") of group `group`.
  bool targets(const std::string& group, const std::string& chip) const {
    return target == group || target == chip;
  }
  /// Active for a sample at `tau` seconds since the start of the data: start <= tau < end.
  bool active(double tau) const { return tau >= start && (!end || tau < *end); }
};

/// Parses one `--fault` spec `KIND:TARGET:T0[:T1|end][:key=value,...]`; InputError naming
/// the spec and what is wrong.
FaultEvent parse_fault_spec(const std::string& spec);
/// Parses one entry of the scenario.yaml `faults:` list (a map or a spec string); `where`
/// names it (e.g. "'scenario.yaml': faults[2]").
FaultEvent fault_from_yaml(const YAML::Node& node, const std::string& where);

/// Ramp length of the slip window [s] (shortened to half the event for shorter events).
constexpr double kSlipRamp = 0.2;

/// C-infinity step from 0 (x <= 0) to 1 (x >= 1): S(x) = 1 / (1 + exp(q)), q = 1/x - 1/(1-x).
/// Every derivative vanishes at both ends (exp(-1/x) is flat at 0), S(1/2) = 1/2 and
/// S(x) + S(1 - x) = 1 (q(1-x) = -q(x)), so the ramp's integral is half its length.
/// Evaluated as a jet of x (x given as a jet), so its derivatives are exact.
template <int N>
Jet<N> smooth_step(const Jet<N>& x) {
  if (x.c[0] <= 0.0) return Jet<N>(0.0);
  if (x.c[0] >= 1.0) return Jet<N>(1.0);
  const Jet<N> q = Jet<N>(1.0) / x - Jet<N>(1.0) / (1.0 - x);
  // |q| > 745: S or 1 - S is below e^-745 (the smallest double), and so are its
  // derivatives (they are S (1 - S) times powers of q' ~ 1/x^2 <= 6e5): exactly 0 or 1.
  if (q.c[0] > 745.0) return Jet<N>(0.0);
  if (q.c[0] < -745.0) return Jet<N>(1.0);
  if (q.c[0] > 0.0) {
    const Jet<N> m = exp(-q);  // S = m / (1 + m) with m = e^-q <= 1: no overflow
    return m / (1.0 + m);
  }
  const Jet<N> e = exp(q);  // S = 1 / (1 + e) with e <= 1
  return Jet<N>(1.0) / (1.0 + e);
}

/// The slip window of an event over [t0, t1] (t1 = +inf: open-ended) at time t, as a jet
/// in t: w = S((t - t0)/r) - S((t - t1)/r + 1) with r = min(kSlipRamp, (t1 - t0)/2): zero
/// outside [t0, t1], one on [t0 + r, t1 - r], ramps of length r inside the interval. Its
/// integral over all time is (t1 - t0) - r (each ramp contributes r/2).
template <int N>
Jet<N> slip_window(double t, double t0, double t1) {
  const double r = std::isfinite(t1) ? std::min(kSlipRamp, 0.5 * (t1 - t0)) : kSlipRamp;
  auto arg = [&](double shift) {  // the jet of x = (t - shift) / r: value and slope 1/r
    Jet<N> x((t - shift) / r);
    if constexpr (N >= 1) x.c[1] = 1.0 / r;
    return x;
  };
  Jet<N> w = smooth_step(arg(t0));
  if (std::isfinite(t1)) w -= smooth_step(arg(t1 - r));
  return w;
}

}  // namespace wheelins::sim
