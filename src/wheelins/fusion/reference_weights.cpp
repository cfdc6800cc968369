// The reference weights of reference_weights.hpp (paper eq. 8).
#include "wheelins/fusion/reference_weights.hpp"

#include <algorithm>
#include <cstdio>

namespace wheelins {

double reference_point_variance(const ReferencePointModel& r, const Mat21& P) {
  const Eigen::Matrix<double, 2, kStateDim> Hh = r.H.topRows<2>();
  return (Hh * P * Hh.transpose()).trace();
}

ReferenceWeights::ReferenceWeights(const FusionOptions& options, const std::vector<double>& configured)
    : covariance_(options.weighting == ReferenceWeighting::kCovariance),
      alpha_(1.0 / options.weight_window),
      n_(static_cast<int>(configured.size())) {
  for (int i = 0; i < n_; ++i) w_[i] = covariance_ ? 1.0 : configured[i];
}

void ReferenceWeights::observe(int i, double variance, bool counted) {
  if (!covariance_) return;
  if (!counted) {
    averaging_[i] = false;  // counts again: starts afresh from its new covariance
    return;
  }
  const double v = std::max(variance, kMinVariance);
  mean_var_[i] = averaging_[i] ? mean_var_[i] + alpha_ * (v - mean_var_[i]) : v;
  averaging_[i] = true;
  w_[i] = 1.0 / mean_var_[i];
}

void ReferenceWeights::record(double t, const std::array<double, kMaxModules>& k_used) {
  WeightRecord r;
  r.t = t;
  r.k = k_used;
  history_.push_back(r);
}

std::vector<WeightSummary> summarize_weights(const std::vector<WeightRecord>& history, int n) {
  std::vector<WeightSummary> s(n);
  std::vector<int> count(n, 0);
  for (int i = 0; i < n; ++i) s[i].min = 1.0;
  for (const WeightRecord& r : history)
    for (int i = 0; i < n; ++i) {
      if (!(r.k[i] > 0.0)) continue;
      ++count[i];
      s[i].mean += r.k[i];
      s[i].min = std::min(s[i].min, r.k[i]);
      s[i].max = std::max(s[i].max, r.k[i]);
    }
  for (int i = 0; i < n; ++i) {
    if (count[i]) s[i].mean /= count[i];
    else s[i].min = 0.0;
    s[i].counted = history.empty() ? 0.0 : static_cast<double>(count[i]) / history.size();
  }
  return s;
}

std::string weights_csv(const std::vector<WeightRecord>& history,
                        const std::vector<std::string>& modules) {
  std::string out = "t";
  for (const auto& m : modules) out += "," + m;
  out += "\n";
  char buf[32];
  for (const WeightRecord& r : history) {
    std::snprintf(buf, sizeof buf, "%.3f", r.t);
    out += buf;
    for (std::size_t i = 0; i < modules.size(); ++i) {
      std::snprintf(buf, sizeof buf, ",%.6f", r.k[i]);
      out += buf;
    }
    out += "\n";
  }
  return out;
}

std::string weights_report(const std::vector<WeightRecord>& history,
                           const std::vector<std::string>& modules, const FusionOptions& options) {
  if (history.empty()) return "";
  const int n = static_cast<int>(modules.size());
  const std::vector<WeightSummary> s = summarize_weights(history, n);
  std::string out = std::string("reference weights k_i (eq. 8, ") +
                    (options.weighting == ReferenceWeighting::kCovariance
                         ? "inverse variance of each subsystem's o"
                         : (options.weights.empty() ? "equal" : "fixed")) +
                    "), mean [least, greatest] over " + std::to_string(history.size()) +
                    " constraint epochs:\n";
  char buf[160];
  for (int i = 0; i < n; ++i) {
    std::snprintf(buf, sizeof buf, "  %-12s %.3f [%.3f, %.3f]", modules[i].c_str(), s[i].mean, s[i].min,
                  s[i].max);
    out += buf;
    if (s[i].counted < 1.0) {
      std::snprintf(buf, sizeof buf, "  (counted in %.1f %% of the epochs)", 100.0 * s[i].counted);
      out += buf;
    }
    out += "\n";
  }
  return out;
}

}  // namespace wheelins
