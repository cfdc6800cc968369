// Clock offsets between two modules (or a module and a reference) from the signals
// themselves: the offset o such that a(t) = b(t - o), i.e. b's times + o are on a's clock
// (the manifest's time_offset_s of b when a's clock is the run's).
//
// Method: both signals on a common step (coarse_step), the Pearson correlation at every
// lag with enough overlap, computed with FFTs (Eigen's FFT module) and prefix sums for
// the per-lag means and variances, so any offset within the two recordings' spans is found
// in O(N log N); the best lag refined at the series' own step and by a parabola through
// the three best lags; its 1 sigma from the scatter of the same fit on `chunks` disjoint
// parts of the overlap (the standard error of their mean, at least a tenth of a step).
#pragma once

#include <algorithm>
#include <limits>
#include <vector>

#include "wheelins/survey/series.hpp"

namespace wheelins::survey {

struct ClockOptions {
  double coarse_step = 0.05;  ///< [s] the step of the search over all lags
  double min_overlap = 20.0;  ///< [s] shortest overlap a lag is judged on
  double search_lo = -std::numeric_limits<double>::infinity();  ///< [s] offsets searched
  double search_hi = std::numeric_limits<double>::infinity();
  int chunks = 5;             ///< parts of the overlap the 1 sigma comes from
};

struct ClockFit {
  bool found = false;        ///< a lag with enough overlap existed
  double offset = 0.0;       ///< o [s]
  double sigma = 0.0;        ///< 1 sigma [s] (infinite when the chunks could not be fitted)
  double correlation = 0.0;  ///< Pearson correlation at o
  double overlap = 0.0;      ///< [s] overlap at o
};

/// A signal given at evenly spaced times t0 + (i + 0.5) * dt (a Series' bins) or at any
/// increasing times.
struct Signal {
  std::vector<double> t;
  std::vector<double> x;
  /// > 0 when t is evenly spaced by it (at() then needs no search).
  double step = 0.0;
  static Signal of(const Series& s, const std::vector<double>& x);
  double at(double time) const;  ///< linear interpolation, clamped at the ends (inline below: hot)
  void shift(double offset);     ///< adds offset to every time
  double start() const { return t.empty() ? 0.0 : t.front(); }
  double end() const { return t.empty() ? 0.0 : t.back(); }
};

inline double Signal::at(double time) const {
  if (t.empty()) return 0.0;
  if (!(time > t.front())) return x.front();
  if (time >= t.back()) return x.back();
  if (step > 0.0) {
    const double u = (time - t.front()) / step;
    const std::size_t k = std::min(static_cast<std::size_t>(u), x.size() - 2);
    const double a = u - static_cast<double>(k);
    return (1.0 - a) * x[k] + a * x[k + 1];
  }
  const auto it = std::upper_bound(t.begin(), t.end(), time);
  const std::size_t k = static_cast<std::size_t>(it - t.begin());
  const double a = (time - t[k - 1]) / (t[k] - t[k - 1]);
  return (1.0 - a) * x[k - 1] + a * x[k];
}

/// The offset o with a(t) = b(t - o) (see the header).
ClockFit fit_clock_offset(const Signal& a, const Signal& b, const ClockOptions& options = {});

/// Pearson correlation of a(t) and b(t - o) over their overlap at step `step`; NaN when
/// the overlap is shorter than `min_overlap`.
double correlation_at(const Signal& a, const Signal& b, double o, double step, double min_overlap,
                      double* overlap = nullptr);

}  // namespace wheelins::survey
