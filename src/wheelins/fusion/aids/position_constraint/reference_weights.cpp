// The reference weights of reference_weights.hpp (paper eq. 8).
#include "wheelins/fusion/aids/position_constraint/reference_weights.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace wheelins {

double reference_point_variance(const ReferencePointModel& r, const Mat21& P) {
  const Eigen::Matrix<double, 2, kStateDim> Hh = r.H.topRows<2>();
  return (Hh * P * Hh.transpose()).trace();
}

void StandaloneDrift::start(double t0, double heading0, double bias_var, double sf_var) {
  P.setZero();
  P(2, 2) = std::max(bias_var, 0.0);
  P(3, 3) = std::max(sf_var, 0.0);
  t = t0;
  heading = heading0;
  started = true;
}

void StandaloneDrift::step(double t1, double heading1, double speed, double arw, double bias_std,
                           double tau) {
  // Phi = exp(A dt) and Q_d = int Phi Q_c Phi^T to second order in dt (A^3 = 0 but for the
  // bias decay, which over 1 s of a correlation time of minutes is first order). The yaw
  // rate is the mean over the whole interval.
  const double beta = bias_std > 0.0 && tau > 0.0 ? 1.0 / tau : 0.0;
  const double qb = bias_std > 0.0 && tau > 0.0 ? 2.0 * bias_std * bias_std / tau : 0.0;
  const double omega = t1 - t > 1e-9 ? std::remainder(heading1 - heading, 2.0 * kPi) / (t1 - t) : 0.0;
  while (t1 - t > 1e-9) {
    const double dt = std::min(1.0, t1 - t);
    Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
    A(0, 1) = speed;
    A(1, 2) = 1.0;
    A(1, 3) = omega;
    A(2, 2) = -beta;
    const Eigen::Matrix4d Phi = Eigen::Matrix4d::Identity() + A * dt + A * A * (0.5 * dt * dt);
    const Eigen::Vector4d qc(0.0, arw * arw, qb, 0.0);
    const Eigen::Matrix4d Qc = qc.asDiagonal();
    const Eigen::Matrix4d AQ = A * Qc;
    const Eigen::Matrix4d Qd = Qc * dt + (AQ + AQ.transpose()) * (0.5 * dt * dt) +
                               A * Qc * A.transpose() * (dt * dt * dt / 3.0);
    P = Phi * P * Phi.transpose() + Qd;
    t += dt;
  }
  heading = heading1;
}

ReferenceWeights::ReferenceWeights(const FusionOptions& options, const std::vector<double>& configured)
    : covariance_(options.weighting == ReferenceWeighting::kCovariance),
      standalone_(options.weighting == ReferenceWeighting::kStandalone),
      alpha_(1.0 / options.weight_window),
      n_(static_cast<int>(configured.size())) {
  for (int i = 0; i < n_; ++i) w_[i] = covariance_ || standalone_ ? 1.0 : configured[i];
}

void ReferenceWeights::observe_standalone(int i, double t, double heading, double speed, const ImuNoise& q,
                                          bool wheel, double bias_var0, double sf_var0) {
  StandaloneDrift& d = drift_[i];
  if (!d.started) d.start(t, heading, wheel ? 0.0 : bias_var0, sf_var0);
  d.step(t, heading, speed, q.gyro_arw, wheel ? 0.0 : q.gyro_bias_std, q.gyro_bias_tau);
  w_[i] = 1.0 / std::max(d.lateral_variance(), kMinVariance);
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

std::vector<WeightSummary> summarize_weights(const std::vector<WeightRecord>& history, int n,
                                             const std::vector<bool>& follows) {
  std::vector<WeightSummary> s(n);
  for (int i = 0; i < n && static_cast<std::size_t>(i) < follows.size(); ++i) s[i].follows = follows[i];
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

std::string weights_report(const std::vector<WeightSummary>& s, std::size_t epochs,
                           const std::vector<std::string>& modules, const FusionOptions& options) {
  if (epochs == 0) return "";
  const int n = static_cast<int>(modules.size());
  std::string out = std::string("reference weights k_i (eq. 8, ") +
                    (options.weighting == ReferenceWeighting::kCovariance
                         ? "inverse variance of each subsystem's o"
                         : options.weighting == ReferenceWeighting::kStandalone
                               ? "inverse of each subsystem's drift on its own"
                               : (options.weights.empty() ? "equal" : "fixed")) +
                    "), mean [least, greatest] over " + std::to_string(epochs) +
                    " constraint epochs:\n";
  char buf[160];
  for (int i = 0; i < n; ++i) {
    std::snprintf(buf, sizeof buf, "  %-12s %.3f [%.3f, %.3f]", modules[i].c_str(), s[i].mean, s[i].min,
                  s[i].max);
    out += buf;
    if (s[i].follows) {
      // It counts only while no wheel that does not steer does (fault handling).
      std::snprintf(buf, sizeof buf, "  (steered: follows the wheels that do not steer, counted in %.1f %% of the epochs; "
                    "--steered-in-reference counts it)", 100.0 * s[i].counted);
      out += buf;
    } else if (s[i].counted < 1.0) {
      std::snprintf(buf, sizeof buf, "  (counted in %.1f %% of the epochs)", 100.0 * s[i].counted);
      out += buf;
    }
    out += "\n";
  }
  return out;
}

}  // namespace wheelins
