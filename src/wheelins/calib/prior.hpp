// The installation calibration's estimates combined with their priors (docs/filter.md
// section 15): the 1 sigma of a mean from its sums, and a data estimate combined with a
// Gaussian prior around the manifest's value (observed or not).
#pragma once

#include <algorithm>
#include <cmath>

#include "wheelins/calib/calibration_types.hpp"

namespace wheelins::calib_detail {

/// The 1 sigma of a mean over n samples from their sum and sum of squares (the sample
/// variance with n - 1), with a systematic term added in quadrature.
inline double std_of_mean(double sum, double sum_sq, double n, double systematic) {
  const double mean = sum / n;
  const double var = std::max(0.0, (sum_sq / n - mean * mean) * n / (n - 1.0));
  return std::sqrt(var / n + systematic * systematic);
}

/// A data estimate (value, sigma; sigma = inf: no data) combined with a zero-mean-offset
/// Gaussian prior around `prior`.
inline CalibratedValue with_prior(double prior, double prior_std, double data, double data_std,
                                  double observed_ratio) {
  CalibratedValue v;
  if (!(data_std < 1e300) || !std::isfinite(data)) {
    v.value = prior;
    v.std = prior_std;
    return v;
  }
  const double wp = 1.0 / (prior_std * prior_std), wd = 1.0 / (data_std * data_std);
  v.value = (wp * prior + wd * data) / (wp + wd);
  v.std = std::sqrt(1.0 / (wp + wd));
  v.observed = v.std < observed_ratio * prior_std;
  return v;
}

}  // namespace wheelins::calib_detail
