// The reference track's clock from its speed against the wheels' (reference_clock.hpp).
#include "wheelins/survey/reference_clock.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "wheelins/nav/earth.hpp"

namespace wheelins::survey {

Signal wheel_speed_signal(const std::vector<Series>& series, const DatasetSurvey& survey) {
  std::vector<Signal> speeds;
  for (std::size_t i = 0; i < series.size() && i < survey.modules.size(); ++i) {
    const ModuleFinding& f = survey.modules[i];
    if (f.kind != ModuleKind::kWheel || f.steered || !f.forward_clear) continue;
    std::vector<double> v = spin_rate(series[i], f.traits);
    for (double& x : v) x *= -f.axle_sign;
    Signal s = Signal::of(series[i], v);
    s.shift(f.clock.found ? f.clock.offset : 0.0);
    speeds.push_back(std::move(s));
  }
  Signal out;
  if (speeds.empty()) return out;
  const double from = std::max_element(speeds.begin(), speeds.end(), [](const Signal& a, const Signal& b) { return a.start() < b.start(); })->start();
  const double to = std::min_element(speeds.begin(), speeds.end(), [](const Signal& a, const Signal& b) { return a.end() < b.end(); })->end();
  const double step = speeds.front().step > 0.0 ? speeds.front().step : 0.01;
  for (double t = from; t <= to; t += step) {
    double v = 0.0;
    for (const Signal& s : speeds) v += s.at(t);
    out.t.push_back(t);
    out.x.push_back(v / static_cast<double>(speeds.size()));
  }
  out.step = step;
  return out;
}

ReferenceClockFit fit_reference_clock(const std::vector<TruthRecord>& track, const std::vector<Series>& series,
                                      const DatasetSurvey& survey, const ClockOptions& options) {
  ReferenceClockFit fit;
  const Signal wheels = wheel_speed_signal(series, survey);
  if (wheels.t.size() < 100) {
    fit.notes.push_back("no wheel whose way forward is clear: the reference's clock cannot be fitted");
    return fit;
  }
  if (track.size() < 10) {
    fit.notes.push_back("the reference has fewer than 10 records");
    return fit;
  }
  // The track's horizontal speed at its records (central differences), in its own time unit.
  const earth::LocalFrame frame(track.front().lla);
  std::vector<Vec3> p(track.size());
  for (std::size_t k = 0; k < track.size(); ++k) p[k] = frame.ned_from_geodetic(track[k].lla);
  const double imu_span = wheels.end() - wheels.start();
  const double raw_span = track.back().t - track.front().t;
  for (int e = -3; e <= 3; ++e) {
    const double scale = std::pow(10.0, e);
    const double span = raw_span * scale;
    if (!(span > 0.2 * imu_span && span < 5.0 * imu_span) && e != 0) continue;
    Signal v;
    for (std::size_t k = 1; k + 1 < track.size(); ++k) {
      const double dt = (track[k + 1].t - track[k - 1].t) * scale;
      if (!(dt > 0.0)) continue;
      v.t.push_back(track[k].t * scale);
      v.x.push_back((p[k + 1] - p[k - 1]).head<2>().norm() / dt);
    }
    if (v.t.size() < 10) continue;
    ClockOptions o = options;
    o.min_overlap = std::min(o.min_overlap, 0.5 * std::min(imu_span, span));
    const ClockFit f = fit_clock_offset(wheels, v, o);
    char buf[160];
    std::snprintf(buf, sizeof buf, "time scale %g s per unit: offset %+.4f s, correlation %.3f", scale, f.offset,
                  f.correlation);
    fit.notes.push_back(buf);
    if (f.found && f.correlation > fit.correlation) {
      fit.found = true;
      fit.scale = scale;
      fit.offset = f.offset;
      fit.sigma = f.sigma;
      fit.correlation = f.correlation;
    }
  }
  return fit;
}

}  // namespace wheelins::survey
