// The study's statistics (stats.hpp): the Student t distribution (through the regularized
// incomplete beta function), the t and bootstrap intervals, paired differences.
#include "wheelins/study/stats.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "wheelins/nav/types.hpp"
#include "wheelins/sim/rng.hpp"

namespace wheelins::study {

IntervalMethod interval_method_from_name(const std::string& name) {
  if (name == "t") return IntervalMethod::kStudentT;
  if (name == "bootstrap") return IntervalMethod::kBootstrap;
  throw InputError("interval '" + name + "': expected t or bootstrap");
}

const char* interval_method_name(IntervalMethod m) {
  return m == IntervalMethod::kStudentT ? "t" : "bootstrap";
}

std::string interval_description(IntervalMethod m, double confidence, int resamples) {
  char pct[32];
  std::snprintf(pct, sizeof pct, "%g %%", 100.0 * confidence);
  if (m == IntervalMethod::kStudentT)
    return std::string(pct) + " Student t interval of the mean: mean +- t(n-1) sd / sqrt(n)";
  return std::string(pct) + " percentile bootstrap interval of the mean (" +
         std::to_string(resamples) + " resamples, fixed seed)";
}

namespace {

/// Continued fraction of I_x(a, b) (modified Lentz), valid for x < (a + 1) / (a + b + 2).
double beta_fraction(double x, double a, double b) {
  constexpr double kTiny = 1e-300, kEps = 1e-15;
  const double qab = a + b, qap = a + 1.0, qam = a - 1.0;
  double c = 1.0, d = 1.0 - qab * x / qap;
  if (std::fabs(d) < kTiny) d = kTiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m <= 500; ++m) {
    const double m2 = 2.0 * m;
    double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
    d = 1.0 + aa * d;
    if (std::fabs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::fabs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    h *= d * c;
    aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
    d = 1.0 + aa * d;
    if (std::fabs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::fabs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::fabs(del - 1.0) < kEps) break;
  }
  return h;
}

double finite_mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

}  // namespace

double incomplete_beta(double x, double a, double b) {
  if (!(a > 0.0) || !(b > 0.0) || !(x >= 0.0 && x <= 1.0)) return std::nan("");
  if (x == 0.0 || x == 1.0) return x;
  const double front = std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) +
                                a * std::log(x) + b * std::log1p(-x));
  if (x < (a + 1.0) / (a + b + 2.0)) return front * beta_fraction(x, a, b) / a;
  return 1.0 - front * beta_fraction(1.0 - x, b, a) / b;
}

double student_t_cdf(double t, double dof) {
  if (!(dof > 0.0) || std::isnan(t)) return std::nan("");
  if (std::isinf(t)) return t > 0 ? 1.0 : 0.0;
  // P(|T| > |t|) = I_{dof / (dof + t^2)}(dof / 2, 1 / 2).
  const double tail = 0.5 * incomplete_beta(dof / (dof + t * t), 0.5 * dof, 0.5);
  return t > 0 ? 1.0 - tail : tail;
}

double student_t_quantile(double p, double dof) {
  if (!(p > 0.0 && p < 1.0) || !(dof > 0.0)) return std::nan("");
  if (p == 0.5) return 0.0;
  if (p < 0.5) return -student_t_quantile(1.0 - p, dof);
  // Bracket, then bisect: the CDF is monotonic, and 200 halvings reach the last bit.
  double lo = 0.0, hi = 1.0;
  while (student_t_cdf(hi, dof) < p && hi < 1e300) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-15 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (student_t_cdf(mid, dof) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

Summary summarize(const std::vector<double>& values, const IntervalOptions& o) {
  if (!(o.confidence > 0.0 && o.confidence < 1.0))
    throw InputError("confidence " + std::to_string(o.confidence) + ": must be in (0, 1)");
  std::vector<double> v;
  for (double x : values)
    if (std::isfinite(x)) v.push_back(x);
  Summary s;
  s.n = v.size();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  s.mean = s.sd = s.lo = s.hi = nan;
  if (v.empty()) return s;
  s.mean = finite_mean(v);
  if (v.size() < 2) return s;
  double ss = 0.0;
  for (double x : v) ss += (x - s.mean) * (x - s.mean);
  s.sd = std::sqrt(ss / static_cast<double>(v.size() - 1));
  const double n = static_cast<double>(v.size());
  if (o.method == IntervalMethod::kStudentT) {
    const double half =
        student_t_quantile(0.5 * (1.0 + o.confidence), n - 1.0) * s.sd / std::sqrt(n);
    s.lo = s.mean - half;
    s.hi = s.mean + half;
    return s;
  }
  if (o.resamples < 100) throw InputError("bootstrap resamples: at least 100");
  sim::Rng rng(o.seed, "study/bootstrap");
  std::vector<double> means(static_cast<std::size_t>(o.resamples));
  for (double& m : means) {
    double sum = 0.0;
    for (std::size_t i = 0; i < v.size(); ++i) sum += v[rng.next_u64() % v.size()];
    m = sum / n;
  }
  std::sort(means.begin(), means.end());
  // The empirical quantile at rank q (B - 1), linearly interpolated.
  auto quantile = [&](double q) {
    const double r = q * static_cast<double>(means.size() - 1);
    const auto k = static_cast<std::size_t>(std::floor(r));
    const double f = r - static_cast<double>(k);
    return k + 1 < means.size() ? means[k] + f * (means[k + 1] - means[k]) : means[k];
  };
  s.lo = quantile(0.5 * (1.0 - o.confidence));
  s.hi = quantile(0.5 * (1.0 + o.confidence));
  return s;
}

}  // namespace wheelins::study
