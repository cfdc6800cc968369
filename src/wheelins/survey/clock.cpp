// Clock offsets from cross-correlation (clock.hpp).
#include "wheelins/survey/clock.hpp"

#include <unsupported/Eigen/FFT>

#include <algorithm>
#include <cmath>
#include <complex>

namespace wheelins::survey {
namespace {

std::vector<double> resample(const Signal& s, double t0, double step, std::size_t n) {
  std::vector<double> out(n);
  for (std::size_t i = 0; i < n; ++i) out[i] = s.at(t0 + static_cast<double>(i) * step);
  return out;
}

std::size_t fft_size(std::size_t n) {
  std::size_t m = 1;
  while (m < n) m <<= 1;
  return m;
}

/// The best offset over the lags inside [lo, hi] on a grid of `step`, by FFT.
bool coarse_search(const Signal& a, const Signal& b, const ClockOptions& o, double* best_offset) {
  const double h = o.coarse_step;
  const std::size_t na = static_cast<std::size_t>(std::floor((a.end() - a.start()) / h)) + 1;
  const std::size_t nb = static_cast<std::size_t>(std::floor((b.end() - b.start()) / h)) + 1;
  if (na < 4 || nb < 4) return false;
  std::vector<double> x = resample(a, a.start(), h, na), y = resample(b, b.start(), h, nb);
  // c[d] = sum_i x_i y_(i-d), d in (-nb, na): circular correlation of zero-padded vectors.
  const std::size_t N = fft_size(na + nb);
  std::vector<double> xp(N, 0.0), yp(N, 0.0);
  std::copy(x.begin(), x.end(), xp.begin());
  std::copy(y.begin(), y.end(), yp.begin());
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> X, Y;
  fft.fwd(X, xp);
  fft.fwd(Y, yp);
  for (std::size_t k = 0; k < X.size(); ++k) X[k] *= std::conj(Y[k]);
  std::vector<double> c;
  fft.inv(c, X);
  // Prefix sums for the per-lag means and variances of the overlapping parts.
  std::vector<double> sx(na + 1, 0.0), sxx(na + 1, 0.0), sy(nb + 1, 0.0), syy(nb + 1, 0.0);
  for (std::size_t i = 0; i < na; ++i) sx[i + 1] = sx[i] + x[i], sxx[i + 1] = sxx[i] + x[i] * x[i];
  for (std::size_t j = 0; j < nb; ++j) sy[j + 1] = sy[j] + y[j], syy[j + 1] = syy[j] + y[j] * y[j];
  const long min_m = std::max<long>(4, std::lround(o.min_overlap / h));
  double best = -2.0;
  bool found = false;
  for (long d = -static_cast<long>(nb) + 1; d < static_cast<long>(na); ++d) {
    const double offset = a.start() - b.start() + static_cast<double>(d) * h;
    if (offset < o.search_lo || offset > o.search_hi) continue;
    const long i0 = std::max<long>(0, d), i1 = std::min<long>(static_cast<long>(na), static_cast<long>(nb) + d);
    const long m = i1 - i0;
    if (m < min_m) continue;
    const long j0 = i0 - d, j1 = i1 - d;
    const double Sx = sx[i1] - sx[i0], Sxx = sxx[i1] - sxx[i0];
    const double Sy = sy[j1] - sy[j0], Syy = syy[j1] - syy[j0];
    const double cxy = c[static_cast<std::size_t>((d % static_cast<long>(N) + static_cast<long>(N)) % static_cast<long>(N))];
    const double md = static_cast<double>(m);
    const double vx = Sxx - Sx * Sx / md, vy = Syy - Sy * Sy / md;
    if (!(vx > 0.0 && vy > 0.0)) continue;
    const double r = (cxy - Sx * Sy / md) / std::sqrt(vx * vy);
    if (r > best) {
      best = r;
      *best_offset = offset;
      found = true;
    }
  }
  return found;
}

/// Refines `o` within +-span at `step`, with a parabola through the best three.
double refine(const Signal& a, const Signal& b, double o, double span, double step, double min_overlap,
              double* corr) {
  const int n = static_cast<int>(std::ceil(span / step));
  std::vector<double> r(static_cast<std::size_t>(2 * n + 1), -2.0);
  int best = -1;
  for (int k = -n; k <= n; ++k) {
    const double v = correlation_at(a, b, o + k * step, step, min_overlap);
    if (std::isfinite(v)) r[static_cast<std::size_t>(k + n)] = v;
    if (best < 0 || r[static_cast<std::size_t>(k + n)] > r[static_cast<std::size_t>(best)]) best = k + n;
  }
  double shift = 0.0;
  if (best > 0 && best < 2 * n) {
    const double y0 = r[static_cast<std::size_t>(best - 1)], y1 = r[static_cast<std::size_t>(best)],
                 y2 = r[static_cast<std::size_t>(best + 1)];
    const double den = y0 - 2.0 * y1 + y2;
    if (den < 0.0) shift = std::clamp(0.5 * (y0 - y2) / den, -0.5, 0.5);
  }
  *corr = r[static_cast<std::size_t>(best)];
  return o + (best - n + shift) * step;
}

Signal part(const Signal& s, double from, double to) {
  Signal p;
  for (std::size_t i = 0; i < s.t.size(); ++i)
    if (s.t[i] >= from && s.t[i] <= to) {
      p.t.push_back(s.t[i]);
      p.x.push_back(s.x[i]);
    }
  p.step = s.step;
  return p;
}

}  // namespace

Signal Signal::of(const Series& s, const std::vector<double>& x) {
  Signal out;
  out.t.resize(x.size());
  out.x = x;
  for (std::size_t i = 0; i < x.size(); ++i) out.t[i] = s.time(i);
  out.step = s.dt;
  return out;
}

void Signal::shift(double offset) {
  for (double& v : t) v += offset;
}


double correlation_at(const Signal& a, const Signal& b, double o, double step, double min_overlap,
                      double* overlap) {
  const double from = std::max(a.start(), b.start() + o), to = std::min(a.end(), b.end() + o);
  if (overlap) *overlap = std::max(0.0, to - from);
  if (!(to - from >= min_overlap)) return std::nan("");
  double sx = 0.0, sy = 0.0, sxx = 0.0, syy = 0.0, sxy = 0.0, m = 0.0;
  for (double t = from; t <= to; t += step) {
    const double x = a.at(t), y = b.at(t - o);
    sx += x, sy += y, sxx += x * x, syy += y * y, sxy += x * y, m += 1.0;
  }
  const double vx = sxx - sx * sx / m, vy = syy - sy * sy / m;
  if (!(vx > 0.0 && vy > 0.0)) return std::nan("");
  return (sxy - sx * sy / m) / std::sqrt(vx * vy);
}

ClockFit fit_clock_offset(const Signal& a, const Signal& b, const ClockOptions& o) {
  ClockFit fit;
  double coarse = 0.0;
  if (!coarse_search(a, b, o, &coarse)) return fit;
  const double fine = std::min(0.01, o.coarse_step);
  double corr = 0.0;
  fit.offset = refine(a, b, coarse, 2.0 * o.coarse_step, fine, o.min_overlap, &corr);
  fit.correlation = correlation_at(a, b, fit.offset, fine, o.min_overlap, &fit.overlap);
  fit.found = std::isfinite(fit.correlation);
  if (!fit.found) return fit;
  // 1 sigma from the chunks' own offsets near the whole fit's.
  const double from = std::max(a.start(), b.start() + fit.offset);
  const double to = std::min(a.end(), b.end() + fit.offset);
  const int K = std::max(2, o.chunks);
  const double len = (to - from) / K;
  std::vector<double> offs;
  for (int k = 0; k < K; ++k) {
    const Signal ak = part(a, from + k * len, from + (k + 1) * len);
    if (ak.t.size() < 10) continue;
    double c = 0.0;
    const double ok = refine(ak, b, fit.offset, 0.1, fine, 0.5 * len, &c);
    if (std::isfinite(c) && c > 0.0) offs.push_back(ok);
  }
  if (offs.size() >= 2) {
    double mean = 0.0, ss = 0.0;
    for (double x : offs) mean += x;
    mean /= static_cast<double>(offs.size());
    for (double x : offs) ss += (x - mean) * (x - mean);
    const double sd = std::sqrt(ss / static_cast<double>(offs.size() - 1));
    fit.sigma = std::max(sd / std::sqrt(static_cast<double>(offs.size())), 0.1 * fine);
  } else {
    fit.sigma = std::numeric_limits<double>::infinity();
  }
  return fit;
}

}  // namespace wheelins::survey
