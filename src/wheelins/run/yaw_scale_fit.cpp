// A Wheel-IMU's yaw scale factor from a reference track (yaw_scale_fit.hpp).
#include "wheelins/run/yaw_scale_fit.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Dense>

#include "wheelins/math/rotation.hpp"
#include "wheelins/run/run.hpp"
#include "wheelins/survey/clock.hpp"

namespace wheelins {

YawScaleFit fit_yaw_scale(const Manifest& m, const std::string& module, const YawScaleFitOptions& o) {
  const ModuleSpec* spec = m.find(module);
  YawScaleFit out;
  out.yaw_scale = CalibratedValue{spec ? spec->yaw_scale : 0.0, 0.0, false};
  if (!spec || spec->kind != ModuleKind::kWheel) return out;
  RunRequest req = calibration_run_request(m, {module}, 0.02);
  req.manifest.heading_known = false;  // aligned onto the reference's start, as a run is scored
  RunEvaluationRequest ev;
  ev.keep_series = true;
  req.evaluation = ev;
  // The run's heading, unwrapped, at its records (the evaluated epochs lie within them).
  survey::Signal track;
  req.on_record = [&](const TrajectoryRecord& r) {
    track.t.push_back(r.t);
    track.x.push_back(track.x.empty() ? r.rpy.z() : track.x.back() + wrap_pi(r.rpy.z() - track.x.back()));
  };
  const RunResult res = run_navigation(req);
  if (!res.evaluation) return out;

  // e = a + b (t - t0) + s psi over the epochs with a heading error.
  std::vector<Eigen::Vector3d> X;
  std::vector<double> y;
  double t0 = std::nan(""), psi0 = 0.0, e_prev = 0.0, lo = 0.0, hi = 0.0;
  for (const eval::EpochError& e : res.evaluation->series) {
    if (!std::isfinite(e.heading_err)) continue;
    const double psi = track.at(e.t);
    if (std::isnan(t0)) {
      t0 = e.t, psi0 = psi, e_prev = e.heading_err;
    }
    e_prev += wrap_pi(e.heading_err - e_prev);  // unwrapped
    X.emplace_back(1.0, e.t - t0, psi - psi0);
    y.push_back(e_prev);
    lo = std::min(lo, psi - psi0), hi = std::max(hi, psi - psi0);
  }
  out.epochs = y.size();
  out.turn_span = hi - lo;
  if (y.size() < 30) return out;
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < y.size(); ++k) {
    A += X[k] * X[k].transpose();
    b += X[k] * y[k];
  }
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(A);
  if (ldlt.info() != Eigen::Success || std::abs(A.determinant()) < 1e-12) return out;
  const Eigen::Vector3d c = ldlt.solve(b);
  std::vector<double> r(y.size());
  double ss = 0.0;
  for (std::size_t k = 0; k < y.size(); ++k) ss += (r[k] = y[k] - X[k].dot(c)) * r[k];
  double r01 = 0.0;
  for (std::size_t k = 1; k < r.size(); ++k) r01 += r[k] * r[k - 1];
  const double rho = std::clamp(ss > 0.0 ? r01 / ss : 0.0, 0.0, 0.99);
  const double n = static_cast<double>(y.size());
  const double var = ss / (n - 3.0) * (1.0 + rho) / (1.0 - rho);
  const double sigma = std::sqrt(var * A.inverse()(2, 2));
  out.fitted = c(2);
  out.residual = std::sqrt(ss / n);
  const double total = (1.0 + spec->yaw_scale) * (1.0 + c(2)) - 1.0;
  const bool observed = sigma < o.max_sigma && std::abs(c(2)) >= o.min_significance * sigma &&
                        out.turn_span >= o.min_turn && std::abs(total) <= ManifestLimits::kYawScalePpm * 1e-6;
  out.yaw_scale = CalibratedValue{total, sigma, observed};
  return out;
}

}  // namespace wheelins
