// The survey of a set of modules (dataset.hpp): kinds, axes, clocks, sides, steering and
// the static period, from the data alone.
#include "wheelins/survey/dataset.hpp"
#include "wheelins/survey/format.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace wheelins::survey {
namespace {

Signal shifted(Signal s, double offset) {
  s.shift(offset);
  return s;
}

std::vector<double> absolute(std::vector<double> x) {
  for (double& v : x) v = std::abs(v);
  return x;
}

/// rms(a - b) / rms(b) over the common span of two signals on the common clock, and the
/// least-squares slope of (a - b) on c there (for the sides), at `step`.
double departure(const Signal& a, const Signal& b, double step) {
  const double from = std::max(a.start(), b.start()), to = std::min(a.end(), b.end());
  double sd = 0.0, sb = 0.0;
  // Means over 0.5 s: a steering wheel turns over seconds, the noise is faster.
  const int h = static_cast<int>(std::lround(0.25 / step));
  for (double t = from + 0.25; t <= to - 0.25; t += step) {
    double x = 0.0, y = 0.0;
    for (int k = -h; k <= h; ++k) x += a.at(t + k * step), y += b.at(t + k * step);
    x /= 2 * h + 1;
    y /= 2 * h + 1;
    sd += (x - y) * (x - y);
    sb += y * y;
  }
  return sb > 0.0 ? std::sqrt(sd / sb) : std::nan("");
}

/// Slope and correlation of (a - b) against c over their common span.
void difference_against(const Signal& a, const Signal& b, const Signal& c, double step, double* slope,
                        double* corr) {
  const double from = std::max({a.start(), b.start(), c.start()});
  const double to = std::min({a.end(), b.end(), c.end()});
  double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0, m = 0;
  for (double t = from; t <= to; t += step) {
    const double y = a.at(t) - b.at(t), x = c.at(t);
    sx += x, sy += y, sxx += x * x, syy += y * y, sxy += x * y, m += 1;
  }
  *slope = *corr = 0.0;
  if (m < 10) return;
  const double vx = sxx - sx * sx / m, vy = syy - sy * sy / m, cxy = sxy - sx * sy / m;
  if (vx > 0.0) *slope = cxy / vx;
  if (vx > 0.0 && vy > 0.0) *corr = cxy / std::sqrt(vx * vy);
}

ClockFit combine(const ClockFit& a, const ClockFit& b, double sign_b) {
  ClockFit c = a;
  c.offset = a.offset + sign_b * b.offset;
  c.sigma = std::hypot(a.sigma, b.sigma);
  c.correlation = std::min(a.correlation, b.correlation);
  c.found = a.found && b.found;
  return c;
}

/// A body's horizontal acceleration's size: its specific force less its mean at rest, the
/// part along its up-axis taken out, over 0.25 s.
std::vector<double> horizontal_acceleration(const Series& s, const ModuleTraits& t) {
  Vec3 g = Vec3::Zero();
  double n = 0.0;
  for (const Interval& iv : t.rest)
    for (std::size_t k = s.index(iv.start); k < s.size() && s.time(k) < iv.end; ++k) g += s.accel[k], n += 1.0;
  if (n > 0.0) g /= n;
  std::vector<double> out(s.size());
  for (std::size_t k = 0; k < s.size(); ++k) {
    const Vec3 a = s.accel[k] - g;
    out[k] = (a - a.dot(t.up) * t.up).norm();
  }
  return moving_average(out, std::max(1, static_cast<int>(std::lround(0.25 / s.dt))));
}

/// A wheel's acceleration's size in turns: |d(spin rate)/dt| over 0.25 s.
std::vector<double> wheel_acceleration(const Series& s, const std::vector<double>& spin) {
  const std::vector<double> w = moving_average(spin, std::max(1, static_cast<int>(std::lround(0.25 / s.dt))));
  std::vector<double> out(w.size(), 0.0);
  for (std::size_t k = 1; k + 1 < w.size(); ++k) out[k] = std::abs(w[k + 1] - w[k - 1]) / (2.0 * s.dt);
  return moving_average(out, std::max(1, static_cast<int>(std::lround(0.25 / s.dt))));
}

}  // namespace

const ModuleFinding* DatasetSurvey::find(const std::string& name) const {
  for (const auto& m : modules)
    if (m.module == name) return &m;
  return nullptr;
}

DatasetSurvey survey_modules(const std::vector<ModuleInput>& modules, const SurveyOptions& o) {
  std::vector<Series> series;
  series.reserve(modules.size());
  for (const auto& m : modules) {
    SeriesOptions so = o.series;
    if (m.gyro_limit > 0.0) so.gyro_limit = m.gyro_limit;
    if (m.accel_limit > 0.0) so.accel_limit = m.accel_limit;
    series.push_back(read_series(m.name, m.file, m.read, so));
  }
  return survey_series(series, o);
}

DatasetSurvey survey_series(const std::vector<Series>& S, const SurveyOptions& o) {
  DatasetSurvey out;
  const std::size_t n = S.size();
  std::vector<int> wheels, bodies;
  std::vector<std::vector<double>> spin(n), yaw(n);
  for (std::size_t i = 0; i < n; ++i) {
    ModuleFinding f;
    f.module = S[i].module;
    f.traits = analyse_module(S[i], o.traits);
    f.kind = f.traits.spins ? ModuleKind::kWheel : ModuleKind::kBody;
    if (f.kind == ModuleKind::kWheel) {
      f.axle_axis = f.traits.spin_axis;
      // Rolling forward turns a wheel negatively about an axis pointing right.
      f.axle_sign = f.traits.spin_direction <= 0.0 ? 1 : -1;
      f.forward_clear = std::abs(f.traits.spin_direction) >= o.min_forward;
      spin[i] = absolute(spin_rate(S[i], f.traits));
      wheels.push_back(static_cast<int>(i));
    } else {
      bodies.push_back(static_cast<int>(i));
    }
    // Smoothed over 0.2 s: the vehicle's yaw rate is slow, the wheels' estimate of it noisy.
    yaw[i] = moving_average(yaw_rate(S[i], f.traits), std::max(1, static_cast<int>(std::lround(0.2 / S[i].dt))));
    f.yaw_departure = std::nan("");
    out.modules.push_back(std::move(f));
  }
  if (n == 0) return out;
  // The wheel all clocks are tied through: the one with the longest data (the others are
  // matched against it), the first listed among equals.
  std::sort(wheels.begin(), wheels.end(), [&](int a, int b) {
    // Whole seconds (spans alike keep their listed order: the index breaks ties).
    const auto span = [&](int i) {
      return std::floor(S[static_cast<std::size_t>(i)].t_last - S[static_cast<std::size_t>(i)].t_first);
    };
    return span(a) != span(b) ? span(a) > span(b) : a < b;
  });
  const double step = S.front().dt;
  auto signal = [&](std::size_t i, const std::vector<double>& x) { return Signal::of(S[i], x); };

  // Clocks. Wheels against the first wheel by their spin rates (a rolling vehicle's wheels
  // turn alike), else by their yaw rates.
  std::vector<ClockFit> to_w0(n);  // offset to the first wheel's clock
  if (!wheels.empty()) {
    const std::size_t w0 = static_cast<std::size_t>(wheels.front());
    to_w0[w0].found = true;
    to_w0[w0].correlation = 1.0;
    out.modules[w0].clock_basis = "its own clock";
    for (std::size_t k = 1; k < wheels.size(); ++k) {
      const std::size_t i = static_cast<std::size_t>(wheels[k]);
      ClockFit f = fit_clock_offset(signal(w0, spin[w0]), signal(i, spin[i]), o.clock);
      std::string basis = "spin rate against " + S[w0].module;
      if (!f.found || f.correlation < 0.8) {
        const ClockFit g = fit_clock_offset(signal(w0, yaw[w0]), signal(i, yaw[i]), o.clock);
        if (g.found && (!f.found || g.correlation > f.correlation)) {
          f = g;
          basis = "yaw rate against " + S[w0].module;
        }
      }
      if (!(f.correlation >= o.min_clock_correlation)) f.found = false;  // no common motion to tell
      to_w0[i] = f;
      out.modules[i].clock_basis = basis;
    }
  }
  // Bodies against the wheel whose yaw rate matches best (an unsteered one).
  std::vector<ClockFit> to_ref(n);
  if (!bodies.empty()) {
    std::size_t ref = static_cast<std::size_t>(bodies.front());
    for (int b : bodies) {
      const std::size_t i = static_cast<std::size_t>(b);
      ClockFit best;
      std::string basis;
      if (wheels.empty()) {
        if (i == ref) {
          best.found = true, best.correlation = 1.0;
          basis = "its own clock";
        } else {
          best = fit_clock_offset(signal(ref, yaw[ref]), signal(i, yaw[i]), o.clock);
          basis = "yaw rate against " + S[ref].module;
        }
      } else {
        // o_(b, w0) = o_(b, j) - o_(w0, j) for the best wheel j: by the yaw rates, else (a
        // drive without turns) by the size of the horizontal acceleration.
        for (int w : wheels) {
          const std::size_t j = static_cast<std::size_t>(w);
          if (!to_w0[j].found ||
              std::find(o.steered.begin(), o.steered.end(), S[j].module) != o.steered.end())
            continue;
          const ClockFit f = fit_clock_offset(signal(i, yaw[i]), signal(j, yaw[j]), o.clock);
          if (f.found && f.correlation >= o.min_clock_correlation && (!best.found || f.correlation > best.correlation)) {
            best = combine(f, to_w0[j], -1.0);
            basis = "yaw rate against " + S[j].module;
          }
        }
        if (!best.found) {
          const std::size_t j = static_cast<std::size_t>(wheels.front());
          const ClockFit f = fit_clock_offset(signal(i, horizontal_acceleration(S[i], out.modules[i].traits)),
                                              signal(j, wheel_acceleration(S[j], spin[j])), o.clock);
          if (f.found && f.correlation >= o.min_clock_correlation) {
            best = combine(f, to_w0[j], -1.0);
            basis = "acceleration against " + S[j].module;
            out.modules[i].clock_weak = true;
          } else {
            best = ClockFit{};
            basis = "not found (no common turning or acceleration)";
          }
        }
      }
      to_ref[i] = best;  // for now: body clock -> w0 clock, inverted below
      out.modules[i].clock_basis = basis;
    }
    // The reference is the first body tied to the wheels: every offset becomes "to the
    // reference's clock". A body tied to none keeps its clock unknown; with no body tied,
    // the first wheel's clock is the reference.
    for (int b : bodies)
      if (wheels.empty() || to_ref[static_cast<std::size_t>(b)].found) {
        ref = static_cast<std::size_t>(b);
        break;
      }
    const bool ref_tied = wheels.empty() || to_ref[ref].found;
    const ClockFit ref_to_w0 = wheels.empty() ? ClockFit{true, 0.0, 0.0, 1.0, 0.0}
                               : ref_tied   ? to_ref[ref]
                                            : ClockFit{true, 0.0, 0.0, 1.0, 0.0};
    if (!ref_tied) ref = static_cast<std::size_t>(wheels.front());
    const std::string ref_basis = out.modules[ref].clock_basis;
    for (std::size_t i = 0; i < n; ++i) {
      ModuleFinding& f = out.modules[i];
      if (i == ref) {
        f.clock = ClockFit{true, 0.0, 0.0, 1.0, 0.0};
        f.clock_reference = true;
        f.clock_basis = "the reference clock";
      } else if (f.kind == ModuleKind::kWheel && !ref_tied) {
        f.clock = to_w0[i];
      } else if (f.kind == ModuleKind::kWheel) {
        // t_ref = t_w0 + o_(ref, w0) and t_w0 = t_i + o_(w0, i).
        f.clock = combine(to_w0[i], ref_to_w0, +1.0);
        if (static_cast<int>(i) == wheels.front())
          f.clock_basis = "the reference " + S[ref].module + "'s " + ref_basis;
      } else if (!wheels.empty()) {
        // Another body: t_w0 = t_b - to_ref[b]... fit(a=b, b=j) gives t_b = t_j + o, so
        // t_j = t_b - o and t_ref = t_w0 + o_ref: t_ref = t_b - o_(b,w0) + o_(ref,w0).
        ClockFit c = to_ref[i];
        c.offset = -c.offset + ref_to_w0.offset;
        c.sigma = std::hypot(c.sigma, ref_to_w0.sigma);
        f.clock = c;
      } else {
        f.clock = to_ref[i];
      }
    }
  } else if (!wheels.empty()) {
    for (std::size_t i = 0; i < n; ++i) {
      out.modules[i].clock = to_w0[i];
      out.modules[i].clock_reference = static_cast<int>(i) == wheels.front();
      if (out.modules[i].clock_reference) out.modules[i].clock_basis = "the reference clock";
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    ModuleFinding& f = out.modules[i];
    const double off = f.clock.found ? f.clock.offset : 0.0;
    f.start = S[i].t_first + off;
    f.end = S[i].t_end + off;
    f.input_start = S[i].t_first;
    f.input_end = S[i].t_end;
  }

  // Everything below compares the modules on the common clock.
  auto common = [&](std::size_t i, const std::vector<double>& x) {
    return shifted(signal(i, x), out.modules[i].clock.found ? out.modules[i].clock.offset : 0.0);
  };
  // The static period: the first interval in which every module rests -- each wheel by its
  // spin rate, each body by the spreads of its rate and specific force. Should the bodies
  // never be quiet while the wheels rest (an idling engine shakes them), the wheels' common
  // rest is taken and the survey says so.
  double from = -1e300, to = 1e300;
  std::vector<Signal> masks, body_masks;  // masks: the wheels' (every body's without wheels)
  for (std::size_t i = 0; i < n; ++i) {
    const bool wheel = out.modules[i].kind == ModuleKind::kWheel;
    if (!wheel && !wheels.empty()) {
      const auto m = rest_mask(S[i], out.modules[i].traits);
      body_masks.push_back(common(i, std::vector<double>(m.begin(), m.end())));
      continue;
    }
    from = std::max(from, out.modules[i].start);
    to = std::min(to, S[i].t_last + (out.modules[i].clock.found ? out.modules[i].clock.offset : 0.0));
    const auto m = rest_mask(S[i], out.modules[i].traits);
    masks.push_back(common(i, std::vector<double>(m.begin(), m.end())));
  }
  auto first_rest = [&](bool with_bodies) -> std::optional<Interval> {
    double run_start = std::nan("");
    for (double t = from; t <= to; t += step) {
      bool all = !masks.empty();
      for (const Signal& m : masks) all = all && m.at(t) > 0.5;
      if (with_bodies)
        for (const Signal& m : body_masks) all = all && m.at(t) > 0.5;
      if (all && std::isnan(run_start)) run_start = t;
      if (!all && !std::isnan(run_start)) {
        if (t - run_start >= o.min_static + 2.0 * o.static_margin)
          return Interval{run_start + o.static_margin, t - o.static_margin};
        run_start = std::nan("");
      }
    }
    return std::nullopt;
  };
  out.static_period = first_rest(true);
  if (!out.static_period && !body_masks.empty()) {
    out.static_period = first_rest(false);
    out.static_bodies_quiet = !out.static_period;
  }

  // A body rests when the wheels do (a car body's own rates are too quiet to tell rest from
  // a smooth drive): its bias and up-axis from those bins, its yaw rate again with them.
  if (!wheels.empty() && !masks.empty())
    for (int b : bodies) {
      const std::size_t i = static_cast<std::size_t>(b);
      ModuleFinding& f = out.modules[i];
      const double off = f.clock.found ? f.clock.offset : 0.0;
      std::vector<std::uint8_t> rest(S[i].size(), 0);
      for (std::size_t k = 0; k < S[i].size(); ++k) {
        const double t = S[i].time(k) + off;
        bool all = t >= from && t <= to;
        for (const Signal& m : masks) all = all && m.at(t) > 0.5;
        rest[k] = all;
      }
      std::vector<Interval> iv;
      Vec3 gs = Vec3::Zero(), fs = Vec3::Zero();
      double n_rest = 0.0;
      for (std::size_t k = 0; k < rest.size();) {
        if (!rest[k]) {
          ++k;
          continue;
        }
        std::size_t j = k;
        while (j < rest.size() && rest[j]) ++j;
        const Interval r{S[i].t0 + static_cast<double>(k) * S[i].dt, S[i].t0 + static_cast<double>(j) * S[i].dt};
        if (r.length() >= o.traits.min_rest) {
          iv.push_back(r);
          for (std::size_t q = k; q < j; ++q) gs += S[i].gyro[q], fs += S[i].accel[q], n_rest += 1.0;
        }
        k = j;
      }
      if (n_rest > 0.0) {
        f.traits.rest = iv;
        f.traits.rest_found = true;
        f.traits.gyro_bias = gs / n_rest;
        f.traits.up = fs.normalized();
        yaw[i] = moving_average(yaw_rate(S[i], f.traits), std::max(1, static_cast<int>(std::lround(0.2 / S[i].dt))));
      }
    }

  // The vehicle's yaw rate: the reference body's, else the first wheel's.
  std::optional<Signal> vehicle_yaw;
  if (!bodies.empty()) vehicle_yaw = common(static_cast<std::size_t>(bodies.front()), yaw[static_cast<std::size_t>(bodies.front())]);
  else if (!wheels.empty()) vehicle_yaw = common(static_cast<std::size_t>(wheels.front()), yaw[static_cast<std::size_t>(wheels.front())]);

  // Sides: every pair of wheels votes (the right wheel is faster in a left turn).
  if (vehicle_yaw && wheels.size() >= 2) {
    for (std::size_t a = 0; a < wheels.size(); ++a)
      for (std::size_t b = a + 1; b < wheels.size(); ++b) {
        const std::size_t i = static_cast<std::size_t>(wheels[a]), j = static_cast<std::size_t>(wheels[b]);
        double slope = 0.0, corr = 0.0;
        difference_against(common(i, spin[i]), common(j, spin[j]), *vehicle_yaw, 0.05, &slope, &corr);
        if (std::abs(corr) < 0.3) continue;
        out.modules[i].side_evidence += corr;
        out.modules[j].side_evidence -= corr;
      }
    for (int w : wheels) {
      ModuleFinding& f = out.modules[static_cast<std::size_t>(w)];
      if (std::abs(f.side_evidence) >= 0.3) f.side = f.side_evidence > 0.0 ? 1 : -1;
    }
  }
  // Steering: a wheel's yaw rate against the vehicle's, judged only where the vehicle turns.
  double yaw_rms = 0.0;
  if (vehicle_yaw) {
    for (double x : vehicle_yaw->x) yaw_rms += x * x;
    yaw_rms = vehicle_yaw->x.empty() ? 0.0 : std::sqrt(yaw_rms / static_cast<double>(vehicle_yaw->x.size()));
  }
  if (!bodies.empty() && yaw_rms >= o.min_turning)
    for (int w : wheels) {
      ModuleFinding& f = out.modules[static_cast<std::size_t>(w)];
      const Signal wy = common(static_cast<std::size_t>(w), yaw[static_cast<std::size_t>(w)]);
      f.yaw_departure = departure(wy, *vehicle_yaw, 0.05);
      ClockOptions lead = o.clock;
      lead.search_lo = -2.0;
      lead.search_hi = 2.0;
      const ClockFit l = fit_clock_offset(*vehicle_yaw, wy, lead);
      f.yaw_lead = l.found ? l.offset : std::nan("");
      f.steered = f.yaw_departure > o.steering_ratio ||
                  (l.found && l.correlation >= 0.6 && l.offset > o.steering_lead);
    }

  // A body's forward and left axes: its specific force against the wheels' acceleration and
  // their speed times the yaw rate (per wheel speed in rad/s: only the directions are used).
  if (!wheels.empty() && vehicle_yaw) {
    std::vector<Signal> speeds;
    for (int w : wheels) {
      const std::size_t i = static_cast<std::size_t>(w);
      if (out.modules[i].steered || !out.modules[i].forward_clear) continue;
      std::vector<double> v = spin_rate(S[i], out.modules[i].traits);
      for (double& x : v) x *= -out.modules[i].axle_sign;
      speeds.push_back(common(i, moving_average(v, std::max(1, static_cast<int>(std::lround(0.2 / S[i].dt))))));
    }
    for (int b : bodies) {
      const std::size_t i = static_cast<std::size_t>(b);
      if (speeds.empty()) break;
      ModuleFinding& f = out.modules[i];
      const double off = f.clock.found ? f.clock.offset : 0.0;
      const auto rest = rest_mask(S[i], f.traits);
      // The specific force over 0.5 s: a car body's vibration is far larger than the
      // accelerations of its motion at the sample rate.
      // Both sides are high-passed (less their 8 s means): a road's grade and bank tilt the
      // body slowly, and gravity along its axes would otherwise pass for acceleration.
      std::vector<Vec3> acc(S[i].size());
      const int h = std::max(1, static_cast<int>(std::lround(0.25 / S[i].dt)));
      const int H = std::max(2, static_cast<int>(std::lround(4.0 / S[i].dt)));
      for (int ax = 0; ax < 3; ++ax) {
        std::vector<double> x(S[i].size());
        for (std::size_t k = 0; k < x.size(); ++k) x[k] = S[i].accel[k][ax];
        const std::vector<double> fast = moving_average(x, 2 * h + 1), slow = moving_average(x, 2 * H + 1);
        for (std::size_t k = 0; k < x.size(); ++k) acc[k][ax] = fast[k] - slow[k];
      }
      // The regressors on the body's bins, high-passed the same way.
      std::vector<double> ra(S[i].size()), rc(S[i].size());
      for (std::size_t k = 0; k < S[i].size(); ++k) {
        const double t = S[i].time(k) + off;
        double v = 0.0, vp = 0.0, vm = 0.0;
        for (const Signal& sp : speeds) v += sp.at(t), vp += sp.at(t + 0.05), vm += sp.at(t - 0.05);
        v /= static_cast<double>(speeds.size());
        ra[k] = (vp - vm) / (0.1 * static_cast<double>(speeds.size()));
        rc[k] = v * vehicle_yaw->at(t);
      }
      {
        const std::vector<double> sa = moving_average(ra, 2 * H + 1), sc = moving_average(rc, 2 * H + 1);
        const std::vector<double> fa = moving_average(ra, 2 * h + 1), fc = moving_average(rc, 2 * h + 1);
        for (std::size_t k = 0; k < ra.size(); ++k) ra[k] = fa[k] - sa[k], rc[k] = fc[k] - sc[k];
      }
      Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
      Eigen::Matrix<double, 3, 3> B = Eigen::Matrix3d::Zero();  // rows: regressors, cols: axes
      Vec3 fs = Vec3::Zero(), fss = Vec3::Zero();
      double m = 0.0;
      const std::size_t dk = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(0.05 / S[i].dt)));
      for (std::size_t k = dk; k + dk < S[i].size(); k += dk) {
        const Vec3 r(ra[k], rc[k], 1.0);
        const Vec3 y = acc[k];
        A += r * r.transpose();
        B += r * y.transpose();
        fs += y;
        fss += y.cwiseAbs2();
        m += 1.0;
      }
      if (m < 50.0 || std::abs(A.determinant()) < 1e-12) continue;
      const Eigen::Matrix3d C = A.ldlt().solve(B);  // row 0: forward * r, row 1: left * r
      Vec3 fwd = C.row(0).transpose(), lft = C.row(1).transpose();
      // Each fit's correlation: the variance it explains along its own axis.
      auto fit_corr = [&](const Vec3& dir, int row) {
        const Vec3 u = dir.normalized();
        double sxy = 0, sxx = 0, syy = 0, sx = 0, sy = 0, mm = 0;
        for (std::size_t k = dk; k + dk < S[i].size(); k += dk) {
          const double x = row == 0 ? ra[k] : rc[k];
          const double y = acc[k].dot(u);
          sx += x, sy += y, sxx += x * x, syy += y * y, sxy += x * y, mm += 1;
        }
        const double vx = sxx - sx * sx / mm, vy = syy - sy * sy / mm;
        return vx > 0 && vy > 0 ? (sxy - sx * sy / mm) / std::sqrt(vx * vy) : 0.0;
      };
      (void)rest;
      if (!(fwd.norm() > 0.0 && lft.norm() > 0.0)) continue;
      f.forward_fit = fit_corr(fwd, 0);
      f.left_fit = fit_corr(lft, 1);
      // Orthogonal to the measured up-axis, and to each other.
      const Vec3 up = f.traits.up;
      fwd = (fwd - fwd.dot(up) * up).normalized();
      lft = up.cross(fwd);
      f.forward = fwd;
      f.left = lft;
      f.axes_found = f.forward_fit > 0.5;
      if (f.axes_found) f.level = fit_level(S[i], f.traits.up, f.forward, o.level);
    }
  }

  // Notes.
  for (const ModuleFinding& f : out.modules) {
    const ModuleTraits& t = f.traits;
    if (f.kind == ModuleKind::kWheel)
      out.notes.push_back(f.module + ": spins about its " + std::string(1, "xyz"[t.spin_axis]) + " axis (" +
                          fmt("%.1f %% of the rotation, 95th percentile %.1f rad/s); ", 100.0 * t.spin_share, t.spin_p95) +
                          (f.forward_clear ? fmt("%.0f %% of its turning one way: the axle axis points ", 50.0 * (1.0 + std::abs(t.spin_direction))) +
                                                 (f.axle_sign > 0 ? "right" : "left")
                                           : std::string("turns both ways: the way forward is not clear")));
    else
      out.notes.push_back(f.module + fmt(": does not spin (95th percentile rate %.2f rad/s): a body IMU", t.spin_p95));
    if (f.kind == ModuleKind::kBody)
      out.notes.push_back(f.module + fmt(": forward axis [%.2f, %.2f, %.2f] in its axes", f.forward.x(), f.forward.y(), f.forward.z()) +
                          fmt(" (acceleration fit %.2f, centripetal fit %.2f), up ", f.forward_fit, f.left_fit) +
                          fmt("[%.2f, %.2f, %.2f]", t.up.x(), t.up.y(), t.up.z()));
    if (f.kind == ModuleKind::kBody && f.axes_found)
      out.notes.push_back(f.module + (f.level.found ? fmt(": level from the drive: up [%.3f, %.3f, %.3f]", f.level.up.x(), f.level.up.y(), f.level.up.z()) +
                                                          fmt(" (+- %.1f deg roll, +- %.1f deg pitch; ", f.level.sigma_roll_deg, f.level.sigma_pitch_deg) +
                                                          fmt("the up-axis at rest is %.1f deg from it)", angle_deg(f.level.up, t.up))
                                                    : ": level not fitted from the drive: " + f.level.why));
    if (!f.clock_reference && f.clock.found)
      out.notes.push_back(f.module + fmt(": clock offset %+.4f s +- %.4f s (correlation %.3f, ", f.clock.offset, f.clock.sigma, f.clock.correlation) +
                          f.clock_basis + ")");
    else if (!f.clock.found)
      out.notes.push_back(f.module + ": clock offset not found (its data do not overlap the others' enough)");
    if (f.kind == ModuleKind::kWheel && f.side)
      out.notes.push_back(f.module + ": on the vehicle's " + (f.side > 0 ? "right" : "left") + fmt(" (evidence %.2f)", f.side_evidence));
    if (f.kind == ModuleKind::kWheel && std::isfinite(f.yaw_departure))
      out.notes.push_back(f.module + fmt(": yaw rate departs %.2f of the vehicle's and leads it by %.2f s: ", f.yaw_departure, f.yaw_lead) +
                          (f.steered ? "a steered wheel" : "not steered"));
  }
  if (out.static_period)
    out.notes.push_back(fmt("static period [%.3f, %.3f] s (%.1f s; ", out.static_period->start, out.static_period->end,
                            out.static_period->length()) +
                        static_period_basis(out) + ")");
  else
    out.notes.push_back("no static period found (the modules never rest together for " + fmt("%.1f s)", o.min_static));
  return out;
}

std::string static_period_basis(const DatasetSurvey& s) {
  bool wheel = false, body = false;
  for (const ModuleFinding& f : s.modules) (f.kind == ModuleKind::kWheel ? wheel : body) = true;
  if (!wheel) return "every module at rest: rate and specific force quiet";
  if (!body) return "every wheel at rest";
  return s.static_bodies_quiet ? "every wheel at rest and every body quiet"
                               : "every wheel at rest; the bodies are never quiet with them (an idling engine?): check it";
}

std::string survey_report(const DatasetSurvey& s) {
  std::string out = "module          kind   axle     side   steered        clock offset [s]\n";
  for (const ModuleFinding& f : s.modules) {
    char line[256];
    const bool w = f.kind == ModuleKind::kWheel;
    std::string axle = w ? std::string(1, "xyz"[f.axle_axis]) + (f.forward_clear ? (f.axle_sign > 0 ? " right" : " left") : " ?") : "-";
    std::string side = w ? (f.side > 0 ? "right" : f.side < 0 ? "left" : "?") : "-";
    std::string steer = !w ? "-" : std::isfinite(f.yaw_lead) ? (f.steered ? "yes" : "no") + fmt(" (%+.2f s)", f.yaw_lead) : "?";
    std::string clock = f.clock_reference ? "0 (the reference)"
                        : f.clock.found   ? fmt("%+.4f +- %.4f", f.clock.offset, f.clock.sigma)
                                          : "not found";
    std::snprintf(line, sizeof line, "%-15s %-6s %-8s %-6s %-14s %s\n", f.module.c_str(), w ? "wheel" : "body",
                  axle.c_str(), side.c_str(), steer.c_str(), clock.c_str());
    out += line;
  }
  out += s.static_period ? fmt("static period %.2f .. %.2f s (%.1f s, ", s.static_period->start,
                               s.static_period->end, s.static_period->length()) + static_period_basis(s) + ")\n"
                         : std::string("no static period (the modules never rest together)\n");
  return out;
}

}  // namespace wheelins::survey
