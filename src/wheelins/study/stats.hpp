// Summary statistics of a study: mean, standard deviation and a confidence interval
// of the mean, for a sample and for paired differences (docs/studies.md, "Statistics").
//
//  * Student t interval (the default): mean +- t_{(1+c)/2, n-1} s / sqrt(n), with s the
//    sample standard deviation (n - 1 in the denominator). Exact for normal data, and
//    close for n >= 20 whatever the distribution (central limit theorem).
//  * Percentile bootstrap: the (1-c)/2 and (1+c)/2 quantiles of the means of B resamples
//    drawn with replacement (Efron & Tibshirani 1993, ch. 13), from a fixed seed, so the
//    same values give the same interval on every run and platform.
// A paired difference is the sample of d_i = b_i - a_i over the replicates both have.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace wheelins::study {

enum class IntervalMethod { kStudentT, kBootstrap };

IntervalMethod interval_method_from_name(const std::string& name);  ///< "t" | "bootstrap"
const char* interval_method_name(IntervalMethod m);
/// A sentence for the report saying which interval it is.
std::string interval_description(IntervalMethod m, double confidence, int resamples);

struct Summary {
  std::size_t n = 0;            ///< finite values
  double mean = 0.0, sd = 0.0;  ///< NaN when n < 1 / n < 2
  double lo = 0.0, hi = 0.0;    ///< the interval of the mean; NaN when n < 2
};

struct IntervalOptions {
  IntervalMethod method = IntervalMethod::kStudentT;
  double confidence = 0.95;
  int resamples = 10000;       ///< bootstrap
  std::uint64_t seed = 20240;  ///< bootstrap
};

/// Non-finite values are left out (and not counted in n).
Summary summarize(const std::vector<double>& values, const IntervalOptions& options = {});

/// The Student t distribution with `dof` degrees of freedom: its CDF and quantile
/// (p in (0, 1)); dof > 0, not necessarily whole.
double student_t_cdf(double t, double dof);
double student_t_quantile(double p, double dof);

/// The regularized incomplete beta function I_x(a, b) (a, b > 0, x in [0, 1]).
double incomplete_beta(double x, double a, double b);

}  // namespace wheelins::study
